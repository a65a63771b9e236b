#include "drape/motion/standing.hpp"

#include <optional>

namespace drape::motion {

std::vector<scene::JointAt> jointsAt(const Skeleton& skeleton) {
  const std::vector<Vec3> rest = skeleton.restPositions();
  std::vector<scene::JointAt> out;
  out.reserve(skeleton.size());
  for (std::size_t i = 0; i < skeleton.size(); ++i) out.push_back({skeleton.joints[i].parent, rest[i]});
  return out;
}

void turnPose(std::span<Quat> local, Vec3& root, const Quat& turn) {
  const Quat back = turn.conjugate();
  for (Quat& q : local) q = (turn * q * back).normalized();
  root = turn * root;
}

Standing standUp(Clip& clip) {
  const std::optional<scene::Upright> u = scene::uprightAlongAnotherAxis(jointsAt(clip.skeleton));
  if (!u) return {};
  for (SkeletonJoint& j : clip.skeleton.joints) {
    j.offset = u->turn * j.offset;
    if (j.endSite) *j.endSite = u->turn * *j.endSite;
  }
  const std::size_t n = clip.skeleton.size();
  for (std::size_t f = 0; f < clip.frameCount(); ++f)
    turnPose({clip.rotations.data() + f * n, n}, clip.rootTranslations[f], u->turn);
  return {u->axis, u->turn};
}

}  // namespace drape::motion
