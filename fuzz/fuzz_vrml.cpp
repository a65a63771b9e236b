// libFuzzer target for the VRML97 reader: the whole path a scene from outside takes, the
// pre-scan, Coin in the child process, the FlatBuffers hand-over and the scene build.
// Every input must end in a scene or a drape::Error: anything else (a crash, a sanitizer
// report, another exception) in this process is a bug in drape. Coin dying in the child
// is the isolation doing its job and comes back as a drape::Error.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "drape/core/error.hpp"
#include "drape/formats/vrml_read.hpp"
#include "drape/scene/scene_build.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  drape::formats::vrml::ReadOptions options;
  options.limits.seconds = 5.0;
  options.limits.memoryBytes = std::size_t{1} << 30;
  try {
    // Relative Inline/EXTERNPROTO URLs resolve against the real data, so inputs that
    // mutate GR001's Inlines reach the Inline path.
    const auto document =
        drape::formats::vrml::readText(text, "fuzz.wrl", DRAPE_SOURCE_DIR "/data/vrml/choreonoid_GR001", options);
    (void)drape::scene::buildScene(document);
  } catch (const drape::Error&) {
    // A clear message: the expected outcome for malformed input.
  }
  return 0;
}
