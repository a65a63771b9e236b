#pragma once
// A skinned character as plain data: what every skinned-avatar reader (glTF through
// drape's own reader, Collada and FBX through Assimp) hands back across the isolation
// child's pipe, and what the avatar writers take; and one of its animations as the sampled
// motion of its joints.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/mesh/trimesh.hpp"

namespace drape::formats {

struct SkinnedJoint {
  std::string name;                          ///< the node's name, or "joint<i>" if it has none
  int parent = -1;                           ///< nearest ancestor that is a joint; parents come first
  Eigen::Matrix4d restWorld = Eigen::Matrix4d::Identity();  ///< node world transform in the file's rest pose
};

struct SkinnedModel {
  std::string source;
  std::vector<SkinnedJoint> joints;
  std::vector<Vec3> positions;               ///< m, Y up, skinned with the rest-pose nodes
  std::vector<mesh::Triangle> triangles;
  std::vector<std::array<std::uint16_t, 4>> vertexJoints;  ///< indices into joints
  std::vector<std::array<float, 4>> vertexWeights;         ///< normalised to sum 1
  /// The file's animations by name ("animation <index>" if one has none), in the file's
  /// order: what the avatar could play as its own motion (a reader of the motion samples them).
  std::vector<std::string> animations;
  /// The meshes its skin moves, each by its node's name (its mesh's name, or "node <i>" /
  /// "mesh <i>", where the node has none), in the file's order; and those read, which are
  /// all of them unless the reader was asked for some by name (an avatar file that holds
  /// the character's clothes or hair as well as its body).
  std::vector<std::string> meshes, meshesRead;
};

/// One of an avatar file's animations as the motion of its skin's joints, sampled at a
/// fixed rate from the animation's first key time to its last.
struct SkinnedJointMotion {
  std::string animation;                  ///< its name, or "animation <index>"
  std::vector<std::string> animationNames;  ///< every animation's name ("animation <index>" if it has none)
  double rate = 30.0;                     ///< frames per second
  double start_s = 0.0, end_s = 0.0;      ///< the animation's first and last key times
  double floor_m = 0.0;                   ///< m, the lowest point of the skin at rest: the file's floor
  std::vector<std::string> joints;        ///< the skin's joints, parent-first and named as in SkinnedModel
  std::vector<int> parents;               ///< each joint's parent joint (-1: a root), earlier in the list
  std::vector<Vec3> restCenters;          ///< m, each joint's world position in the file's rest pose
  /// Frame-major, joint j of frame f at [f * joints.size() + j]: `rotation` turns the joint
  /// from its rest orientation (the rotation of W(t) W_rest^-1, W its node's world
  /// matrix), `translation` is its world position.
  std::vector<RigidTransform> frames;
  [[nodiscard]] std::size_t frameCount() const { return joints.empty() ? 0 : frames.size() / joints.size(); }
};

/// Plain-data round trips used across the process boundary. `name` is the file the bytes
/// came from, for messages.
[[nodiscard]] std::string serialise(const SkinnedModel& model);
[[nodiscard]] SkinnedModel deserialiseSkinnedModel(std::string_view bytes, const std::string& name);
[[nodiscard]] std::string serialise(const SkinnedJointMotion& motion);
[[nodiscard]] SkinnedJointMotion deserialiseJointMotion(std::string_view bytes, const std::string& name);
[[nodiscard]] std::string serialise(const std::vector<SkinnedJointMotion>& motions);
[[nodiscard]] std::vector<SkinnedJointMotion> deserialiseJointMotions(std::string_view bytes, const std::string& name);

namespace detail {
/// The most frames x joints a motion reader samples (560 MB of transforms).
constexpr std::size_t kMaxMotionTransforms = 10'000'000;
/// The name an animation is called by: its own, or "animation <index>".
[[nodiscard]] std::string animationName(const std::string& own, std::size_t index);
/// The index of the animation `which` names among `names`: by name, by its index in decimal
/// digits, or the first for "". Throws drape::Error("FILE: has no animation ...") listing them.
[[nodiscard]] std::size_t chooseAnimation(const std::vector<std::string>& names, const std::string& which,
                                          const std::string& file);
/// Frames of an animation from start_s to end_s at `rate`, both ends included; throws
/// naming the file when the rate is unusable or the sample would exceed kMaxMotionTransforms.
[[nodiscard]] std::size_t motionFrameCount(double start_s, double end_s, double rate, std::size_t joints,
                                           const std::string& animation, const std::string& file);
/// Appends `motion` to `motions`; throws naming the file when all of them together would
/// hold more than `cap` joint transforms.
void appendWithinCap(std::vector<SkinnedJointMotion>& motions, SkinnedJointMotion motion, const std::string& file,
                     std::size_t cap = kMaxMotionTransforms);
/// The lowest height of `positions` (the skin at rest), or of `joints` where there are none.
[[nodiscard]] double lowestOf(const std::vector<Vec3>& positions, const std::vector<Vec3>& joints);
/// A joint's motion from its world matrix now and the inverse of its rest world matrix:
/// the rotation nearest W(t) W_rest^-1 (its polar factor, since scaled chains leave it a
/// rotation only up to rounding, or a shear where scales animate) and its world position.
[[nodiscard]] RigidTransform jointMotionOf(const Eigen::Matrix4d& world, const Eigen::Matrix4d& restInverse);
}  // namespace detail

}  // namespace drape::formats
