#pragma once
// The one error type that crosses module boundaries. Loaders, option checks and the
// simulation's stability guard throw drape::Error; the CLI prints its message on one line
// and exits with its code. Inside hot loops nothing throws: problems come back as flags.

#include <stdexcept>
#include <string>

namespace drape {

/// Process exit codes of the drape command.
enum class ExitCode : int {
  Ok = 0,
  Internal = 1,  ///< a bug in drape: please report it
  BadInput = 2,  ///< a file, option or value that drape cannot use
  Unstable = 3,  ///< the simulation diverged (NaN or speed bound exceeded)
  Unavailable = 4,  ///< a server or peer the command needs does not answer (studio roles)
};

/// A position in a source file, 1-based; line or column 0 means "not known".
struct SourcePos {
  std::string file;
  int line = 0;
  int column = 0;

  /// "file:line:column", "file:line" or "file", as much as is known.
  [[nodiscard]] std::string str() const;
};

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message, ExitCode code = ExitCode::BadInput)
      : std::runtime_error(message), code_(code) {}

  /// "file:line:column: what" (the form every parser reports in).
  [[nodiscard]] static Error at(const SourcePos& pos, const std::string& what) {
    return Error(pos.str() + ": " + what);
  }

  [[nodiscard]] ExitCode code() const { return code_; }

 private:
  ExitCode code_;
};

}  // namespace drape
