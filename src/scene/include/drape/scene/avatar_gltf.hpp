#pragma once
// Skinned characters (glTF 2.0 .gltf/.glb through drape's own reader, Collada .dae and
// FBX .fbx through Assimp) as segmented avatars: one joint per skeleton joint (rest
// centre = the joint node's rest position, frame aligned with the root coordinate
// system), the skinned mesh kept for drawing, and one closed segment per joint that
// dominates any triangle (avatar_segment.hpp). Files are read in a limited child process
// (formats/gltf_avatar.hpp, formats/assimp_avatar.hpp).

#include <string>
#include <vector>

#include "drape/formats/gltf_avatar.hpp"
#include "drape/formats/skinned_model.hpp"
#include "drape/scene/avatar.hpp"

namespace drape::scene {

/// Builds the avatar from an already-read skinned model (positions in metres, Y up).
[[nodiscard]] Avatar buildAvatarFromSkinnedModel(const formats::SkinnedModel& model);

/// Reads and builds; throws drape::Error naming the file. `meshes`, when given, names the
/// skinned meshes that make the body (by node or mesh name): a file that also holds the
/// character's clothes or hair leaves those out of the body the cloth collides with.
[[nodiscard]] Avatar loadGltfAvatar(const std::string& path, const std::vector<std::string>& meshes = {});

/// Reads a Collada (.dae) or FBX (.fbx) skinned character through Assimp and builds it;
/// throws drape::Error naming the file. `meshes` as for loadGltfAvatar.
[[nodiscard]] Avatar loadAssimpAvatar(const std::string& path, const std::vector<std::string>& meshes = {});

/// The avatar's skinned mesh and skeleton as plain data, for the skinned-model writers
/// (joint frames are the avatar's: rest centre, root-aligned axes). Throws drape::Error if
/// the avatar has no skinned mesh.
[[nodiscard]] formats::SkinnedModel skinnedModelOf(const Avatar& avatar);

/// A VRML97 file of one H-Anim Humanoid (as `drape convert --to .wrl` writes them), read
/// as a scene (scene::loadScene) and its humanoid taken. Throws drape::Error naming the file
/// when it holds no Humanoid or several.
[[nodiscard]] Avatar loadHumanoidFile(const std::string& path);

/// Any avatar file drape reads: .glb/.gltf, .dae/.fbx, a MakeHuman .mhskel (the mesh and
/// weights beside it), or a VRML97 H-Anim humanoid (.wrl). Throws drape::Error for other
/// extensions, and for `meshes` (as for loadGltfAvatar) given with a file of one body.
/// `drawnMeshes` names skinned meshes of the same file drawn with the body but not part of
/// it (Avatar::drawnSkin: hair, eyes); a mesh both drawn and the body's is an error.
[[nodiscard]] Avatar loadAvatarFile(const std::string& path, const std::vector<std::string>& meshes = {},
                                    const std::vector<std::string>& drawnMeshes = {});

}  // namespace drape::scene
