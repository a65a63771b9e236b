// The signed distance to a closed mesh, against brute force (the nearest of every
// triangle's closest points) and the winding number (the side), on star-shaped meshes with
// random radii (dents, ridges and sharp corners everywhere) and on a cube (its distance is
// known in closed form), with points near the surface, far from it and outside the grid.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "drape/core/error.hpp"
#include "drape/mesh/closest_point.hpp"
#include "drape/mesh/surface_distance.hpp"

namespace drape::mesh {
namespace {

/// A latitude-longitude sphere whose vertices lie at random radii in [1 - bump, 1 + bump]
/// around `centre`: closed, manifold, and embedded (every triangle is a radial graph), with
/// its triangles turned outwards.
TriMesh bumpySphere(std::mt19937& rng, const Vec3& centre, double bump, int rings, int around) {
  std::uniform_real_distribution<double> radius(1.0 - bump, 1.0 + bump);
  TriMesh m;
  const auto at = [&](double theta, double phi) -> Vec3 {
    return centre + radius(rng) * Vec3(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
  };
  m.positions.push_back(at(0, 0));  // north pole
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < around; ++s)
      m.positions.push_back(at(std::numbers::pi * r / rings, 2 * std::numbers::pi * s / around));
  m.positions.push_back(at(std::numbers::pi, 0));  // south pole
  const auto ring = [&](int r, int s) { return static_cast<std::uint32_t>(1 + (r - 1) * around + (s % around)); };
  const auto south = static_cast<std::uint32_t>(m.positions.size() - 1);
  for (int s = 0; s < around; ++s) {
    m.triangles.push_back({0, ring(1, s + 1), ring(1, s)});
    m.triangles.push_back({south, ring(rings - 1, s), ring(rings - 1, s + 1)});
    for (int r = 1; r + 1 < rings; ++r) {
      m.triangles.push_back({ring(r, s), ring(r, s + 1), ring(r + 1, s)});
      m.triangles.push_back({ring(r, s + 1), ring(r + 1, s + 1), ring(r + 1, s)});
    }
  }
  if (windingNumber(m.positions, m.triangles, centre) < 0)
    for (Triangle& t : m.triangles) std::swap(t[1], t[2]);
  return m;
}

double bruteForceDistance(const TriMesh& m, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const Triangle& t : m.triangles)
    best = std::min(best, (p - closestOnTriangle(p, m.positions[t[0]], m.positions[t[1]], m.positions[t[2]])).norm());
  return best;
}

TEST(SurfaceDistance, TheNearestPointAndItsSideAsBruteForceAndTheWindingNumberSay) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int inside = 0, outside = 0, nearSurface = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Vec3 centre(unit(rng), unit(rng), unit(rng));
    const double bump = trial % 2 == 0 ? 0.05 : 0.35;  // gentle, or sharp ridges and pits
    const TriMesh m = bumpySphere(rng, centre, bump, 6 + trial % 7, 5 + trial % 11);
    const SurfaceDistance distance(m.positions, m.triangles);
    for (int q = 0; q < 200; ++q) {
      Vec3 p = centre + 2.5 * Vec3(unit(rng), unit(rng), unit(rng));
      if (q % 3 == 0) {  // just off the surface, where the side is hardest to tell
        const Triangle& t = m.triangles[rng() % m.triangles.size()];
        std::uniform_real_distribution<double> w(0.0, 1.0);
        double a = w(rng), b = w(rng);
        if (q % 9 == 0) a = 0;  // on an edge
        if (q % 27 == 0) b = 0;  // on a corner
        if (a + b > 1) a = 1 - a, b = 1 - b;
        const Vec3 onSurface = m.positions[t[0]] + a * (m.positions[t[1]] - m.positions[t[0]]) +
                               b * (m.positions[t[2]] - m.positions[t[0]]);
        p = onSurface + 1e-3 * Vec3(unit(rng), unit(rng), unit(rng));
        ++nearSurface;
      }
      const SurfacePoint found = distance.at(p);
      const double expected = bruteForceDistance(m, p);
      ASSERT_NEAR(std::abs(found.distance_m), expected, 1e-12) << "trial " << trial << " point " << q;
      ASSERT_NEAR((found.point - p).norm(), expected, 1e-12);
      const Triangle& t = m.triangles[found.triangle];
      ASSERT_LT((closestOnTriangle(p, m.positions[t[0]], m.positions[t[1]], m.positions[t[2]]) - found.point).norm(),
                1e-12);
      if (expected < 1e-9) continue;  // on the surface: either side
      const bool in = windingNumber(m.positions, m.triangles, p) > 0.5;
      ASSERT_EQ(found.distance_m < 0, in) << "trial " << trial << " point " << q << " at " << expected;
      (in ? inside : outside) += 1;
    }
  }
  EXPECT_GT(inside, 1000);
  EXPECT_GT(outside, 1000);
  EXPECT_GT(nearSurface, 2000);
}

// Spheres crumpled by random moves of their vertices pass through themselves, where a
// pseudo-normal may point the wrong way: an inside is only ever where the winding number
// says so too, and the distances are brute force's all the same.
TEST(SurfaceDistance, ACrumpledMeshCallsInsideOnlyWhatItsWindingNumberCallsInside) {
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int inside = 0, outside = 0;
  for (int trial = 0; trial < 20; ++trial) {
    TriMesh m = bumpySphere(rng, Vec3::Zero(), 0.1, 8, 12);
    for (Vec3& x : m.positions) x += 0.45 * Vec3(unit(rng), unit(rng), unit(rng));
    const SurfaceDistance distance(m.positions, m.triangles);
    for (int q = 0; q < 300; ++q) {
      const Vec3 p = 1.6 * Vec3(unit(rng), unit(rng), unit(rng));
      const SurfacePoint found = distance.at(p);
      ASSERT_NEAR(std::abs(found.distance_m), bruteForceDistance(m, p), 1e-12) << "trial " << trial;
      const double winding = windingNumber(m.positions, m.triangles, p);
      if (found.distance_m < 0) {
        ASSERT_GT(winding, 0.5) << "trial " << trial << " point " << q;
        ++inside;
      } else {
        ++outside;
      }
    }
  }
  EXPECT_GT(inside, 300);
  EXPECT_GT(outside, 300);
}

TEST(SurfaceDistance, ACubesDistanceInClosedForm) {
  // The unit cube [0, 1]^3 as 12 triangles: its sharp edges and corners are where a single
  // face's normal gives the wrong side.
  TriMesh cube;
  for (int i = 0; i < 8; ++i) cube.positions.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  const std::array<std::array<std::uint32_t, 4>, 6> faces{{{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}}};
  for (const auto& f : faces) {
    cube.triangles.push_back({f[0], f[1], f[2]});
    cube.triangles.push_back({f[0], f[2], f[3]});
  }
  ASSERT_NEAR(windingNumber(cube.positions, cube.triangles, Vec3(0.5, 0.5, 0.5)), 1.0, 1e-12);
  const SurfaceDistance distance(cube.positions, cube.triangles);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coordinate(-1.0, 2.0);
  for (int trial = 0; trial < 5000; ++trial) {
    const Vec3 p(coordinate(rng), coordinate(rng), coordinate(rng));
    const Vec3 outside = (p - p.cwiseMax(Vec3::Zero()).cwiseMin(Vec3::Ones()));
    const double expected = outside.norm() > 0 ? outside.norm() : -std::min({p.minCoeff(), 1.0 - p.maxCoeff()});
    ASSERT_NEAR(distance.at(p).distance_m, expected, 1e-12) << p.transpose();
  }
  // Far away, well outside the grid.
  EXPECT_NEAR(distance.at(Vec3(-40, 0.5, 0.5)).distance_m, 40.0, 1e-12);
  EXPECT_NEAR(distance.at(Vec3(30, 31, 1)).distance_m, std::sqrt(29.0 * 29.0 + 30.0 * 30.0), 1e-9);
}

TEST(SurfaceDistance, NoTrianglesIsInfinitelyFarAndABadIndexIsAnError) {
  const std::vector<Vec3> x{Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY()};
  EXPECT_TRUE(std::isinf(SurfaceDistance(x, {}).at(Vec3::Zero()).distance_m));
  const std::vector<Triangle> bad{{0, 1, 3}};
  EXPECT_THROW(SurfaceDistance(x, bad), Error);
}

}  // namespace
}  // namespace drape::mesh
