#include "drape/sim/garment_layers.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/core/error.hpp"

namespace drape::sim {

std::vector<std::vector<std::size_t>> garmentsBelow(const std::vector<GarmentSpec>& garments) {
  std::vector<std::vector<std::size_t>> below(garments.size());
  for (std::size_t g = 0; g < garments.size(); ++g)
    for (const std::string& name : garments[g].over) {
      const auto it = std::find_if(garments.begin(), garments.end(), [&](const GarmentSpec& s) { return s.name == name; });
      if (it == garments.end()) {
        std::vector<std::string> names;
        for (const GarmentSpec& s : garments) names.push_back(s.name);
        throw Error(fmt::format("garment '{}' is worn over '{}', which is not among the garments simulated with it "
                                "({}): a garment steps with the garments it is worn over",
                                garments[g].name, name, fmt::join(names, ", ")));
      }
      const auto b = static_cast<std::size_t>(it - garments.begin());
      if (b == g) throw Error(fmt::format("garment '{}' is worn over itself", garments[g].name));
      if (std::find(below[g].begin(), below[g].end(), b) == below[g].end()) below[g].push_back(b);
    }
  const std::vector<int> layers = layersOf(below);
  for (std::size_t g = 0; g < garments.size(); ++g)
    if (layers[g] < 0)
      throw Error(fmt::format("garment '{}' is worn, through the garments it is worn over, over itself: the over "
                              "names must not go round",
                              garments[g].name));
  return below;
}

namespace {

/// Points on triangle (a, b, c) no farther apart than `spacing`, its corners left out. The
/// corners by value: they may be elements of `points`, which grows.
void sampleTriangle(const Vec3 a, const Vec3 b, const Vec3 c, double spacing, std::vector<Vec3>& points) {
  const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
  const int n = static_cast<int>(std::ceil(longest / spacing));
  if (n < 2) return;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j) {
      if ((i == 0 && j == 0) || i == n || j == n) continue;
      points.push_back(a + (b - a) * (double(i) / n) + (c - a) * (double(j) / n));
    }
}

/// The spacing of the body's points a garment worn over others is given, in its gaps: as
/// near as it is worn over them.
constexpr double kBodySpacingGaps = 2.0;

}  // namespace

std::vector<Vec3> restBodyPoints(const scene::Avatar& avatar, const std::vector<std::string>& segments,
                                 double spacing_m) {
  std::vector<Vec3> points;
  for (const scene::Segment& s : avatar.segments) {
    if (std::find(segments.begin(), segments.end(), s.name) == segments.end()) continue;
    const RigidTransform rest = avatar.joints[static_cast<std::size_t>(s.joint)].restWorld();
    const std::size_t first = points.size();
    for (const Vec3& p : s.mesh.positions) points.push_back(rest.apply(p));
    if (!(spacing_m > 0.0)) continue;
    for (const mesh::Triangle& t : s.mesh.triangles)
      sampleTriangle(points[first + t[0]], points[first + t[1]], points[first + t[2]], spacing_m, points);
  }
  return points;
}

std::unique_ptr<cloth::LayerCollider> makeLayerCollider(
    const std::vector<GarmentSpec>& garments, std::size_t g, std::span<const std::size_t> below,
    const std::vector<std::uint32_t>& fixed, const std::function<cloth::ClothSolver&(std::size_t)>& solver,
    double frame_s, const scene::Avatar* avatar) {
  const GarmentSpec& spec = garments[g];
  if (!(spec.selfCollision_m > 0) && below.empty()) return nullptr;
  cloth::ClothSolver& own = solver(g);
  auto layers = std::make_unique<cloth::LayerCollider>(own.model(), spec.name, spec.selfCollision_m, spec.collisionEvery);
  layers->setFixedVertices(fixed);
  layers->setStitches(spec.stitches);
  for (const std::size_t b : below)
    layers->addGarmentBelow(solver(b).model(), garments[b].name, solver(b).state(), spec.overGap_m, frame_s);
  if (!below.empty() && avatar)
    layers->setBody(restBodyPoints(*avatar, spec.collidesWith, kBodySpacingGaps * spec.overGap_m));
  layers->initialise(own.state());
  layers->liftOver(own.mutableState());  // what was modelled under the garments below, out over them
  return layers;
}

}  // namespace drape::sim
