// `drape bench`: the benchmarks. Each one is a nested subcommand (bench_*.cpp or the
// module's own cmd file registers {"name", ..., .parent = "bench"}) that prints JSON.

#include "command.hpp"

namespace drape::cli {
namespace {

RunFunction setupBench(CLI::App& app) {
  app.require_subcommand(1);
  app.footer("Each benchmark prints one JSON object on standard output; progress goes to standard error.");
  return [] { return 0; };
}

const bool registered_cmd_bench = registerCommand({"bench", "Run a benchmark and print its figures as JSON", "", 90, &setupBench});

}  // namespace
}  // namespace drape::cli
