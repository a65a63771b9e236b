#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "drape/core/error.hpp"
#include "drape/mesh/topology.hpp"

namespace drape::mesh {
namespace {

TriMesh grid(int nx, int ny) {
  TriMesh m;
  m.name = "grid";
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m.positions.emplace_back(i, j, 0);
  auto id = [&](int i, int j) { return static_cast<std::uint32_t>(j * (nx + 1) + i); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

TEST(Topology, GridCountsMatchEuler) {
  const int nx = 5, ny = 4;
  const TriMesh m = grid(nx, ny);
  const Topology t = Topology::build(m);
  // Edges of a triangulated grid: horizontal + vertical + diagonal.
  const std::size_t expected = nx * (ny + 1) + ny * (nx + 1) + nx * ny;
  EXPECT_EQ(t.edges.size(), expected);
  EXPECT_EQ(t.edges.size() - t.interiorEdgeCount(), static_cast<std::size_t>(2 * (nx + ny)));
  ASSERT_EQ(t.boundaryLoops.size(), 1u);
  EXPECT_EQ(t.boundaryLoops[0].size(), static_cast<std::size_t>(2 * (nx + ny)));
  // V - E + F = 1 for a disc.
  EXPECT_EQ(static_cast<long>(m.positions.size()) - static_cast<long>(t.edges.size()) + static_cast<long>(m.triangles.size()), 1);
}

TEST(Topology, OppositeVerticesAreTheThirdCorners) {
  const TriMesh m = grid(3, 3);
  const Topology t = Topology::build(m);
  for (const Edge& e : t.edges) {
    const Triangle& f0 = m.triangles[e.face0];
    EXPECT_TRUE(std::count(f0.begin(), f0.end(), e.v0) == 1 && std::count(f0.begin(), f0.end(), e.v1) == 1);
    EXPECT_TRUE(e.opposite0 != e.v0 && e.opposite0 != e.v1);
    if (!e.boundary()) {
      EXPECT_TRUE(e.opposite1 != e.v0 && e.opposite1 != e.v1 && e.opposite1 != e.opposite0);
    }
  }
  for (std::size_t f = 0; f < m.triangles.size(); ++f)
    for (int c = 0; c < 3; ++c) {
      const Edge& e = t.edges[t.triangleEdges[f][c]];
      EXPECT_TRUE((e.v0 == std::min(m.triangles[f][c], m.triangles[f][(c + 1) % 3])));
    }
}

TEST(Topology, RejectsNonManifoldEdges) {
  TriMesh m = grid(1, 1);
  m.positions.emplace_back(0.5, 0.5, 1.0);
  m.triangles.push_back({0, 3, 4});  // a third face on the diagonal 0-3
  try {
    (void)Topology::build(m);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("grid: non-manifold edge between vertices 0 and 3"), std::string::npos) << e.what();
  }
  EXPECT_EQ(countNonManifoldEdges(m), 1u);
}

TEST(Topology, RejectsDegenerateAndOutOfRangeTriangles) {
  TriMesh m = grid(1, 1);
  m.triangles.push_back({0, 1, 1});
  EXPECT_THROW((void)Topology::build(m), Error);
  m = grid(1, 1);
  m.positions.emplace_back(2, 0, 0);
  m.triangles.push_back({0, 1, 4});  // collinear: zero area
  EXPECT_THROW((void)Topology::build(m), Error);
  m = grid(1, 1);
  m.triangles.push_back({0, 1, 9});
  EXPECT_THROW((void)Topology::build(m), Error);
}

/// The grid with a slit up column c from the bottom edge to row s: the vertices of the
/// column below row s are doubled, the copies `gap` to the right and taken by the cells
/// right of the column.
TriMesh slitGrid(int nx, int ny, int c, int s, double gap) {
  TriMesh m = grid(nx, ny);
  std::vector<std::uint32_t> copy(static_cast<std::size_t>(s));
  for (int j = 0; j < s; ++j) {
    copy[static_cast<std::size_t>(j)] = static_cast<std::uint32_t>(m.positions.size());
    m.positions.emplace_back(c + gap, j, 0);
  }
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const int cellI = static_cast<int>(t / 2) % nx;
    if (cellI != c) continue;  // only the cells right of the column
    for (std::uint32_t& v : m.triangles[t]) {
      const int i = static_cast<int>(v) % (nx + 1), j = static_cast<int>(v) / (nx + 1);
      if (i == c && j < s) v = copy[static_cast<std::size_t>(j)];
    }
  }
  return m;
}

TEST(FacingBoundaryPairs, ASlitsTwoEdgesArePairedRowByRowAwayFromItsClosedEnd) {
  const int nx = 6, ny = 8, c = 3, s = 6;
  const TriMesh m = slitGrid(nx, ny, c, s, 0.1);
  const Topology t = Topology::build(m);
  ASSERT_EQ(t.boundaryLoops.size(), 1u);
  const auto pairs = facingBoundaryPairs(m, t, 0.3);
  // Row j's two vertices are 2 (s - j) boundary edges apart around the slit's end: rows
  // s - 1 and s - 2 are neighbours along the boundary (fewer than 6 edges), the rest pair.
  ASSERT_EQ(pairs.size(), static_cast<std::size_t>(s - 2));
  for (int j = 0; j < s - 2; ++j) {
    const auto original = static_cast<std::uint32_t>(j * (nx + 1) + c);
    const auto copy = static_cast<std::uint32_t>((nx + 1) * (ny + 1) + j);
    EXPECT_EQ(pairs[static_cast<std::size_t>(j)], (std::array<std::uint32_t, 2>{original, copy})) << j;
  }
  EXPECT_EQ(facingBoundaryPairs(m, t, 0.3, 2 * s + 2).size(), 0u) << "every row within the separation";
  EXPECT_EQ(facingBoundaryPairs(m, t, 0.09).size(), 0u) << "the gap is wider";
  EXPECT_THROW((void)facingBoundaryPairs(m, t, 0.0), Error);
  EXPECT_THROW((void)facingBoundaryPairs(m, t, std::nan("")), Error);
}

TEST(FacingBoundaryPairs, TwoSheetsFacingEachOtherArePairedAlongTheirWholeEdges) {
  const int n = 4;
  TriMesh m = grid(n, n);
  const TriMesh right = grid(n, n);
  const auto offset = static_cast<std::uint32_t>(m.positions.size());
  for (const Vec3& p : right.positions) m.positions.push_back(p + Vec3(n + 0.2, 0, 0));
  for (const Triangle& tri : right.triangles) m.triangles.push_back({tri[0] + offset, tri[1] + offset, tri[2] + offset});
  const Topology t = Topology::build(m);
  ASSERT_EQ(t.boundaryLoops.size(), 2u);
  const auto pairs = facingBoundaryPairs(m, t, 0.5);
  ASSERT_EQ(pairs.size(), static_cast<std::size_t>(n + 1));
  for (const auto& [a, b] : pairs) {
    EXPECT_DOUBLE_EQ(m.positions[a].x(), n);
    EXPECT_DOUBLE_EQ(m.positions[b].x(), n + 0.2);
    EXPECT_DOUBLE_EQ(m.positions[a].y(), m.positions[b].y());
  }
}

/// facingBoundaryPairs by comparing every pair of boundary vertices: the reference.
std::vector<std::array<std::uint32_t, 2>> facingPairsBruteForce(const TriMesh& m, const Topology& t, double gap,
                                                                int minSeparation) {
  std::vector<std::array<std::uint32_t, 3>> places;  // vertex, loop, index
  for (std::uint32_t l = 0; l < t.boundaryLoops.size(); ++l)
    for (std::uint32_t i = 0; i < t.boundaryLoops[l].size(); ++i) places.push_back({t.boundaryLoops[l][i], l, i});
  const auto apart = [&](const auto& p, const auto& q) {
    if (p[1] != q[1]) return true;
    const auto n = static_cast<std::uint32_t>(t.boundaryLoops[p[1]].size());
    const std::uint32_t d = p[2] > q[2] ? p[2] - q[2] : q[2] - p[2];
    return static_cast<int>(std::min(d, n - d)) >= minSeparation;
  };
  const std::size_t none = places.size();
  std::vector<std::size_t> nearest(places.size(), none);
  for (std::size_t i = 0; i < places.size(); ++i) {
    double best = gap;
    for (std::size_t j = 0; j < places.size(); ++j) {
      if (j == i || !apart(places[i], places[j])) continue;
      const double d = (m.positions[places[j][0]] - m.positions[places[i][0]]).norm();
      if (d <= best) {
        best = d;
        nearest[i] = j;
      }
    }
  }
  std::vector<std::array<std::uint32_t, 2>> pairs;
  for (std::size_t i = 0; i < places.size(); ++i) {
    const std::size_t j = nearest[i];
    if (j == none || j < i || nearest[j] != i) continue;
    pairs.push_back({std::min(places[i][0], places[j][0]), std::max(places[i][0], places[j][0])});
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

TEST(FacingBoundaryPairs, TheSameAsComparingEveryPairOnRandomSheets) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::size_t found = 0;
  for (int trial = 0; trial < 200; ++trial) {
    // A few sheets near each other; on even trials on the lattice (equally near vertices
    // everywhere: the tie rule is tested), on odd ones jittered and turned.
    const bool lattice = trial % 2 == 0;
    TriMesh m;
    const int sheets = 1 + trial % 4;
    for (int k = 0; k < sheets; ++k) {
      const int nx = 1 + static_cast<int>(5 * unit(rng)), ny = 1 + static_cast<int>(5 * unit(rng));
      const TriMesh sheet = trial % 3 == 0 ? slitGrid(nx + 2, ny + 3, 1 + nx / 2, 1 + ny, lattice ? 0.0 : 0.3 * unit(rng))
                                           : grid(nx, ny);
      const Vec3 at = lattice ? Vec3(std::floor(8 * unit(rng)), std::floor(8 * unit(rng)), std::floor(2 * unit(rng)))
                              : Vec3(8 * unit(rng), 8 * unit(rng), 2 * unit(rng));
      const double turn = lattice ? 0.0 : 6.3 * unit(rng);
      const auto offset = static_cast<std::uint32_t>(m.positions.size());
      for (const Vec3& p : sheet.positions) {
        Vec3 q(std::cos(turn) * p.x() - std::sin(turn) * p.y(), std::sin(turn) * p.x() + std::cos(turn) * p.y(), p.z());
        if (!lattice) q += 0.05 * Vec3(unit(rng), unit(rng), unit(rng));
        m.positions.push_back(q + at);
      }
      for (const Triangle& tri : sheet.triangles) m.triangles.push_back({tri[0] + offset, tri[1] + offset, tri[2] + offset});
    }
    const Topology t = Topology::build(m);
    const double gap = lattice ? std::floor(1 + 3 * unit(rng)) : 3 * unit(rng);
    const int separation = 1 + static_cast<int>(8 * unit(rng));
    const auto pairs = facingBoundaryPairs(m, t, gap, separation);
    EXPECT_EQ(pairs, facingPairsBruteForce(m, t, gap, separation)) << "trial " << trial;
    found += pairs.size();
  }
  EXPECT_GT(found, 400u) << "the cases pair something";
}

TEST(TriMesh, AreaAndNormals) {
  const TriMesh m = grid(2, 3);
  EXPECT_NEAR(m.totalArea(), 6.0, 1e-12);
  for (const Vec3& n : m.vertexNormals()) EXPECT_NEAR((n - Vec3(0, 0, 1)).norm(), 0.0, 1e-12);
}

}  // namespace
}  // namespace drape::mesh
