// The closest point of a triangle, against a brute-force search over a fine barycentric
// grid of the triangle, on many random triangles and points (vertex, edge and face
// regions all occur).

#include <gtest/gtest.h>

#include <random>

#include "drape/mesh/closest_point.hpp"

namespace drape::mesh {
namespace {

TEST(ClosestPoint, MatchesABruteForceSearchOverTheTriangle) {
  std::mt19937 rng(5);
  std::normal_distribution<double> n;
  const auto random = [&] { return Vec3(n(rng), n(rng), n(rng)); };
  constexpr int kSteps = 200;  // grid spacing: the longest edge / 200
  int onVertex = 0, onEdge = 0, inside = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Vec3 a = random(), b = random(), c = random(), p = 2.0 * random();
    const Vec3 q = closestOnTriangle(p, a, b, c);
    // q lies on the triangle: its barycentric coordinates are in [0, 1] and it is in the plane.
    const Vec3 normal = (b - a).cross(c - a);
    EXPECT_NEAR(normal.normalized().dot(q - a), 0.0, 1e-9);
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= kSteps; ++i)
      for (int j = 0; i + j <= kSteps; ++j) {
        const Vec3 s = a + (b - a) * (double(i) / kSteps) + (c - a) * (double(j) / kSteps);
        best = std::min(best, (p - s).norm());
      }
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const double found = (p - q).norm();
    EXPECT_LE(found, best + 1e-12) << "trial " << trial;              // nothing on the grid is nearer
    EXPECT_GE(found, best - longest / kSteps) << "trial " << trial;  // and it is as near as the grid allows
    const double eps = 1e-9;
    if ((q - a).norm() < eps || (q - b).norm() < eps || (q - c).norm() < eps) ++onVertex;
    else if (std::abs(normal.normalized().dot((p - q).normalized())) < 1.0 - 1e-6) ++onEdge;
    else ++inside;
    // The region it names holds the point: that corner, a point of that edge, or the face
    // (p - q along the normal).
    const TrianglePoint f = closestOnTriangleFeature(p, a, b, c);
    EXPECT_EQ(f.point, q);
    const auto onSegment = [&](const Vec3& u, const Vec3& v) {
      return (q - closestOnTriangle(q, u, v, v)).norm() < 1e-9 * longest;
    };
    switch (f.feature) {
      case TriangleFeature::CornerA: EXPECT_EQ(q, a); break;
      case TriangleFeature::CornerB: EXPECT_EQ(q, b); break;
      case TriangleFeature::CornerC: EXPECT_EQ(q, c); break;
      case TriangleFeature::EdgeAB: EXPECT_TRUE(onSegment(a, b)) << trial; break;
      case TriangleFeature::EdgeBC: EXPECT_TRUE(onSegment(b, c)) << trial; break;
      case TriangleFeature::EdgeCA: EXPECT_TRUE(onSegment(c, a)) << trial; break;
      case TriangleFeature::Face:
        EXPECT_GT(std::abs(normal.normalized().dot((p - q).normalized())), 1.0 - 1e-6) << trial;
        break;
    }
  }
  EXPECT_GT(onVertex, 10);
  EXPECT_GT(onEdge, 10);
  EXPECT_GT(inside, 10);
}

// The weights rebuild the point's projection onto the plane, and a point of the triangle
// has weights in [0, 1]; on many random triangles, points in and out of their plane.
TEST(Barycentric, RebuildsTheProjectionOntoTheTrianglesPlane) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  const auto point = [&] { return Vec3(coordinate(random), coordinate(random), coordinate(random)); };
  for (int trial = 0; trial < 1000; ++trial) {
    const Vec3 a = point(), b = point(), c = point();
    const Vec3 n = (b - a).cross(c - a);
    if (n.norm() < 1e-3) continue;
    const Vec3 p = point();
    const Vec3 w = barycentric(p, a, b, c);
    EXPECT_NEAR(w.sum(), 1.0, 1e-9);
    const Vec3 projection = p - (p - a).dot(n) / n.squaredNorm() * n;
    EXPECT_LT((w.x() * a + w.y() * b + w.z() * c - projection).norm(), 1e-9);
    const Vec3 onTriangle = closestOnTriangle(p, a, b, c);
    const Vec3 u = barycentric(onTriangle, a, b, c);
    EXPECT_GE(u.minCoeff(), -1e-9);
  }
  EXPECT_EQ(barycentric(Vec3(1, 2, 3), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()), Vec3(1, 0, 0));
}

}  // namespace
}  // namespace drape::mesh
