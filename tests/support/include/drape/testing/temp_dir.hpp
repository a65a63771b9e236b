#pragma once
// Shared by the test modules: a directory for this test process's files, removed when the
// process ends. CTest runs every test in a process of its own, so a directory named after
// the process and left behind would add hundreds to the temporary directory on each run.

#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace drape::testing {

/// `<temporary directory>/drape-test-<pid>/<name>`, created (empty for a fresh name); the
/// whole `drape-test-<pid>` goes when the process exits normally.
inline std::filesystem::path processTempDir(const std::string& name) {
  struct Owned {
    std::filesystem::path path;
    ~Owned() {
      std::error_code ignored;  // nothing to report to at exit; the directory is only tidied
      std::filesystem::remove_all(path, ignored);
    }
  };
  static const Owned owned{std::filesystem::temp_directory_path() / ("drape-test-" + std::to_string(::getpid()))};
  const std::filesystem::path dir = owned.path / name;
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace drape::testing
