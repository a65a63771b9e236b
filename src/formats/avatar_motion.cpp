#include "drape/formats/avatar_motion.hpp"

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/core/files.hpp"
#include "drape/formats/assimp_avatar.hpp"
#include "drape/formats/gltf_avatar.hpp"
#include "drape/formats/hanim_motion.hpp"

namespace drape::formats {
namespace {

void checkPath(const std::string& path) {
  if (!isAvatarMotionPath(path))
    throw Error(fmt::format("{}: drape reads an avatar's own animations from .glb, .gltf, .vrm, .dae, .fbx and VRML97 (.wrl) "
                            "files, not '{}'",
                            path, lowerExtension(path)));
}

}  // namespace

bool isAvatarMotionPath(const std::string& path) {
  return isGltfPath(path) || isAssimpAvatarPath(path) || isVrmlPath(path);
}

SkinnedJointMotion readAvatarMotion(const std::string& path, double rate, const std::string& animation) {
  checkPath(path);
  if (isVrmlPath(path)) return readHanimMotion(path, rate, animation);
  return isGltfPath(path) ? readGltfJointMotion(path, rate, animation) : readAssimpJointMotion(path, rate, animation);
}

std::vector<SkinnedJointMotion> readAvatarMotions(const std::string& path, double rate) {
  checkPath(path);
  if (isVrmlPath(path)) return readHanimMotions(path, rate);
  return isGltfPath(path) ? readGltfJointMotions(path, rate) : readAssimpJointMotions(path, rate);
}

}  // namespace drape::formats
