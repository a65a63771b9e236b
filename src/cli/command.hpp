#pragma once
// Subcommand registry of the drape executable. Each cmd_*.cpp registers itself:
//
//   static const bool registered = drape::cli::registerCommand(
//       {"run", "Simulate garments and write the results", 10, &setupRun});
//
// setup() adds the subcommand's options to `app` and returns the function that runs it
// (after CLI11 has parsed and checked the options). That function returns the exit code;
// a drape::Error thrown from it is printed on one line and becomes its exit code.

#include <charconv>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

namespace drape::cli {

using RunFunction = std::function<int()>;

struct Command {
  std::string name;
  std::string description;
  std::string parent;  ///< "" for top-level commands, e.g. "bench" for `drape bench cloth`
  int order = 100;  ///< position in `drape --help`
  RunFunction (*setup)(CLI::App& app) = nullptr;
};

bool registerCommand(Command command);
[[nodiscard]] std::vector<Command> registeredCommands();

/// `drape inspect FILE` dispatches on the file's extension (lower case, with the dot) to
/// the inspector registered for it; an inspector prints a readable summary to `out` and
/// throws drape::Error on a bad file.
using Inspector = std::function<void(const std::string& path, std::ostream& out)>;
bool registerInspector(std::vector<std::string> extensions, std::string what, Inspector inspector);
struct InspectorEntry {
  std::vector<std::string> extensions;
  std::string what;
  Inspector inspect;
};
[[nodiscard]] const std::vector<InspectorEntry>& registeredInspectors();

/// `text` as a whole number in [least, most] (decimal digits, an optional leading '-',
/// spaces around it allowed), or nothing: the one parser behind the options CLI11 cannot
/// type, such as lists and ranges, so that "12x", "" and "1.5" are refused alike.
[[nodiscard]] inline std::optional<long long> wholeNumber(std::string_view text, long long least, long long most) {
  while (!text.empty() && text.front() == ' ') text.remove_prefix(1);
  while (!text.empty() && text.back() == ' ') text.remove_suffix(1);
  long long value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc{} || end != text.data() + text.size() || value < least || value > most)
    return std::nullopt;
  return value;
}

/// Global options shared by every subcommand.
struct GlobalOptions {
  int verbosity = 0;
  int threads = 0;  ///< --threads; 0: not given (every core, or one for `bench paper`)
};
[[nodiscard]] const GlobalOptions& globalOptions();

}  // namespace drape::cli
