#include "drape/formats/vrml_transform.hpp"

namespace drape::formats::vrml {
namespace {

Vec3 vec3(const Node& n, const char* name, const Vec3& fallback) {
  const Field* f = n.field(name);
  return f != nullptr && f->numbers.size() >= 3 ? Vec3(f->numbers[0], f->numbers[1], f->numbers[2]) : fallback;
}

Eigen::AngleAxisd rotationField(const Node& n, const char* name) {
  const Field* f = n.field(name);
  return f != nullptr ? rotationOf(f->numbers.data(), f->numbers.size()) : Eigen::AngleAxisd(0.0, Vec3::UnitZ());
}

}  // namespace

Eigen::AngleAxisd rotationOf(const double* numbers, std::size_t count) {
  if (count < 4) return {0.0, Vec3::UnitZ()};
  const Vec3 axis(numbers[0], numbers[1], numbers[2]);
  if (axis.norm() < 1e-12) return {0.0, Vec3::UnitZ()};
  return {numbers[3], axis.normalized()};
}

TransformFields TransformFields::of(const Node& node) {
  TransformFields t;
  t.translation = vec3(node, "translation", Vec3::Zero());
  t.center = vec3(node, "center", Vec3::Zero());
  t.rotation = rotationField(node, "rotation");
  t.scale = vec3(node, "scale", Vec3::Ones());
  t.scaleOrientation = rotationField(node, "scaleOrientation");
  return t;
}

Eigen::Affine3d TransformFields::matrix() const {
  Eigen::Affine3d t = Eigen::Affine3d::Identity();
  t.translate(translation);
  t.translate(center);
  t.rotate(rotation);
  t.rotate(scaleOrientation);
  t.scale(scale);
  t.rotate(scaleOrientation.inverse());
  t.translate(-center);
  return t;
}

bool isTransformLike(std::string_view type) {
  return type == "Transform" || type == "Joint" || type == "Site" || type == "Humanoid";
}

}  // namespace drape::formats::vrml
