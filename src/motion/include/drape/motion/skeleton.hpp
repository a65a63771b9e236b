#pragma once
// Skeletons, poses and clips: "what the motion is". A Skeleton is a joint tree with rest
// offsets; a Clip is a Skeleton plus one pose (local joint rotations and a root
// translation) per frame at a fixed rate, starting at a time code. Units are metres once
// loaded (clip_io.hpp converts file units). Clips are immutable after loading; playing
// one onto an avatar is AvatarAnimation's job (animation.hpp).

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/core/timecode.hpp"

namespace drape::motion {

struct SkeletonJoint {
  std::string name;
  int parent = -1;                  ///< index into Skeleton::joints; -1 for a root. Parents come first.
  Vec3 offset = Vec3::Zero();       ///< m, from the parent joint, in the parent's frame at rest
  std::optional<Vec3> endSite;      ///< m, tip of a leaf joint (BVH End Site), in this joint's frame
};

struct Skeleton {
  std::vector<SkeletonJoint> joints;

  [[nodiscard]] std::size_t size() const { return joints.size(); }
  /// Index of the joint named `name`, or -1.
  [[nodiscard]] int find(std::string_view name) const;
  /// World positions of every joint with all rotations zero (the skeleton's rest pose),
  /// the root at the origin.
  [[nodiscard]] std::vector<Vec3> restPositions() const;
  /// Largest extent of the rest pose's joints and end sites (m, or file units before
  /// scaling): used to guess units.
  [[nodiscard]] double restExtent() const;
  /// Multiplies every offset by `factor` (unit conversion).
  void scale(double factor);
};

/// One frame of motion: local joint rotations (relative to the parent, at the joint) and
/// the root's translation in the world.
struct Pose {
  std::vector<Quat> local;
  Vec3 rootTranslation = Vec3::Zero();  ///< m
};

struct Clip {
  std::string name;                   ///< for messages and summaries
  std::string source;                 ///< file it came from
  Skeleton skeleton;
  double rate = 30.0;                 ///< frames per second
  TimeCode start;                     ///< time code of frame 0
  std::vector<Quat> rotations;        ///< frame-major: frameCount() x skeleton.size() local rotations
  std::vector<Vec3> rootTranslations; ///< m, one per frame

  [[nodiscard]] std::size_t frameCount() const { return rootTranslations.size(); }
  /// s, time from the first frame to the last.
  [[nodiscard]] double duration() const {
    return frameCount() > 1 ? static_cast<double>(frameCount() - 1) / rate : 0.0;
  }
  [[nodiscard]] std::span<const Quat> frameRotations(std::size_t f) const {
    return {rotations.data() + f * skeleton.size(), skeleton.size()};
  }
  [[nodiscard]] Pose pose(std::size_t f) const;
};

/// Forward kinematics: world transforms of every joint of `skeleton` for the local
/// rotations `local` and root translation `root`. `outWorld` has skeleton.size() entries.
/// Allocates nothing.
void forwardKinematics(const Skeleton& skeleton, std::span<const Quat> local, const Vec3& root,
                       std::span<RigidTransform> outWorld);

}  // namespace drape::motion
