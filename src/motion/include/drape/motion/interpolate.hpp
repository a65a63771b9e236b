#pragma once
// Micro-interpolation primitives (paper section 4.3.1): between two motion frames a joint's
// world transform is interpolated per substep, translation linearly and rotation by SLERP.
// Both functions return their endpoints bit for bit at s = 0 and s = 1, so substep 0 and
// substep N of a frame reproduce the two frames exactly.

#include "drape/core/math.hpp"

namespace drape::motion {

/// Spherical linear interpolation from a (s = 0) to b (s = 1) along the shorter arc
/// (b is negated when a.b < 0), at constant angular speed. Inputs must be unit quaternions.
[[nodiscard]] Quat slerp(const Quat& a, const Quat& b, double s);

/// Translation (1 - s) a + s b, rotation slerp(a, b, s).
[[nodiscard]] RigidTransform interpolate(const RigidTransform& a, const RigidTransform& b, double s);

}  // namespace drape::motion
