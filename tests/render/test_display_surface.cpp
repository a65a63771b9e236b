// The garments' display surfaces (Loop subdivision through OpenSubdiv): what Loop's limit
// surface must do, checked on meshes whose answer is known, and the source that draws them.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>

#include "drape/core/error.hpp"
#include "drape/field/shapes.hpp"
#include "drape/mesh/generators.hpp"
#include "drape/render/display_surface.hpp"

namespace drape::render {
namespace {

/// A 7 x 6 sheet in the xy plane, its vertices jittered within the plane.
mesh::TriMesh jitteredSheet(std::mt19937& rng) {
  mesh::TriMesh m = mesh::makeSheet(Vec3::Zero(), Vec3(0.6, 0, 0), Vec3(0, 0.5, 0), 6, 5);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  for (Vec3& p : m.positions) p += Vec3(jitter(rng), jitter(rng), 0.0);
  return m;
}

std::size_t edgeCount(const mesh::TriMesh& m) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (const mesh::Triangle& t : m.triangles)
    for (int k = 0; k < 3; ++k) edges.insert(std::minmax(t[k], t[(k + 1) % 3]));
  return edges.size();
}

TEST(LoopSurface, EachLevelSplitsEveryTriangleInFour) {
  std::mt19937 rng(1);
  const mesh::TriMesh sheet = jitteredSheet(rng);
  LoopSurface one(sheet.vertexCount(), sheet.triangles, 1);
  EXPECT_EQ(one.triangles().size(), 4 * sheet.triangleCount());
  EXPECT_EQ(one.vertexCount(), sheet.vertexCount() + edgeCount(sheet));  // a vertex per vertex and per edge
  LoopSurface three(sheet.vertexCount(), sheet.triangles, 3);
  EXPECT_EQ(three.triangles().size(), 64 * sheet.triangleCount());
  for (const mesh::Triangle& t : three.triangles())
    for (const std::uint32_t v : t) ASSERT_LT(v, three.vertexCount());
}

TEST(LoopSurface, CommutesWithAffineMaps) {
  // Loop's weights sum to one at every rule, the limit's too: the surface of a mapped mesh
  // is the mapped surface. Random sheets bent out of their plane, random affine maps.
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (int trial = 0; trial < 40; ++trial) {
    mesh::TriMesh sheet = jitteredSheet(rng);
    for (Vec3& p : sheet.positions) p.z() = 0.1 * unit(rng);
    Mat3 a;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) a(i, j) = unit(rng) + (i == j ? 2.0 : 0.0);
    const Vec3 b(unit(rng), unit(rng), unit(rng));
    std::vector<Vec3> mapped;
    for (const Vec3& p : sheet.positions) mapped.push_back(a * p + b);
    LoopSurface surface(sheet.vertexCount(), sheet.triangles, 2);
    std::vector<Vec3> refined, refinedOfMapped;
    surface.positions(sheet.positions, refined);
    surface.positions(mapped, refinedOfMapped);
    ASSERT_EQ(refined.size(), surface.vertexCount());
    for (std::size_t v = 0; v < refined.size(); ++v)
      ASSERT_LT((a * refined[v] + b - refinedOfMapped[v]).norm(), 1e-12) << "trial " << trial << " vertex " << v;
  }
}

TEST(LoopSurface, AFlatSheetStaysInItsPlaneAndItsOutline) {
  // A flat sheet's surface stays flat, and within its outline (a rectangle whose edge
  // vertices are jittered by up to 2 cm) give or take 5 mm: the boundary is a cubic spline of
  // the edge vertices moved out by what the spline takes off at them, and it overshoots a
  // jittered vertex by a few millimetres.
  std::mt19937 rng(3);
  const mesh::TriMesh sheet = jitteredSheet(rng);
  LoopSurface surface(sheet.vertexCount(), sheet.triangles, 3);
  std::vector<Vec3> refined;
  surface.positions(sheet.positions, refined);
  for (const Vec3& p : refined) {
    ASSERT_EQ(p.z(), 0.0);
    ASSERT_GE(p.x(), -0.025);
    ASSERT_LE(p.x(), 0.625);
    ASSERT_GE(p.y(), -0.025);
    ASSERT_LE(p.y(), 0.525);
  }
}

/// An icosahedron with each triangle split in four and the new vertices put on the sphere:
/// 42 vertices of valence 5 and 6, 80 triangles.
mesh::TriMesh icosphere(double r) {
  const double g = (1.0 + std::sqrt(5.0)) / 2.0;
  mesh::TriMesh m;
  for (const Vec3& p : {Vec3(-1, g, 0), Vec3(1, g, 0), Vec3(-1, -g, 0), Vec3(1, -g, 0), Vec3(0, -1, g), Vec3(0, 1, g),
                        Vec3(0, -1, -g), Vec3(0, 1, -g), Vec3(g, 0, -1), Vec3(g, 0, 1), Vec3(-g, 0, -1), Vec3(-g, 0, 1)})
    m.positions.push_back(r * p.normalized());
  const std::vector<mesh::Triangle> faces{{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                          {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                          {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                          {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> middle;
  const auto mid = [&](std::uint32_t a, std::uint32_t b) {
    const auto key = std::minmax(a, b);
    if (const auto it = middle.find(key); it != middle.end()) return it->second;
    m.positions.push_back(r * (m.positions[a] + m.positions[b]).normalized());
    return middle[key] = static_cast<std::uint32_t>(m.positions.size() - 1);
  };
  for (const mesh::Triangle& f : faces) {
    const std::uint32_t ab = mid(f[0], f[1]), bc = mid(f[1], f[2]), ca = mid(f[2], f[0]);
    for (const mesh::Triangle& t : {mesh::Triangle{f[0], ab, ca}, mesh::Triangle{f[1], bc, ab},
                                    mesh::Triangle{f[2], ca, bc}, mesh::Triangle{ab, bc, ca}})
      m.triangles.push_back(t);
  }
  return m;
}

TEST(LoopSurface, ASphereComesOutRound) {
  // A coarse sphere (r = 0.2 m, 80 triangles): its vertices lie on the sphere, its
  // triangles' centroids up to 13 mm inside. Loop's limit surface of it lies 16 to 18 mm
  // inside; moved out first by what the limit takes off at each vertex, within 3 mm and
  // round to a fifth of the triangles' spread.
  const double r = 0.2;
  const mesh::TriMesh sphere = icosphere(r);
  double coarseLow = r;
  for (const mesh::Triangle& t : sphere.triangles)
    coarseLow = std::min(coarseLow, ((sphere.positions[t[0]] + sphere.positions[t[1]] + sphere.positions[t[2]]) / 3).norm());
  EXPECT_GT(r - coarseLow, 0.012);
  LoopSurface surface(sphere.vertexCount(), sphere.triangles, 3);
  std::vector<Vec3> refined;
  surface.positions(sphere.positions, refined);
  double low = 1e9, high = 0;
  for (const Vec3& p : refined) {
    low = std::min(low, p.norm());
    high = std::max(high, p.norm());
  }
  EXPECT_LT(high, r);
  EXPECT_GT(low, r - 0.003);
  EXPECT_LT(high - low, 0.2 * (r - coarseLow));
}

TEST(LoopSurface, StatesKeepTheirFlagsOnTheSimulatedVerticesOnly) {
  std::mt19937 rng(4);
  const mesh::TriMesh sheet = jitteredSheet(rng);
  std::vector<std::uint8_t> states(sheet.vertexCount(), vertex_state::kOutside);
  std::size_t pinned = 0, bound = 0;
  for (std::size_t v = 0; v < states.size(); ++v) {
    if (v % 5 == 0) {
      states[v] = vertex_state::kPinned;
      ++pinned;
    } else if (v % 7 == 0) {
      states[v] = vertex_state::kBound | vertex_state::kOnSurface;
      ++bound;
    } else if (v % 3 == 0) {
      states[v] = vertex_state::kPenaltyZone;
    }
  }
  LoopSurface surface(sheet.vertexCount(), sheet.triangles, 2);
  std::vector<std::uint8_t> refined;
  surface.states(states, refined);
  ASSERT_EQ(refined.size(), surface.vertexCount());
  std::size_t refinedPinned = 0, refinedBound = 0;
  std::set<std::uint8_t> collision;
  for (const std::uint8_t s : refined) {
    refinedPinned += (s & vertex_state::kPinned) != 0;
    refinedBound += (s & vertex_state::kBound) != 0;
    collision.insert(static_cast<std::uint8_t>(s & vertex_state::kCollisionMask));
  }
  EXPECT_EQ(refinedPinned, pinned);  // markers stay on the simulated vertices
  EXPECT_EQ(refinedBound, bound);
  // Every collision state comes from a simulated vertex, and each one reaches the surface.
  EXPECT_EQ(collision, (std::set<std::uint8_t>{vertex_state::kOutside, vertex_state::kOnSurface,
                                               vertex_state::kPenaltyZone}));
}

TEST(LoopSurface, RefusesWhatIsNotATriangleMesh) {
  const std::vector<mesh::Triangle> repeats{{0, 1, 1}};
  EXPECT_THROW(LoopSurface(3, repeats, 1), Error);
  const std::vector<mesh::Triangle> outside{{0, 1, 3}};
  EXPECT_THROW(LoopSurface(3, outside, 1), Error);
  const std::vector<mesh::Triangle> fine{{0, 1, 2}};
  EXPECT_THROW(LoopSurface(3, fine, 0), Error);
  LoopSurface one(3, fine, 1);
  std::vector<Vec3> out;
  EXPECT_THROW(one.positions(std::vector<Vec3>(2, Vec3::Zero()), out), Error);
}

TEST(LoopSurface, AVertexOfNoTriangleIsLeftOut) {
  // Vertex 3 belongs to no triangle (a stray vertex of an OBJ): the surface is the one of
  // the triangle alone, and its own points are not moved by it.
  const std::vector<mesh::Triangle> one{{0, 1, 2}};
  const std::vector<Vec3> withStray{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(5, 5, 5)};
  const std::vector<Vec3> without(withStray.begin(), withStray.begin() + 3);
  LoopSurface a(4, one, 2), b(3, one, 2);
  std::vector<Vec3> pa, pb;
  a.positions(withStray, pa);
  b.positions(without, pb);
  for (const Vec3& p : pb) EXPECT_NE(std::find(pa.begin(), pa.end(), p), pa.end()) << p.transpose();
  for (const mesh::Triangle& t : a.triangles())
    for (const std::uint32_t v : t) EXPECT_LT(pa[v].norm(), 2.0);
}

TEST(LoopSurface, NonManifoldMeshesAreDrawnWithoutHarm) {
  // Three triangles on one edge (a fin) and two fans meeting at one vertex (a bow tie):
  // what an imported garment may hold. Each is refined, every position finite and near the
  // mesh.
  const std::vector<Vec3> fin{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1, 0), Vec3(0.5, -1, 0), Vec3(0.5, 0, 1)};
  const std::vector<mesh::Triangle> finTriangles{{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  const std::vector<Vec3> bowTie{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(-1, 0, 0), Vec3(-1, -1, 0)};
  const std::vector<mesh::Triangle> bowTieTriangles{{0, 1, 2}, {0, 3, 4}};
  for (const auto& [points, triangles] : {std::pair{fin, finTriangles}, std::pair{bowTie, bowTieTriangles}}) {
    LoopSurface surface(points.size(), triangles, 3);
    std::vector<Vec3> refined;
    surface.positions(points, refined);
    ASSERT_EQ(refined.size(), surface.vertexCount());
    for (const Vec3& p : refined) {
      ASSERT_TRUE(p.allFinite());
      ASSERT_LT(p.norm(), 2.0);
    }
  }
}

TEST(SubdividedSource, RefinesTheGarmentsAndPassesTheBodyThrough) {
  std::mt19937 rng(5);
  const mesh::TriMesh sheet = jitteredSheet(rng);
  const mesh::TriMesh body = field::makeSphere(0.1, Vec3(0, 0, -0.2), 8, 4);
  std::vector<MeshInfo> meshes(2);
  meshes[0] = {"cloth", MeshRole::Garment, sheet.vertexCount(), sheet.triangles};
  meshes[1] = {"body", MeshRole::Skin, body.vertexCount(), body.triangles};
  CallbackSource live(meshes, 30.0, [&](Frame& out) {
    out.positions = {sheet.positions, body.positions};
    out.states = {std::vector<std::uint8_t>(sheet.vertexCount(), vertex_state::kOnSurface), {}};
    return out.index < 3;
  });
  SubdividedSource shown(live, 2);
  LoopSurface surface(sheet.vertexCount(), sheet.triangles, 2);
  ASSERT_EQ(shown.meshes().size(), 2U);
  EXPECT_EQ(shown.meshes()[0].vertexCount, surface.vertexCount());
  EXPECT_EQ(shown.meshes()[0].triangles, surface.triangles());
  EXPECT_EQ(shown.meshes()[1].vertexCount, body.vertexCount());
  Frame frame;
  ASSERT_TRUE(shown.read(0, frame));
  std::vector<Vec3> expected;
  surface.positions(sheet.positions, expected);
  EXPECT_EQ(frame.positions[0], expected);
  EXPECT_EQ(frame.positions[1], body.positions);
  EXPECT_EQ(frame.states[0], std::vector<std::uint8_t>(surface.vertexCount(), vertex_state::kOnSurface));
  EXPECT_TRUE(frame.states[1].empty());
  EXPECT_FALSE(shown.read(3, frame));

  SubdividedSource asSimulated(live, 0);
  EXPECT_EQ(asSimulated.meshes()[0].vertexCount, sheet.vertexCount());
}

}  // namespace
}  // namespace drape::render
