// mesh::weld against brute force: on random meshes whose vertices repeat a few points (as a
// renderer's file splits one point of the surface into several vertices), two vertices are
// one after welding exactly when they are at one position, and every triangle is kept,
// dropped as collapsed or dropped as a repeat, as a pass over all triangles pair by pair says.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <random>

#include "drape/mesh/weld.hpp"

namespace drape::mesh {
namespace {

std::array<Vec3, 3> corners(const TriMesh& m, const Triangle& t) {
  return {m.positions[t[0]], m.positions[t[1]], m.positions[t[2]]};
}

// The same triangle: the same corners in the same cyclic order, or (a two-sided copy) in
// the reverse order.
bool sameTriangle(const std::array<Vec3, 3>& a, const std::array<Vec3, 3>& b) {
  for (int r = 0; r < 3; ++r) {
    bool forward = true, backward = true;
    for (int c = 0; c < 3; ++c) {
      forward = forward && a[static_cast<std::size_t>(c)] == b[static_cast<std::size_t>((c + r) % 3)];
      backward = backward && a[static_cast<std::size_t>(c)] == b[static_cast<std::size_t>((3 + r - c) % 3)];
    }
    if (forward || backward) return true;
  }
  return false;
}

TEST(Weld, MergesExactlyTheVerticesAtOnePositionOnRandomMeshes) {
  std::mt19937 rng(20261205);
  for (int trial = 0; trial < 200; ++trial) {
    std::uniform_int_distribution<int> pointCount(3, 40);
    std::vector<Vec3> points(static_cast<std::size_t>(pointCount(rng)));
    std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
    for (Vec3& p : points) p = Vec3(coordinate(rng), coordinate(rng), coordinate(rng));
    TriMesh in;
    std::uniform_int_distribution<std::size_t> pick(0, points.size() - 1);
    const std::size_t vertexCount = points.size() + pick(rng) * 3;
    for (std::size_t v = 0; v < vertexCount; ++v) in.positions.push_back(points[pick(rng)]);
    std::uniform_int_distribution<std::uint32_t> vertex(0, static_cast<std::uint32_t>(vertexCount - 1));
    for (int t = 0; t < 60; ++t) in.triangles.push_back({vertex(rng), vertex(rng), vertex(rng)});

    const Welded w = weld(in);
    // Brute force: the distinct positions, the triangles kept in order.
    std::vector<Vec3> distinct;
    for (const Vec3& p : in.positions)
      if (std::find(distinct.begin(), distinct.end(), p) == distinct.end()) distinct.push_back(p);
    std::vector<std::array<Vec3, 3>> kept;
    std::size_t collapsed = 0, repeats = 0;
    for (const Triangle& t : in.triangles) {
      const std::array<Vec3, 3> c = corners(in, t);
      if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) {
        ++collapsed;
      } else if (std::any_of(kept.begin(), kept.end(), [&](const auto& k) { return sameTriangle(k, c); })) {
        ++repeats;
      } else {
        kept.push_back(c);
      }
    }
    ASSERT_EQ(w.mesh.triangles.size(), kept.size()) << "trial " << trial;
    for (std::size_t t = 0; t < kept.size(); ++t) {
      const std::array<Vec3, 3> c = corners(w.mesh, w.mesh.triangles[t]);
      EXPECT_EQ(c, kept[t]) << "trial " << trial << " triangle " << t;  // same corners, same order
    }
    EXPECT_EQ(w.collapsed, collapsed);
    EXPECT_EQ(w.duplicates, repeats);
    EXPECT_EQ(w.merged, in.positions.size() - distinct.size());
    // Every kept vertex is a different position, and a triangle uses each of them.
    for (std::size_t a = 0; a < w.mesh.positions.size(); ++a)
      for (std::size_t b = a + 1; b < w.mesh.positions.size(); ++b) EXPECT_NE(w.mesh.positions[a], w.mesh.positions[b]);
    std::vector<bool> used(w.mesh.positions.size(), false);
    for (const Triangle& t : w.mesh.triangles)
      for (std::uint32_t v : t) used[v] = true;
    EXPECT_TRUE(std::all_of(used.begin(), used.end(), [](bool u) { return u; }));
    EXPECT_EQ(w.unused, distinct.size() - w.mesh.positions.size());
    // Keeping the loose vertices: the same triangles, then every other position once.
    const Welded all = weld(in, 1e-7, true);
    EXPECT_EQ(all.mesh.triangles, w.mesh.triangles);
    ASSERT_EQ(all.mesh.positions.size(), distinct.size());
    EXPECT_TRUE(std::equal(w.mesh.positions.begin(), w.mesh.positions.end(), all.mesh.positions.begin()));
    for (const Vec3& p : distinct) EXPECT_NE(std::find(all.mesh.positions.begin(), all.mesh.positions.end(), p), all.mesh.positions.end());
    EXPECT_EQ(all.unused, 0u);
  }
}

TEST(Weld, KeepsVerticesApartBeyondTheTolerance) {
  TriMesh m;
  m.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1e-3, 0, 0), Vec3(1, 1e-9, 0)};
  m.triangles = {{0, 1, 2}, {3, 4, 2}};
  const Welded w = weld(m, 1e-6);
  // 1e-9 m is within the micrometre: vertex 4 is vertex 1; 1 mm is not.
  EXPECT_EQ(w.merged, 1u);
  EXPECT_EQ(w.mesh.positions.size(), 4u);
  EXPECT_EQ(w.mesh.triangles, (std::vector<Triangle>{{0, 1, 2}, {3, 1, 2}}));
}

}  // namespace
}  // namespace drape::mesh
