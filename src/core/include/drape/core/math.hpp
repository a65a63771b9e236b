#pragma once
// Math vocabulary shared by every module. Units are SI throughout (m, kg, s).
// Eigen types are for set-up and small algebra; hot loops run over plain SoA arrays.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace drape {

using Real = double;
using Vec3 = Eigen::Vector3d;
using Vec3f = Eigen::Vector3f;
using Vec3i = Eigen::Vector3i;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;

/// Axis-aligned bounding box (empty when min > max).
struct Aabb {
  Vec3 min = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 max = Vec3::Constant(-std::numeric_limits<double>::infinity());

  void extend(const Vec3& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  [[nodiscard]] bool empty() const { return (min.array() > max.array()).any(); }
  [[nodiscard]] Vec3 size() const { return empty() ? Vec3::Zero() : Vec3(max - min); }
  [[nodiscard]] Vec3 center() const { return 0.5 * (min + max); }
  [[nodiscard]] bool contains(const Vec3& p) const {
    return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
  }
  /// Whether the boxes overlap, or come within `gap` of each other.
  [[nodiscard]] bool overlaps(const Aabb& o, double gap = 0) const {
    return (min.array() <= o.max.array() + gap).all() && (o.min.array() <= max.array() + gap).all();
  }
};

/// A rigid transform x -> rotation * x + translation (no scale): a body part's pose,
/// a pinned fixture's motion, a joint's world transform (the paper's LTM).
struct RigidTransform {
  Quat rotation = Quat::Identity();
  Vec3 translation = Vec3::Zero();

  [[nodiscard]] static RigidTransform identity() { return {}; }
  [[nodiscard]] Vec3 apply(const Vec3& p) const { return rotation * p + translation; }
  [[nodiscard]] Vec3 applyVector(const Vec3& v) const { return rotation * v; }
  [[nodiscard]] RigidTransform inverse() const {
    const Quat inv = rotation.conjugate();
    return {inv, -(inv * translation)};
  }
  /// (a * b)(x) = a(b(x)).
  [[nodiscard]] RigidTransform operator*(const RigidTransform& b) const {
    return {(rotation * b.rotation).normalized(), rotation * b.translation + translation};
  }
};

/// The axis-aligned box around `b`'s corners moved by `pose`.
[[nodiscard]] inline Aabb moved(const Aabb& b, const RigidTransform& pose) {
  Aabb out;
  for (int corner = 0; corner < 8; ++corner)
    out.extend(pose.apply(Vec3((corner & 1) ? b.max.x() : b.min.x(), (corner & 2) ? b.max.y() : b.min.y(),
                               (corner & 4) ? b.max.z() : b.min.z())));
  return out;
}

}  // namespace drape
