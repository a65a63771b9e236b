#pragma once
// Subcommand registry of the drape executable. Each cmd_*.cpp registers itself:
//
//   static const bool registered = drape::cli::registerCommand(
//       {"run", "Simulate garments and write the results", 10, &setupRun});
//
// setup() adds the subcommand's options to `app` and returns the function that runs it
// (after CLI11 has parsed and checked the options). That function returns the exit code;
// a drape::Error thrown from it is printed on one line and becomes its exit code.

#include <functional>
#include <ostream>
#include <string>
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

/// Global options shared by every subcommand.
struct GlobalOptions {
  int verbosity = 0;
};
[[nodiscard]] const GlobalOptions& globalOptions();

}  // namespace drape::cli
