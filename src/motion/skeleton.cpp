#include "drape/motion/skeleton.hpp"

#include <algorithm>

namespace drape::motion {

int Skeleton::find(std::string_view name) const {
  for (std::size_t i = 0; i < joints.size(); ++i)
    if (joints[i].name == name) return static_cast<int>(i);
  return -1;
}

std::vector<Vec3> Skeleton::restPositions() const {
  std::vector<Vec3> p(joints.size(), Vec3::Zero());
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const int parent = joints[i].parent;
    p[i] = (parent < 0 ? Vec3::Zero() : p[static_cast<std::size_t>(parent)]) + joints[i].offset;
  }
  return p;
}

double Skeleton::restExtent() const {
  const std::vector<Vec3> p = restPositions();
  Aabb box;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    box.extend(p[i]);
    if (joints[i].endSite) box.extend(p[i] + *joints[i].endSite);
  }
  return box.empty() ? 0.0 : box.size().maxCoeff();
}

void Skeleton::scale(double factor) {
  for (SkeletonJoint& j : joints) {
    j.offset *= factor;
    if (j.endSite) *j.endSite *= factor;
  }
}

Pose Clip::pose(std::size_t f) const {
  const auto r = frameRotations(f);
  return {std::vector<Quat>(r.begin(), r.end()), rootTranslations[f]};
}

void forwardKinematics(const Skeleton& skeleton, std::span<const Quat> local, const Vec3& root,
                       std::span<RigidTransform> outWorld) {
  for (std::size_t i = 0; i < skeleton.joints.size(); ++i) {
    const SkeletonJoint& j = skeleton.joints[i];
    if (j.parent < 0) {
      outWorld[i] = {local[i], root + j.offset};
    } else {
      const RigidTransform& p = outWorld[static_cast<std::size_t>(j.parent)];
      outWorld[i] = {(p.rotation * local[i]).normalized(), p.apply(j.offset)};
    }
  }
}

}  // namespace drape::motion
