#include "drape/scene/avatar_gltf.hpp"

#include <algorithm>
#include <filesystem>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/core/error.hpp"
#include "drape/core/files.hpp"
#include "drape/formats/assimp_avatar.hpp"
#include "drape/formats/hanim_motion.hpp"
#include "drape/formats/part_names.hpp"
#include "drape/scene/avatar_makehuman.hpp"
#include "drape/scene/avatar_segment.hpp"
#include "drape/scene/scene.hpp"

namespace drape::scene {
namespace {

/// The model's triangles, rest positions and weights as a skinned mesh called `name`.
SkinnedMesh skinnedMesh(const formats::SkinnedModel& model, const std::string& name) {
  SkinnedMesh skin;
  skin.mesh.name = name;
  skin.mesh.positions = model.positions;
  skin.mesh.triangles = model.triangles;
  skin.joints = model.vertexJoints;
  skin.weights = model.vertexWeights;
  return skin;
}

}  // namespace

Avatar buildAvatarFromSkinnedModel(const formats::SkinnedModel& model) {
  Avatar avatar;
  avatar.source = model.source;
  avatar.name = std::filesystem::path(model.source).stem().string();
  for (const formats::SkinnedJoint& j : model.joints) {
    Joint joint;
    joint.name = j.name;
    joint.parent = j.parent;
    joint.restCenter = j.restWorld.block<3, 1>(0, 3);
    // The paper's transform reset (section 4.2): joint frames carry no rotation or scale
    // of the file's own; segments are stored in root-aligned axes at unit scale.
    joint.restOrientation = Quat::Identity();
    avatar.joints.push_back(joint);
  }
  avatar.skin = skinnedMesh(model, avatar.name);
  avatar.animations = model.animations;
  avatar.fileMeshes = model.meshes;
  avatar.meshesRead = model.meshesRead;
  segmentSkinnedAvatar(avatar);
  return avatar;
}

Avatar loadGltfAvatar(const std::string& path, const std::vector<std::string>& meshes) {
  return buildAvatarFromSkinnedModel(formats::readGltfSkinnedModel(path, meshes));
}

Avatar loadAssimpAvatar(const std::string& path, const std::vector<std::string>& meshes) {
  return buildAvatarFromSkinnedModel(formats::readAssimpSkinnedModel(path, meshes));
}

formats::SkinnedModel skinnedModelOf(const Avatar& avatar) {
  if (!avatar.skin) throw Error(fmt::format("{}: the avatar has no skinned mesh to write", avatar.source));
  formats::SkinnedModel model;
  model.source = avatar.source;
  for (const Joint& j : avatar.joints) {
    formats::SkinnedJoint joint;
    joint.name = j.name;
    joint.parent = j.parent;
    const RigidTransform rest = j.restWorld();
    joint.restWorld.topLeftCorner<3, 3>() = rest.rotation.toRotationMatrix();
    joint.restWorld.block<3, 1>(0, 3) = rest.translation;
    model.joints.push_back(std::move(joint));
  }
  model.positions = avatar.skin->mesh.positions;
  model.triangles = avatar.skin->mesh.triangles;
  model.vertexJoints = avatar.skin->joints;
  model.vertexWeights = avatar.skin->weights;
  return model;
}

Avatar loadHumanoidFile(const std::string& path) {
  Scene scene = loadScene(path);
  if (scene.avatars.size() == 1) return std::move(scene.avatars.front());
  if (scene.avatars.empty()) throw Error(fmt::format("{}: has no H-Anim Humanoid to take as an avatar", path));
  std::vector<std::string> names;
  for (const Avatar& a : scene.avatars) names.push_back(fmt::format("'{}'", a.name));
  throw Error(fmt::format("{}: holds {} H-Anim Humanoids ({}); an avatar file holds one", path, names.size(),
                          fmt::join(names, ", ")));
}

namespace {

formats::SkinnedModel readSkinnedModel(const std::string& path, const std::vector<std::string>& parts) {
  return formats::isGltfPath(path) ? formats::readGltfSkinnedModel(path, parts)
                                   : formats::readAssimpSkinnedModel(path, parts);
}

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

/// `drawn` with each shell pattern (formats/part_names.hpp) replaced by the skinned meshes
/// of the file it matches that the body leaves out: `*` draws every one of them. A pattern
/// matching none of them is an error listing them.
std::vector<std::string> drawnNames(const Avatar& avatar, const std::string& path,
                                    const std::vector<std::string>& drawn) {
  std::vector<std::string> names, leftOut;
  for (const std::string& mesh : avatar.fileMeshes)
    if (!contains(avatar.meshesRead, mesh)) leftOut.push_back(mesh);
  for (const std::string& d : drawn) {
    if (!formats::isNamePattern(d)) {
      if (!contains(names, d)) names.push_back(d);
      continue;
    }
    bool any = false;
    for (const std::string& mesh : leftOut)
      if (formats::nameMatches(d, mesh)) {
        any = true;
        if (!contains(names, mesh)) names.push_back(mesh);
      }
    if (!any)
      throw Error(fmt::format("{}: drawnMeshes '{}' matches none of the skinned meshes the body leaves out ({})", path,
                              d,
                              leftOut.empty() ? std::string("none: the body is every mesh of its skin")
                                              : fmt::format("{}", fmt::join(leftOut, ", "))));
  }
  return names;
}

/// The meshes `drawn` names, read again from the avatar's file with its skeleton: the
/// readers build a file's skeleton from its skins whatever meshes are chosen, so the joint
/// indices are the body's. A mesh both drawn and the body's would be drawn twice.
/// `bodyUnnamed`: no meshes named the body, which is then every mesh of the skin.
void addDrawnMeshes(Avatar& avatar, const std::string& path, const std::vector<std::string>& drawn, bool bodyUnnamed) {
  const formats::SkinnedModel model = readSkinnedModel(path, drawnNames(avatar, path, drawn));
  std::vector<std::string> both;
  for (const std::string& name : model.meshesRead)
    if (contains(avatar.meshesRead, name)) both.push_back(name);
  if (!both.empty()) {
    const std::string why = bodyUnnamed ? fmt::format(" (the body is every mesh of its skin unless meshes names those "
                                                      "that make it; its skinned meshes: {})",
                                                      fmt::join(avatar.fileMeshes, ", "))
                                        : "";
    throw Error(fmt::format("{}: drawnMeshes ({}) name {}, which {} the body's: a mesh is drawn or makes the body, "
                            "not both{}",
                            path, fmt::join(drawn, ", "), fmt::join(both, ", "), both.size() == 1 ? "is" : "are", why));
  }
  if (model.joints.size() != avatar.joints.size())
    throw Error(fmt::format("{}: its drawn meshes were read with {} joints, its body with {}", path,
                            model.joints.size(), avatar.joints.size()),
                ExitCode::Internal);
  avatar.drawnSkin = skinnedMesh(model, avatar.name + " (drawn)");
  avatar.drawnMeshesRead = model.meshesRead;
}

}  // namespace

Avatar loadAvatarFile(const std::string& path, const std::vector<std::string>& meshes,
                      const std::vector<std::string>& drawnMeshes) {
  const std::string ext = lowerExtension(path);
  if (formats::isGltfPath(path) || ext == ".dae" || ext == ".fbx") {
    Avatar avatar = formats::isGltfPath(path) ? loadGltfAvatar(path, meshes) : loadAssimpAvatar(path, meshes);
    if (!drawnMeshes.empty()) addDrawnMeshes(avatar, path, drawnMeshes, meshes.empty());
    return avatar;
  }
  const bool makeHuman = ext == ".mhskel";
  if (!makeHuman && !formats::isVrmlPath(path))
    throw Error(fmt::format("{}: drape reads avatars from .glb, .gltf, .vrm, .dae, .fbx, MakeHuman .mhskel and VRML97 "
                            "H-Anim (.wrl) files, not '{}'",
                            path, ext));
  for (const auto& [field, names] : {std::pair{"meshes", &meshes}, std::pair{"drawnMeshes", &drawnMeshes}})
    if (!names->empty())
      throw Error(fmt::format("{}: {} ({}) choose among the skinned meshes of a glTF, Collada or FBX avatar; "
                              "a {} avatar is one body",
                              path, field, fmt::join(*names, ", "), makeHuman ? "MakeHuman" : "VRML97 H-Anim"));
  return makeHuman ? loadMakeHumanAvatar(path) : loadHumanoidFile(path);
}

}  // namespace drape::scene
