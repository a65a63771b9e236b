// Every command's --help, found by walking the subcommand lists the help itself prints:
// each exits 0 and none shows the directory drape was built in (a user's copy of the binary
// would show someone else's paths).
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"

namespace drape {
namespace {

using testing::CliResult;
using testing::runDrape;
using testing::ScratchDir;

/// The names under "Subcommands:" in a CLI11 help text.
std::vector<std::string> subcommandsOf(const std::string& help) {
  std::vector<std::string> names;
  std::istringstream in(help);
  std::string line;
  bool inList = false;
  while (std::getline(in, line)) {
    if (line == "Subcommands:") {
      inList = true;
      continue;
    }
    if (!inList) continue;
    if (line.size() < 3 || line.rfind("  ", 0) != 0) break;
    std::istringstream words(line);
    std::string name;
    words >> name;
    names.push_back(name);
  }
  return names;
}

/// The help without its "Usage:" line, which shows the executable as it was called.
std::string withoutUsage(const std::string& help) {
  std::istringstream in(help);
  std::string line, kept;
  while (std::getline(in, line))
    if (line.rfind("Usage:", 0) != 0) kept += line + "\n";
  return kept;
}

TEST(Help, EveryCommandHelpsWithoutTheBuildDirectory) {
  ScratchDir dir("help");
  std::vector<std::string> pending{""};
  int commands = 0;
  while (!pending.empty()) {
    const std::string command = pending.back();
    pending.pop_back();
    const CliResult r = runDrape(command + " --help", dir);
    ++commands;
    EXPECT_EQ(r.code, 0) << "drape " << command << " --help: " << r.err;
    EXPECT_EQ(withoutUsage(r.out).find(DRAPE_SOURCE_DIR), std::string::npos) << "drape " << command << " --help:\n"
                                                                            << r.out;
    for (const std::string& sub : subcommandsOf(r.out)) pending.push_back(command.empty() ? sub : command + " " + sub);
  }
  // drape itself, its ten commands and bench's five benchmarks.
  EXPECT_GE(commands, 16);
}

}  // namespace
}  // namespace drape
