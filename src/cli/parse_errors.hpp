#pragma once
// What drape prints for a command line CLI11 refuses: which command it was for, what is
// wrong, the option nearest a mistyped one, and where that command's options are listed.
// CLI11's own words ("The following argument was not expected: --jsn") name neither the
// command nor what was meant.

#include <string>

#include <CLI/CLI.hpp>

namespace drape::cli {

/// The whole message for `e` (several lines, no trailing newline).
[[nodiscard]] std::string parseErrorMessage(const CLI::App& root, const CLI::ParseError& e);

}  // namespace drape::cli
