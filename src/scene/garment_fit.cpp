#include "drape/scene/garment_fit.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/core/error.hpp"
#include "drape/formats/mhclo.hpp"
#include "drape/formats/obj.hpp"
#include "drape/scene/avatar_makehuman.hpp"

namespace drape::scene {
namespace {

std::vector<Vec3> restWorldVertices(const Avatar& avatar, const std::string& segmentName) {
  const int s = avatar.findSegment(segmentName);
  if (s < 0) {
    throw Error(fmt::format("{}: the avatar has no segment '{}' to fit a skirt to (its segments: {})", avatar.source,
                            segmentName, fmt::join(avatar.segmentNames(), ", ")));
  }
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

  // The half-extents in x and z of `points` within ring r's band, about the skirt's axis.
  const double band = shape.length / shape.rings;
  const auto extentsAt = [&](const std::vector<Vec3>& points, int r) {
    const double y = waistY - band * r;
    double hx = 0, hz = 0;
    for (const Vec3& p : points) {
      if (std::abs(p.y() - y) > 0.5 * band + (r == 0 ? 0.01 : 0.0)) continue;
      hx = std::max(hx, std::abs(p.x() - centre.x()));
      hz = std::max(hz, std::abs(p.z() - centre.z()));
    }
    return std::pair{hx, hz};
  };
  double rx = 0, rz = 0, wx = 0, wz = 0;
  for (int r = 0; r <= shape.rings; ++r) {
    const auto [hx, hz] = extentsAt(body, r);
    // Radii never shrink going down.
    // The waistband sits close (it is bound there); below it, an ellipse through the box
    // corners of the outline would need sqrt(2) times the half-extents, 1.15 covers the
    // rounded body here.
    const double round = r == 0 ? 1.0 : 1.15;
    const double clearance = r == 0 ? 0.5 * fit.clearance_m : fit.clearance_m;
    rx = std::max(rx, round * hx + clearance);
    rz = std::max(rz, round * hz + clearance);
    // A garment worn under it is cleared as it is (a skirt's rings are ellipses already),
    // its flare included.
    const auto [ux, uz] = extentsAt(fit.wornOver, r);
    const double gap = r == 0 ? fit.wornOverGap_m : 2.0 * fit.wornOverGap_m;
    if (ux > 0.0) wx = std::max(wx, ux + gap);
    if (uz > 0.0) wz = std::max(wz, uz + gap);
    shape.ringRadiusX.push_back(std::max(rx + fit.flare * band * r, wx));
    shape.ringRadiusZ.push_back(std::max(rz + fit.flare * band * r, wz));
  }
  mesh::Skirt skirt = mesh::makeSkirt(shape);
  skirt.mesh.name = "skirt";
  return skirt;
}

namespace {

std::string garmentObjPath(const formats::Mhclo& clo) {
  const std::filesystem::path dir = std::filesystem::path(clo.source).parent_path();
  if (!clo.objFile.empty() && std::filesystem::exists(dir / clo.objFile)) return (dir / clo.objFile).string();
  std::filesystem::path beside(clo.source);
  beside.replace_extension(".obj");
  if (std::filesystem::exists(beside)) return beside.string();
  throw Error(fmt::format("{}: its mesh is neither '{}' nor '{}' beside it", clo.source, clo.objFile,
                          beside.filename().string()));
}

/// MakeHuman's per-axis offset scale: how far apart two base vertices are on this body
/// relative to the body the offsets were made on (base units; the ratio carries the units).
Vec3 offsetScale(const formats::Mhclo& clo, const std::vector<Vec3>& base, double metresPerBaseUnit) {
  Vec3 s = Vec3::Constant(metresPerBaseUnit);
  for (int axis = 0; axis < 3; ++axis) {
    if (!clo.hasScale[axis]) continue;
    const formats::MhcloScale& r = clo.scale[static_cast<std::size_t>(axis)];
    s[axis] = std::abs(base[r.a][axis] - base[r.b][axis]) / r.reference;
  }
  return s;
}

}  // namespace

MakeHumanGarment fitMakeHumanGarment(const std::string& mhcloPath, const std::string& mhskelPath) {
  const formats::Mhclo clo = formats::readMhclo(mhcloPath);
  const std::vector<Vec3> base = loadMakeHumanBaseVertices(mhskelPath);
  const double metresPerBaseUnit = MakeHumanAvatarOptions{}.metresPerUnit;
  formats::ObjReadOptions read;
  read.metresPerUnit = metresPerBaseUnit;  // MakeHuman garments share the base mesh's units
  read.keepUnusedVertices = true;
  MakeHumanGarment g;
  g.modelled = formats::readObj(garmentObjPath(clo), read);
  if (g.modelled.vertexCount() != clo.vertices.size())
    throw Error(fmt::format("{}: fits {} vertices, but its mesh has {}", mhcloPath, clo.vertices.size(),
                            g.modelled.vertexCount()));
  if (clo.largestBaseIndex >= base.size())
    throw Error(fmt::format("{}: uses base-mesh vertex {}, but the base mesh beside {} has {} vertices", mhcloPath,
                            clo.largestBaseIndex, mhskelPath, base.size()));
  for (const formats::MhcloScale& r : clo.scale)
    if (r.a >= base.size() || r.b >= base.size())
      throw Error(fmt::format("{}: a scale line uses a vertex beyond the base mesh's {}", mhcloPath, base.size()));
  const Vec3 scale = offsetScale(clo, base, metresPerBaseUnit);
  g.fitted = g.modelled;
  for (std::size_t i = 0; i < clo.vertices.size(); ++i) {
    const formats::MhcloVertex& v = clo.vertices[i];
    Vec3 p = v.offset.cwiseProduct(scale);
    for (std::size_t k = 0; k < 3; ++k) p += v.weight[k] * base[v.base[k]];
    g.fitted.positions[i] = p;
  }
  return g;
}

}  // namespace drape::scene
