#pragma once
// Runs the real drape executable and captures its exit code, standard output and error.

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace drape::testing {

/// The bundled walking skirt's example directory (scene.wrl, walk.bvh).
inline const std::string kSkirtDir = std::string(DRAPE_SOURCE_DIR) + "/examples/walking_skirt";

struct CliResult {
  int code = -1;
  std::string out, err;
};

inline std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A fresh scratch directory per test, removed by the destructor.
struct ScratchDir {
  std::filesystem::path path;
  explicit ScratchDir(const std::string& name)
      : path(std::filesystem::temp_directory_path() / ("drape-test-" + name + "-" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~ScratchDir() { std::filesystem::remove_all(path); }
  [[nodiscard]] std::string operator/(const std::string& leaf) const { return (path / leaf).string(); }
};

/// `args` is appended to the drape path as shell words (callers quote what needs it).
inline CliResult runDrape(const std::string& args, const ScratchDir& scratch) {
  const std::string outFile = scratch / "stdout.txt", errFile = scratch / "stderr.txt";
  const std::string cmd = std::string("ASAN_OPTIONS=detect_leaks=0 '") + DRAPE_EXE + "' " + args + " >'" + outFile +
                          "' 2>'" + errFile + "'";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(outFile);
  r.err = slurp(errFile);
  return r;
}

/// `drape run ARGS --out SCRATCH/NAME`, which must exit 0 (the test fails with its error
/// otherwise); returns the output directory.
inline std::string runInto(const ScratchDir& scratch, const std::string& name, const std::string& args) {
  const std::string out = scratch / name;
  const CliResult r = runDrape("run " + args + " --out '" + out + "'", scratch);
  EXPECT_EQ(r.code, 0) << r.err;
  return out;
}

/// The stats.json of a run's output directory (an empty object, and a test failure, when
/// the run wrote none).
inline nlohmann::json statsOf(const std::string& out) {
  const std::string path = out + "/stats.json";
  if (!std::filesystem::exists(path)) {
    ADD_FAILURE() << path << " was not written";
    return nlohmann::json::object();
  }
  return nlohmann::json::parse(slurp(path));
}

inline int lineCount(const std::string& text) {
  int n = 0;
  for (char c : text) n += c == '\n';
  return n;
}

}  // namespace drape::testing
