#pragma once
// Captures that stand along another axis than +y, stood up as they load. BVH and ASF/AMC
// files from capture studios stand along +y, as drape's scenes do; files from robotics and
// CAD tools, and some exporters, stand along +z. The rest skeleton's shape tells which
// (scene::findUpright), and the whole clip is turned by the quarter turn that stands it up:
// every joint's world position turns with it, so the motion is the same motion standing.

#include <span>
#include <string>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/motion/skeleton.hpp"
#include "drape/scene/humanoid.hpp"

namespace drape::motion {

/// The skeleton's joints at rest (every rotation zero), as scene::findHumanoid reads them.
[[nodiscard]] std::vector<scene::JointAt> jointsAt(const Skeleton& skeleton);

/// How a capture's skeleton stood: "+y" with no turn where it is a humanoid standing so or
/// no humanoid along any axis, else the axis scene::findUpright finds and its turn.
struct Standing {
  std::string axis = "+y";
  Quat turn = Quat::Identity();
};

/// Stands the clip up along +y where its skeleton is a humanoid along another axis: its
/// offsets, end sites and every frame turned (turnPose); how it stood.
Standing standUp(Clip& clip);

/// Turns one frame: the root translation by `turn`, each local rotation q to turn q turn^-1,
/// which with the skeleton's offsets turned too turns every joint's world position and
/// conjugates its world rotation. Allocates nothing.
void turnPose(std::span<Quat> local, Vec3& root, const Quat& turn);

}  // namespace drape::motion
