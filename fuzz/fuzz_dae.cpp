// libFuzzer target: Collada bytes through the Assimp skinned-avatar reader (in process,
// so the fuzzer sees crashes the isolation child would hide) and the segmentation that
// follows. Assimp is third-party code: a crash found here is a reason to keep the child
// process, and a check drape can make before Assimp sees the bytes.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "drape/core/error.hpp"
#include "drape/formats/assimp_avatar.hpp"
#include "drape/scene/avatar_gltf.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const drape::formats::SkinnedModel model =
        drape::formats::parseAssimpSkinnedModel(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.dae");
    (void)drape::scene::buildAvatarFromSkinnedModel(model);
  } catch (const drape::Error&) {
  }
  return 0;
}
