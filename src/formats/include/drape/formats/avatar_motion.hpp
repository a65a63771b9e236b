#pragma once
// The animations avatar files carry, whatever their format: glTF through drape's own reader
// (gltf_avatar.hpp), Collada and FBX through Assimp (assimp_avatar.hpp), VRML97 H-Anim
// humanoids' interpolators through Coin (hanim_motion.hpp), each in a limited child
// process, each sampled the same way into a SkinnedJointMotion.

#include <string>
#include <vector>

#include "drape/formats/skinned_model.hpp"

namespace drape::formats {

/// True for the extensions whose files may carry their avatar's animations (.glb, .gltf,
/// .dae, .fbx, .wrl, .vrml; any case).
[[nodiscard]] bool isAvatarMotionPath(const std::string& path);

/// One animation of the file (a name, an index from 0, or "" for the first) sampled at
/// `rate` frames per second. Throws drape::Error naming the file.
[[nodiscard]] SkinnedJointMotion readAvatarMotion(const std::string& path, double rate, const std::string& animation = "");

/// Every animation of the file, sampled at `rate` (none: an empty list).
[[nodiscard]] std::vector<SkinnedJointMotion> readAvatarMotions(const std::string& path, double rate);

}  // namespace drape::formats
