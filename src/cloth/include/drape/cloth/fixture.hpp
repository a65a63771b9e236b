#pragma once
// Fixtures (paper section 4.1): vertices that do not move freely but follow a rigid
// transform. A pin group holds its vertices' positions in the group's own frame; at the end
// of every substep they are set to pose(t1) applied to those positions, with the velocity
// that motion implies (or a blend of several groups' poses). "Pinned in place" is a group whose motion is the identity; a group
// bound to a body part follows that part's transform (given per substep by the caller).

#include <cstdint>
#include <memory>
#include <vector>

#include "drape/core/math.hpp"

namespace drape::cloth {

/// Where a fixture group's frame is at time t. One virtual call per group per substep.
/// A function of t alone: the same t gives the same pose, to the bit (the field collider
/// keeps each test's end transforms as the next test's start).
class FixtureMotion {
 public:
  virtual ~FixtureMotion() = default;
  [[nodiscard]] virtual RigidTransform poseAt(double t_s) const = 0;
};

/// A fixed frame (pinned in place).
class StaticMotion final : public FixtureMotion {
 public:
  explicit StaticMotion(const RigidTransform& pose = {}) : pose_(pose) {}
  [[nodiscard]] RigidTransform poseAt(double) const override { return pose_; }

 private:
  RigidTransform pose_;
};

/// A vertex may belong to several groups with weights (linear blend skinning): it is then
/// placed at the weighted sum of where each group's pose puts it, and moves with the
/// weighted sum of their velocities. Its weights over all groups sum to 1. A group without
/// weights places its vertices alone, after the weighted ones.
struct PinGroup {
  std::vector<std::uint32_t> vertices;     ///< garment vertex indices
  std::vector<double> localX, localY, localZ;  ///< their positions in the group frame, m
  std::shared_ptr<const FixtureMotion> motion;  ///< null: identity (pinned in place)
  std::vector<double> weight;  ///< empty: the group places its vertices alone; else each one's share

  /// Pins `vertices` where they are in `restPositions` (world = group frame at t = 0 when
  /// motion is null or poseAt(0) is the identity).
  [[nodiscard]] static PinGroup atRest(std::vector<std::uint32_t> vertices, const std::vector<double>& restX,
                                       const std::vector<double>& restY, const std::vector<double>& restZ,
                                       std::shared_ptr<const FixtureMotion> motion = nullptr);
};

}  // namespace drape::cloth
