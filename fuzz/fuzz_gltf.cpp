// libFuzzer target: glTF/GLB bytes through the skinned-avatar reader (in process, so the
// fuzzer sees crashes the isolation child would hide) and the segmentation that follows.
// No folder is given: only data: URIs may load.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "drape/core/error.hpp"
#include "drape/formats/gltf_avatar.hpp"
#include "drape/scene/avatar_gltf.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const drape::formats::GltfSkinnedModel model =
        drape::formats::parseGltfSkinnedModel(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.glb", "");
    (void)drape::scene::buildAvatarFromSkinnedModel(model);
    (void)drape::formats::deserialiseSkinnedModel(drape::formats::serialise(model), "fuzz.glb");
  } catch (const drape::Error&) {
  }
  return 0;
}
