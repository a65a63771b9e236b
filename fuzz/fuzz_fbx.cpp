// libFuzzer target: FBX bytes (binary or ASCII) through the Assimp skinned-avatar reader in process (so
// the fuzzer sees crashes the isolation child would hide: drape's checks before Assimp,
// Assimp's importer behind them, and drape's reading of the scene it returns), then the
// plain-data round trip. Assimp itself is not instrumented: coverage guides drape's side.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "drape/core/error.hpp"
#include "drape/formats/assimp_avatar.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const drape::formats::SkinnedModel model =
        drape::formats::parseAssimpSkinnedModel(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.fbx");
    (void)drape::formats::deserialiseSkinnedModel(drape::formats::serialise(model), "fuzz.fbx");
  } catch (const drape::Error&) {
  }
  return 0;
}
