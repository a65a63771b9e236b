#include "drape/scene/garment_fit.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "drape/core/error.hpp"

namespace drape::scene {
namespace {

std::vector<Vec3> restWorldVertices(const Avatar& avatar, const std::string& segmentName) {
  const int s = avatar.findSegment(segmentName);
  if (s < 0) throw Error(fmt::format("{}: the avatar has no segment '{}' to fit a skirt to", avatar.source, segmentName));
  const Segment& seg = avatar.segments[static_cast<std::size_t>(s)];
  const RigidTransform rest = avatar.joints[static_cast<std::size_t>(seg.joint)].restWorld();
  std::vector<Vec3> out;
  out.reserve(seg.mesh.positions.size());
  for (const Vec3& p : seg.mesh.positions) out.push_back(rest.apply(p));
  return out;
}

}  // namespace

mesh::Skirt fitSkirt(const Avatar& avatar, const SkirtFit& fit) {
  const std::vector<Vec3> waist = restWorldVertices(avatar, fit.waistSegment);
  std::vector<Vec3> body = waist;
  for (const std::string& hip : fit.hipSegments) {
    if (avatar.findSegment(hip) < 0) continue;
    const std::vector<Vec3> v = restWorldVertices(avatar, hip);
    body.insert(body.end(), v.begin(), v.end());
  }
  for (const std::string& leg : fit.legSegments) {
    if (avatar.findSegment(leg) < 0) continue;
    const std::vector<Vec3> v = restWorldVertices(avatar, leg);
    body.insert(body.end(), v.begin(), v.end());
  }
  Aabb waistBox;
  for (const Vec3& p : waist) waistBox.extend(p);
  Aabb bodyBox;
  for (const Vec3& p : body) bodyBox.extend(p);

  mesh::SkirtShape shape;
  shape.segments = fit.segments;
  shape.rings = fit.rings;
  // The waist: at the waist segment's joint, centred on the segment.
  const int waistSegment = avatar.findSegment(fit.waistSegment);
  const double waistY =
      avatar.joints[static_cast<std::size_t>(avatar.segments[static_cast<std::size_t>(waistSegment)].joint)].restCenter.y();
  shape.length = fit.length_m > 0 ? fit.length_m : 0.55 * (waistY - bodyBox.min.y());
  Vec3 centre = waistBox.center();
  centre.y() = waistY;
  shape.waistCentre = centre;

  // The body's half-extents in x and z within each ring's band, about the skirt's axis.
  const double band = shape.length / shape.rings;
  double rx = 0, rz = 0;
  for (int r = 0; r <= shape.rings; ++r) {
    const double y = waistY - band * r;
    double hx = 0, hz = 0;
    for (const Vec3& p : body) {
      if (std::abs(p.y() - y) > 0.5 * band + (r == 0 ? 0.01 : 0.0)) continue;
      hx = std::max(hx, std::abs(p.x() - centre.x()));
      hz = std::max(hz, std::abs(p.z() - centre.z()));
    }
    // Radii never shrink going down.
    // The waistband sits close (it is bound there); below it, an ellipse through the box
    // corners of the outline would need sqrt(2) times the half-extents, 1.15 covers the
    // rounded body here.
    const double round = r == 0 ? 1.0 : 1.15;
    const double clearance = r == 0 ? 0.5 * fit.clearance_m : fit.clearance_m;
    rx = std::max(rx, round * hx + clearance);
    rz = std::max(rz, round * hz + clearance);
    shape.ringRadiusX.push_back(rx + fit.flare * band * r);
    shape.ringRadiusZ.push_back(rz + fit.flare * band * r);
  }
  mesh::Skirt skirt = mesh::makeSkirt(shape);
  skirt.mesh.name = "skirt";
  return skirt;
}

}  // namespace drape::scene
