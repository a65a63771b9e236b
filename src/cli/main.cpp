// drape: real-time cloth simulation for virtual characters.

#include <algorithm>
#include <cstdio>
#include <exception>
#include <map>
#include <optional>

#include <tbb/global_control.h>

#include "command.hpp"
#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "parse_errors.hpp"

namespace drape::cli {
namespace {

std::vector<Command>& registry() {
  static std::vector<Command> commands;
  return commands;
}

GlobalOptions& mutableGlobals() {
  static GlobalOptions options;
  return options;
}

}  // namespace

bool registerCommand(Command command) {
  registry().push_back(std::move(command));
  return true;
}

std::vector<Command> registeredCommands() {
  std::vector<Command> commands = registry();
  std::sort(commands.begin(), commands.end(), [](const Command& a, const Command& b) {
    return a.order != b.order ? a.order < b.order : a.name < b.name;
  });
  return commands;
}

const GlobalOptions& globalOptions() { return mutableGlobals(); }

}  // namespace drape::cli

int main(int argc, char** argv) {
  using namespace drape;
  CLI::App app{"drape: real-time cloth simulation for virtual characters.\n"
               "Motion capture drives segmented avatars; garments are simulated on them with\n"
               "distance-field collisions; results come out as OBJ, PC2, VRML97, glTF and pictures."};
  app.set_version_flag("--version", std::string("drape ") + DRAPE_VERSION);
  app.require_subcommand(1);
  app.fallthrough();
  bool quiet = false;
  int verbose = 0;
  app.add_flag("-q,--quiet", quiet, "Print errors only");
  app.add_flag("-v,--verbose", verbose, "More detail on standard error (repeat for more)");
  int threads = 0;
  app.add_option("-j,--threads", threads,
                 "Threads for the simulation (default: every core; one for 'bench paper'). Garments run side by "
                 "side; a garment of 1,024 vertices or more also splits its collision tests over them, and one "
                 "of 2,048 triangles or more its forces. The results are the same to the bit with any number of threads")
      ->check(CLI::Range(1, 1024));

  // Top-level commands first, then the ones nested under them ("bench cloth").
  std::map<std::string, cli::RunFunction> runs;
  const std::vector<cli::Command> commands = cli::registeredCommands();
  for (const cli::Command& command : commands) {
    if (!command.parent.empty()) continue;
    CLI::App* sub = app.add_subcommand(command.name, command.description);
    runs[command.name] = command.setup(*sub);
  }
  for (const cli::Command& command : commands) {
    if (command.parent.empty()) continue;
    CLI::App* parent = app.get_subcommand(command.parent);
    CLI::App* sub = parent->add_subcommand(command.name, command.description);
    runs[command.parent + " " + command.name] = command.setup(*sub);
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    std::fprintf(stderr, "%s\n", cli::parseErrorMessage(app, e).c_str());
    return static_cast<int>(ExitCode::BadInput);
  }

  cli::mutableGlobals().verbosity = quiet ? -1 : verbose;
  cli::mutableGlobals().threads = threads;
  setupLogging(cli::globalOptions().verbosity);
  std::optional<tbb::global_control> threadLimit;
  if (threads > 0) threadLimit.emplace(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));

  try {
    for (CLI::App* sub : app.get_subcommands()) {
      std::string key = sub->get_name();
      for (CLI::App* nested : sub->get_subcommands()) key += " " + nested->get_name();
      return runs.at(key)();
    }
  } catch (const Error& e) {
    std::fprintf(stderr, "drape: %s\n", e.what());
    return static_cast<int>(e.code());
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "drape: out of memory\n");
    return static_cast<int>(ExitCode::Internal);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "drape: internal error: %s\n", e.what());
    return static_cast<int>(ExitCode::Internal);
  }
  return 0;
}
