// libFuzzer target: glTF/GLB bytes through the garment mesh reader and the weld, the skinned-avatar reader (in process, so the
// fuzzer sees crashes the isolation child would hide), the segmentation that follows and the
// humanoid found by the skeleton's shape (along any axis), and through the animation
// sampler (at 1 Hz: the fuzzer's animations may be a day long).
// No folder is given: only data: URIs may load.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "drape/core/error.hpp"
#include "drape/formats/mesh_file.hpp"
#include "drape/mesh/weld.hpp"
#include "drape/formats/gltf_avatar.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/scene/humanoid.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {  // as a garment: every mesh at rest, welded
    (void)drape::mesh::weld(drape::formats::parseGltfMesh(bytes, "fuzz.glb", "", {}).mesh);
  } catch (const drape::Error&) {
  }
  try {
    const drape::formats::GltfJointMotion motion = drape::formats::parseGltfJointMotion(bytes, "fuzz.glb", "", 1.0);
    (void)motion.frameCount();
  } catch (const drape::Error&) {
  }
  try {
    const drape::formats::GltfSkinnedModel model =
        drape::formats::parseGltfSkinnedModel(bytes, "fuzz.glb", "");
    const drape::scene::Avatar avatar = drape::scene::buildAvatarFromSkinnedModel(model);
    (void)drape::scene::findUpright(drape::scene::jointsAt(avatar));
    (void)drape::formats::deserialiseSkinnedModel(drape::formats::serialise(model), "fuzz.glb");
    // Its first mesh alone, chosen by name, as an Avatar node's meshes field chooses.
    if (!model.meshes.empty()) (void)drape::formats::parseGltfSkinnedModel(bytes, "fuzz.glb", "", {model.meshes.front()});
  } catch (const drape::Error&) {
  }
  return 0;
}
