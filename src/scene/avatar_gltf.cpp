#include "drape/scene/avatar_gltf.hpp"

#include <algorithm>
#include <filesystem>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/scene/avatar_makehuman.hpp"
#include "drape/scene/avatar_segment.hpp"

namespace drape::scene {

Avatar buildAvatarFromSkinnedModel(const formats::GltfSkinnedModel& model) {
  Avatar avatar;
  avatar.source = model.source;
  avatar.name = std::filesystem::path(model.source).stem().string();
  for (const formats::GltfJoint& j : model.joints) {
    Joint joint;
    joint.name = j.name;
    joint.parent = j.parent;
    joint.restCenter = j.restWorld.block<3, 1>(0, 3);
    // The paper's transform reset (section 4.2): joint frames carry no rotation or scale
    // of the file's own; segments are stored in root-aligned axes at unit scale.
    joint.restOrientation = Quat::Identity();
    avatar.joints.push_back(joint);
  }
  SkinnedMesh skin;
  skin.mesh.name = avatar.name;
  skin.mesh.positions = model.positions;
  skin.mesh.triangles = model.triangles;
  skin.joints = model.vertexJoints;
  skin.weights = model.vertexWeights;
  avatar.skin = std::move(skin);
  segmentSkinnedAvatar(avatar);
  return avatar;
}

Avatar loadGltfAvatar(const std::string& path) { return buildAvatarFromSkinnedModel(formats::readGltfSkinnedModel(path)); }

Avatar loadAvatarFile(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".glb" || ext == ".gltf") return loadGltfAvatar(path);
  if (ext == ".mhskel") return loadMakeHumanAvatar(path);
  throw Error(fmt::format("{}: drape reads avatars from .glb, .gltf and MakeHuman .mhskel files, not '{}'", path, ext));
}

}  // namespace drape::scene
