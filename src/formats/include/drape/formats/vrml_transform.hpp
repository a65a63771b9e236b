#pragma once
// The VRML97 Transform's fields and matrix, shared by the scene builder (rest poses) and the
// H-Anim motion reader (the same fields as interpolators drive them over time). Joint, Site
// and Humanoid carry the same five fields.

#include <string_view>

#include <Eigen/Geometry>

#include "drape/core/math.hpp"
#include "drape/formats/vrml_tree.hpp"

namespace drape::formats::vrml {

struct TransformFields {
  Vec3 translation = Vec3::Zero();
  Vec3 center = Vec3::Zero();
  Eigen::AngleAxisd rotation{0.0, Vec3::UnitZ()};
  Vec3 scale = Vec3::Ones();
  Eigen::AngleAxisd scaleOrientation{0.0, Vec3::UnitZ()};

  /// The node's fields as written (defaults where a field is missing or short; a zero axis
  /// is no rotation).
  [[nodiscard]] static TransformFields of(const Node& node);
  /// T(translation) T(center) R(rotation) R(scaleOrientation) S(scale) R(-scaleOrientation)
  /// T(-center).
  [[nodiscard]] Eigen::Affine3d matrix() const;
};

/// An SFRotation's four numbers (axis x y z, angle in radians) as a rotation; a zero axis
/// or fewer than four numbers is no rotation.
[[nodiscard]] Eigen::AngleAxisd rotationOf(const double* numbers, std::size_t count);

/// Transform, Joint, Site and Humanoid: the node types with Transform's fields.
[[nodiscard]] bool isTransformLike(std::string_view type);

}  // namespace drape::formats::vrml
