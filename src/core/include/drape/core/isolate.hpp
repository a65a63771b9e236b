#pragma once
// Runs untrusted work (a third-party reader on a file from outside) in a child process
// with memory and time limits. Coin3D and Assimp can crash, hang or allocate without
// bound on malformed files; in a child that is an error message, never the end of drape
// or of a server. The child hands its result back as bytes (the caller serialises its own
// structures, e.g. with FlatBuffers); a drape::Error thrown in the child comes back as
// the same message and exit code.

#include <functional>
#include <string>

namespace drape {

struct IsolationLimits {
  std::size_t memoryBytes = std::size_t{4} << 30;  ///< address-space limit of the child
  double seconds = 60.0;                            ///< wall-clock limit, then SIGKILL
};

/// Runs `work` in a forked child and returns the bytes it produced. `what` names the
/// input in messages ("scene.wrl: the VRML97 reader failed (signal 11)").
/// Throws drape::Error(BadInput) if the child dies, runs out of time or memory, or
/// throws a drape::Error itself.
[[nodiscard]] std::string runIsolated(const std::string& what, const std::string& readerName,
                                      const std::function<std::string()>& work,
                                      const IsolationLimits& limits = {});

}  // namespace drape
