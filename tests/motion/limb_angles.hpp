#pragma once
// How far a retargeted avatar's limbs point from the motion's own: the measure the
// retargeting tests hold every joint map to (a wrong pairing, left for right or thigh for
// shin, puts them tens of degrees apart).

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "drape/motion/animation.hpp"
#include "drape/motion/jointmap.hpp"
#include "drape/motion/skeleton.hpp"
#include "drape/scene/avatar.hpp"

namespace drape::motion {

/// Joint positions of the motion's own skeleton at frame f (forward kinematics: offsets are
/// in the parent's frame at rest, whose axes are the world's).
inline std::vector<Vec3> motionJointPositions(const Clip& clip, std::size_t f) {
  const Pose pose = clip.pose(f);
  const std::size_t n = clip.skeleton.size();
  std::vector<Quat> world(n);
  std::vector<Vec3> at(n);
  for (std::size_t j = 0; j < n; ++j) {
    const int parent = clip.skeleton.joints[j].parent;
    if (parent < 0) {
      world[j] = pose.local[j];
      at[j] = pose.rootTranslation;
      continue;
    }
    const auto p = static_cast<std::size_t>(parent);
    world[j] = world[p] * pose.local[j];
    at[j] = at[p] + world[p] * clip.skeleton.joints[j].offset;
  }
  return at;
}

/// The largest angle, over the clip's frames and the limb bones named (motion joint and its
/// child, as the map names them), between a bone's direction in the motion and the same
/// bone's direction on the retargeted avatar, in degrees.
inline double largestLimbAngle_deg(const scene::Avatar& avatar, const Clip& clip, const JointMap& map,
                            const AvatarAnimation& anim, const std::vector<std::pair<std::string, std::string>>& bones) {
  double largest = 0.0;
  for (std::size_t f = 0; f < anim.frameCount(); ++f) {
    const std::vector<Vec3> motion = motionJointPositions(clip, f);
    const auto world = anim.frame(f);
    for (const auto& [from, to] : bones) {
      const Vec3 m = motion[static_cast<std::size_t>(clip.skeleton.find(from))] -
                     motion[static_cast<std::size_t>(clip.skeleton.find(to))];
      const auto avatarJoint = [&](const std::string& motionJoint) {
        return world[static_cast<std::size_t>(avatar.findJoint(*map.avatarJointFor(motionJoint)))].translation;
      };
      const Vec3 a = avatarJoint(from) - avatarJoint(to);
      const double cosine = std::clamp(m.normalized().dot(a.normalized()), -1.0, 1.0);
      largest = std::max(largest, std::acos(cosine) * 180.0 / 3.14159265358979323846);
    }
  }
  return largest;
}

}  // namespace drape::motion
