#pragma once
// glTF 2.0 skinned characters (.gltf, .glb) as segmented avatars: one joint per skin
// joint (rest centre = the joint node's rest position, frame aligned with the root
// coordinate system), the skinned mesh kept for drawing, and one closed segment per joint
// that dominates any triangle (avatar_segment.hpp). The file is read in a limited child
// process (formats/gltf_avatar.hpp).

#include <string>

#include "drape/formats/gltf_avatar.hpp"
#include "drape/scene/avatar.hpp"

namespace drape::scene {

/// Builds the avatar from already-read glTF data (positions in metres).
[[nodiscard]] Avatar buildAvatarFromSkinnedModel(const formats::GltfSkinnedModel& model);

/// Reads and builds; throws drape::Error naming the file.
[[nodiscard]] Avatar loadGltfAvatar(const std::string& path);

/// Any avatar file drape reads: .glb/.gltf, or a MakeHuman .mhskel (the mesh and weights
/// beside it). Throws drape::Error for other extensions.
[[nodiscard]] Avatar loadAvatarFile(const std::string& path);

}  // namespace drape::scene
