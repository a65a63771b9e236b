#include "drape/field/shapes.hpp"

#include <cmath>
#include <numbers>
#include <vector>

namespace drape::field {
namespace {

// A closed surface of revolution about y from a profile (radius, y) that starts and ends on
// the axis (radius 0): one vertex at each pole, rings in between, counter-clockwise outward.
mesh::TriMesh revolve(const std::vector<std::pair<double, double>>& profile, int around, const std::string& name) {
  mesh::TriMesh m;
  m.name = name;
  const int rings = static_cast<int>(profile.size()) - 2;
  m.positions.emplace_back(0, profile.front().second, 0);
  for (int r = 1; r <= rings; ++r)
    for (int k = 0; k < around; ++k) {
      const double a = 2 * std::numbers::pi * k / around;
      m.positions.emplace_back(profile[r].first * std::cos(a), profile[r].second, -profile[r].first * std::sin(a));
    }
  m.positions.emplace_back(0, profile.back().second, 0);
  const auto ring = [&](int r, int k) { return static_cast<std::uint32_t>(1 + (r - 1) * around + (k % around)); };
  const std::uint32_t bottom = 0, top = static_cast<std::uint32_t>(m.positions.size() - 1);
  for (int k = 0; k < around; ++k) m.triangles.push_back({bottom, ring(1, k + 1), ring(1, k)});
  for (int r = 1; r < rings; ++r)
    for (int k = 0; k < around; ++k) {
      m.triangles.push_back({ring(r, k), ring(r, k + 1), ring(r + 1, k + 1)});
      m.triangles.push_back({ring(r, k), ring(r + 1, k + 1), ring(r + 1, k)});
    }
  for (int k = 0; k < around; ++k) m.triangles.push_back({ring(rings, k), ring(rings, k + 1), top});
  return m;
}

}  // namespace

mesh::TriMesh makeRoundedTube(double radiusBottom, double radiusTop, double height, int around, int along) {
  // Profile: bottom quarter circle, straight tapered side, top quarter circle.
  const int capSteps = std::max(2, along / 4);
  const int sideSteps = std::max(1, along - 2 * capSteps);
  const double yBottom = -0.5 * height + radiusBottom, yTop = 0.5 * height - radiusTop;
  std::vector<std::pair<double, double>> profile;
  for (int i = 0; i <= capSteps; ++i) {
    const double a = -0.5 * std::numbers::pi + 0.5 * std::numbers::pi * i / capSteps;
    profile.emplace_back(radiusBottom * std::cos(a), yBottom + radiusBottom * std::sin(a));
  }
  for (int i = 1; i < sideSteps; ++i) {
    const double t = static_cast<double>(i) / sideSteps;
    profile.emplace_back(radiusBottom + t * (radiusTop - radiusBottom), yBottom + t * (yTop - yBottom));
  }
  for (int i = 0; i <= capSteps; ++i) {
    const double a = 0.5 * std::numbers::pi * i / capSteps;
    profile.emplace_back(radiusTop * std::cos(a), yTop + radiusTop * std::sin(a));
  }
  profile.front().first = 0;
  profile.back().first = 0;
  return revolve(profile, around, "rounded tube");
}

mesh::TriMesh makeSphere(double radius, const Vec3& centre, int around, int along) {
  std::vector<std::pair<double, double>> profile;
  for (int i = 0; i <= along; ++i) {
    const double a = -0.5 * std::numbers::pi + std::numbers::pi * i / along;
    profile.emplace_back(i == 0 || i == along ? 0.0 : radius * std::cos(a), radius * std::sin(a));
  }
  mesh::TriMesh m = revolve(profile, around, "sphere");
  for (Vec3& p : m.positions) p += centre;
  return m;
}

mesh::TriMesh makeBox(const Vec3& lo, const Vec3& hi) {
  mesh::TriMesh m;
  m.name = "box";
  for (int i = 0; i < 8; ++i)
    m.positions.emplace_back((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
  // Quads (outward, counter-clockwise), split in two.
  const std::uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  return m;
}

void fitToBox(mesh::TriMesh& m, const Aabb& box) {
  const Aabb from = m.bounds();
  const Vec3 scale = box.size().cwiseQuotient(from.size());
  for (Vec3& p : m.positions) p = box.min + (p - from.min).cwiseProduct(scale);
}

}  // namespace drape::field
