#pragma once
// A segmented avatar (paper section 4.2): a joint hierarchy, each joint carrying rigid
// segment meshes. Loaders (H-Anim VRML97, glTF, MakeHuman) reset every segment to unit
// scale in its joint's frame, so a pose only needs each joint's world rigid transform:
//   segment vertex in world = jointWorld.apply(vertex in joint frame).
// "What it is" only: poses and clips live in motion/.

#include <optional>
#include <string>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/mesh/trimesh.hpp"

namespace drape::scene {

struct Joint {
  std::string name;
  int parent = -1;          ///< index into Avatar::joints; -1 for the root. Parents come first.
  Vec3 restCenter = Vec3::Zero();                ///< m, world position of the joint centre at rest
  Quat restOrientation = Quat::Identity();       ///< world orientation of the joint frame at rest
  /// World transform of the joint frame in the rest pose.
  [[nodiscard]] RigidTransform restWorld() const { return {restOrientation, restCenter}; }
};

struct Segment {
  std::string name;   ///< the name collision lists refer to (ClothSet.collidesWith)
  int joint = -1;     ///< index of the joint it moves with
  mesh::TriMesh mesh; ///< m, in the joint's frame
};

/// The skinned mesh a character is drawn with, when it came from a skinned source.
struct SkinnedMesh {
  mesh::TriMesh mesh;                                 ///< m, world rest pose
  std::vector<std::array<std::uint16_t, 4>> joints;   ///< per vertex, indices into Avatar::joints
  std::vector<std::array<float, 4>> weights;          ///< per vertex, summing to 1
};

struct Avatar {
  std::string name;
  std::string source;            ///< file it was loaded from, for messages
  std::vector<Joint> joints;
  std::vector<Segment> segments;
  std::optional<SkinnedMesh> skin;
  /// The animations the avatar's own file carries (a glTF, Collada or FBX file's, by name,
  /// in its order): the motion it plays when no other is given. Empty for the other
  /// sources (an H-Anim humanoid's interpolators are found where its file has ROUTEs).
  std::vector<std::string> animations;
  /// A glTF, Collada or FBX file's skinned meshes (by node or mesh name), and those its
  /// skin was built from: all of them, or those the Avatar node's `meshes` chose.
  std::vector<std::string> fileMeshes, meshesRead;
  /// Skinned meshes of the same file drawn with the body and moved by its skeleton, but no
  /// part of the body the cloth collides with (hair, eyes, accessories: the Avatar node's
  /// drawnMeshes), and the names they were read by. Never segmented, fitted or tucked.
  std::optional<SkinnedMesh> drawnSkin;
  std::vector<std::string> drawnMeshesRead;

  /// Index of the joint named `name`, or -1.
  [[nodiscard]] int findJoint(const std::string& name) const {
    for (std::size_t i = 0; i < joints.size(); ++i)
      if (joints[i].name == name) return static_cast<int>(i);
    return -1;
  }
  /// Every segment's name, in order (for messages that list what the avatar has).
  [[nodiscard]] std::vector<std::string> segmentNames() const {
    std::vector<std::string> names;
    for (const Segment& s : segments) names.push_back(s.name);
    return names;
  }
  /// Index of the segment named `name`, or -1.
  [[nodiscard]] int findSegment(const std::string& name) const {
    for (std::size_t i = 0; i < segments.size(); ++i)
      if (segments[i].name == name) return static_cast<int>(i);
    return -1;
  }
};

/// Places an avatar loaded in its own frame: scaled about its origin, then moved rigidly (an
/// Avatar node's scale, rotation and translation; a quarter turn that stands a Z-up body up).
void placeAvatar(Avatar& avatar, const RigidTransform& placement, double scale = 1.0);

}  // namespace drape::scene
