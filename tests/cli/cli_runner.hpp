#pragma once
// Runs the real drape executable and captures its exit code, standard output and error.

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <signal.h>
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

/// `args` is appended to the drape path as shell words (callers quote what needs it);
/// `wrapper` goes before it (e.g. "xvfb-run -a " for a window).
inline CliResult runDrape(const std::string& args, const ScratchDir& scratch, const std::string& wrapper = "") {
  const std::string outFile = scratch / "stdout.txt", errFile = scratch / "stderr.txt";
  const std::string cmd = std::string("ASAN_OPTIONS=detect_leaks=0 ") + wrapper + "'" + DRAPE_EXE + "' " + args +
                          " >'" + outFile + "' 2>'" + errFile + "'";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(outFile);
  r.err = slurp(errFile);
  return r;
}

/// Replaces the first `from` in `text` with `to`; a test failure when there is none.
inline void replaceOnce(std::string& text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
}

/// A bundled example's scene text with its URLs into data/ made absolute (for a copy in a
/// scratch directory).
inline std::string exampleSceneWithDataFound(const std::string& scene) {
  std::string text = slurp(scene);
  replaceOnce(text, "url \"../../data/", "url \"" + std::string(DRAPE_DATA_DIR) + "/");
  return text;
}

/// The walking skirt twice over, as two garments 'Skirt' and 'Skirt2' of one scene (they do
/// not touch each other: each comes out as the skirt alone), written into `scratch`.
inline std::string twoSkirtScene(const ScratchDir& scratch) {
  std::string scene = exampleSceneWithDataFound(kSkirtDir + "/scene.wrl");
  replaceOnce(scene, "constraintMask IndexedFaceSet {", "constraintMask DEF SkirtMask IndexedFaceSet {");
  scene += R"(
DEF Skirt2 ClothSet {
  cloth Shape { geometry USE SkirtMesh }
  constraintMask USE SkirtMask
  material USE Knit
  avatar USE Body
  collidesWith [ "LowerBack", "Hips", "LeftUpLeg", "RightUpLeg", "LeftLeg", "RightLeg" ]
  maskTolerance 0.0005
  bindThreshold 0.040
}
)";
  const std::string path = scratch / "two.wrl";
  std::ofstream(path) << scene;
  return path;
}

/// The two characters' example scene: Ada and Bea in the walking skirt, 1.2 m apart.
inline const std::string kTwoCharacters = std::string(DRAPE_SOURCE_DIR) + "/examples/two_characters/scene.wrl";

/// The two characters' scene with Bea at `translation` ("X Y Z", m) instead of 1.2 m to
/// Ada's side, the files it names found from its own directory, written into `scratch` as
/// close.wrl.
inline std::string twoCharactersWithBeaAt(const ScratchDir& scratch, const std::string& translation) {
  std::string text = slurp(kTwoCharacters);
  text.replace(text.find("translation 1.2 0 0"), 19, "translation " + translation);
  for (const std::string relative : {"\"../../data/", "\"../walking_skirt/"}) {
    std::string to = "\"";
    to += DRAPE_SOURCE_DIR;
    to += relative[4] == '.' ? "/data/" : "/examples/walking_skirt/";
    for (std::size_t at = text.find(relative); at != std::string::npos; at = text.find(relative))
      text.replace(at, relative.size(), to);
  }
  const std::string scene = scratch / "close.wrl";
  std::ofstream(scene) << text;
  return scene;
}

/// A drape command running in the background (a studio role), its standard output and
/// error in files of the scratch directory; killed, if still running, when it goes.
class DrapeProcess {
 public:
  /// `prefix`: a command drape runs under (xvfb-run -a: a virtual display).
  DrapeProcess(const std::string& args, const ScratchDir& scratch, const std::string& name,
               const std::string& prefix = "")
      : out_(scratch / (name + ".out")), err_(scratch / (name + ".err")) {
    const std::string cmd = "ASAN_OPTIONS=detect_leaks=0 exec " + prefix + " '" + DRAPE_EXE + "' " + args + " >'" +
                            out_ + "' 2>'" + err_ + "'";
    pid_ = ::fork();
    if (pid_ == 0) {
      ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
  }
  ~DrapeProcess() {
    if (pid_ > 0) kill();
  }
  DrapeProcess(const DrapeProcess&) = delete;
  DrapeProcess& operator=(const DrapeProcess&) = delete;

  /// Waits for it to end: its exit code and output (code -1 when a signal ended it).
  CliResult wait() {
    int status = 0;
    if (pid_ > 0) ::waitpid(pid_, &status, 0);
    pid_ = -1;
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out_), slurp(err_)};
  }
  /// Ends it at once (SIGKILL: no chance to tidy up, as a crash or a pulled plug).
  CliResult kill() {
    if (pid_ > 0) ::kill(pid_, SIGKILL);
    return wait();
  }
  /// What it has written to standard error so far.
  [[nodiscard]] std::string errSoFar() const { return slurp(err_); }
  /// What it has written to standard output so far.
  [[nodiscard]] std::string outSoFar() const { return slurp(out_); }
  /// Sends it `signal` (SIGINT: Ctrl-C), as a user or a service manager stops it.
  void signal(int signal) const {
    if (pid_ > 0) ::kill(pid_, signal);
  }

 private:
  std::string out_, err_;
  pid_t pid_ = -1;
};

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
