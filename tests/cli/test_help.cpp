// Every command's --help, found by walking the subcommand lists the help itself prints:
// each exits 0 and none shows the directory drape was built in (a user's copy of the binary
// would show someone else's paths). And a command line drape cannot read: the command it
// was for, what is wrong, what a mistyped word meant, where the options are listed.
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

TEST(Help, AMistypedCommandLineNamesItsCommandAndWhatWasMeant) {
  ScratchDir dir("parse-errors");
  struct Case {
    std::string args;
    std::vector<std::string> said;  ///< lines of standard error, in order
  };
  const std::vector<Case> cases = {
      {"bench paper --jsn",
       {"drape bench paper: the following argument was not expected: --jsn", "  --jsn: did you mean --json?",
        "'drape bench paper --help' lists its options"}},
      // Two letters swapped are one slip.
      {"bench paper --josn", {"  --josn: did you mean --json?"}},
      {"bnech", {"drape: a subcommand is required", "  bnech: did you mean bench?",
                 "'drape --help' lists its options and commands"}},
      // Another error first (--out missing), and an option of drape itself mistyped after
      // the command (drape's own options are taken there too).
      {"run scene.wrl --thread 2", {"drape run: --out is required", "  --thread: did you mean --threads?"}},
      // --out, as drape run writes, is render's pictures and export's --glb: not by spelling.
      {"render some/run --out pictures",
       {"drape render: the following arguments were not expected: pictures --out",
        "  --out: did you mean --png, --video or --contact-sheet?", "'drape render --help' lists its options"}},
      {"export some/run --out x.glb", {"  --out: did you mean --glb?"}},
      {"player scene.wrl --nats nats://127.0.0.1:4222", {"  --nats: did you mean --server?"}},
      // Nothing near --zzz among bench paper's options: no guess.
      {"bench paper --zzz", {"drape bench paper: the following argument was not expected: --zzz",
                             "'drape bench paper --help' lists its options"}},
  };
  for (const Case& c : cases) {
    const CliResult r = runDrape(c.args, dir);
    EXPECT_EQ(r.code, 2) << c.args;
    std::size_t from = 0;
    for (const std::string& line : c.said) {
      const std::size_t at = r.err.find(line + "\n", from);
      ASSERT_NE(at, std::string::npos) << "drape " << c.args << ": no line '" << line << "' (in order) in\n" << r.err;
      from = at + line.size();
    }
    if (c.args.find("--zzz") != std::string::npos) EXPECT_EQ(r.err.find("did you mean"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("Run with --help"), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace drape
