#include "drape/motion/interpolate.hpp"

#include <cmath>

namespace drape::motion {

Quat slerp(const Quat& a, const Quat& b, double s) {
  // Exact endpoints: substep 0 and substep N must equal the frames themselves.
  if (s <= 0.0) return a;
  if (s >= 1.0) return b;
  double dot = a.dot(b);
  const double sign = dot < 0.0 ? -1.0 : 1.0;  // q and -q are the same rotation: take the short way
  dot *= sign;
  double wa = 1.0 - s;
  double wb = s;
  if (dot < 0.9999999) {
    // sin-weighted blend: constant angular speed along the great arc
    const double theta = std::acos(std::min(dot, 1.0));
    const double sinTheta = std::sin(theta);
    wa = std::sin((1.0 - s) * theta) / sinTheta;
    wb = std::sin(s * theta) / sinTheta;
  }
  wb *= sign;
  Quat q(wa * a.w() + wb * b.w(), wa * a.x() + wb * b.x(), wa * a.y() + wb * b.y(), wa * a.z() + wb * b.z());
  q.normalize();
  return q;
}

RigidTransform interpolate(const RigidTransform& a, const RigidTransform& b, double s) {
  if (s <= 0.0) return a;
  if (s >= 1.0) return b;
  return {slerp(a.rotation, b.rotation, s), (1.0 - s) * a.translation + s * b.translation};
}

}  // namespace drape::motion
