#pragma once
// What drape prints for a command line CLI11 refuses: which command it was for, what is
// wrong, the option nearest a mistyped one, and where that command's options are listed.
// CLI11's own words ("The following argument was not expected: --jsn") name neither the
// command nor what was meant.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

namespace drape::cli {

/// Edits (insertions, deletions, substitutions, swaps of neighbours) between two words.
[[nodiscard]] std::size_t editDistance(std::string_view a, std::string_view b);

/// Of `names`, the one nearest `word` if it is near enough to be what was meant (at most one
/// edit in a word of up to five letters, two in a longer one) and nearer than any other.
[[nodiscard]] std::optional<std::string> nearestName(std::string_view word, const std::vector<std::string>& names);

/// The long and short names (with their dashes) of the options `app` takes, the ones of the
/// commands it falls through to included, and the names of its subcommands.
[[nodiscard]] std::vector<std::string> namesTakenBy(const CLI::App& app);

/// The command line's deepest command CLI11 had reached ("drape bench paper").
[[nodiscard]] const CLI::App& deepestCommand(const CLI::App& root);

/// The whole message for `e` (several lines, no trailing newline).
[[nodiscard]] std::string parseErrorMessage(const CLI::App& root, const CLI::ParseError& e);

}  // namespace drape::cli
