// libFuzzer target: Collada bytes through the garment mesh reader (and the weld), the Assimp skinned-avatar reader in process (so
// the fuzzer sees crashes the isolation child would hide: drape's checks before Assimp,
// Assimp's importer behind them, and drape's reading of the scene it returns), then the
// plain-data round trip; then its animations. Assimp itself is not instrumented: coverage guides drape's side.

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "drape/core/error.hpp"
#include "drape/formats/mesh_file.hpp"
#include "drape/mesh/weld.hpp"
#include "drape/formats/assimp_avatar.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {  // as a garment: every mesh at rest, welded
    (void)drape::mesh::weld(drape::formats::parseAssimpMesh(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.dae", {}).mesh);
  } catch (const drape::Error&) {
  }
  try {
    const drape::formats::SkinnedModel model =
        drape::formats::parseAssimpSkinnedModel(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.dae");
    (void)drape::formats::deserialiseSkinnedModel(drape::formats::serialise(model), "fuzz.dae");
    // Its animations, sampled at 1 Hz (a long one is refused by the sample's cap, not run).
    const std::vector<drape::formats::SkinnedJointMotion> motions =
        drape::formats::parseAssimpJointMotions(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.dae", 1.0);
    (void)drape::formats::deserialiseJointMotions(drape::formats::serialise(motions), "fuzz.dae");
  } catch (const drape::Error&) {
  }
  return 0;
}
