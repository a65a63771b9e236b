#include <gtest/gtest.h>

#include "drape/mesh/generators.hpp"
#include "drape/mesh/topology.hpp"

namespace drape::mesh {
namespace {

TEST(Generators, SheetHasTheRequestedAreaAndOneBoundary) {
  const TriMesh m = makeSheet(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 0, 0.5), 8, 3);
  EXPECT_EQ(m.triangles.size(), 48u);
  EXPECT_NEAR(m.totalArea(), 1.0, 1e-12);
  const Topology t = Topology::build(m);
  EXPECT_EQ(t.boundaryLoops.size(), 1u);
}

TEST(Generators, SkirtIsATubeWithOutwardNormals) {
  SkirtShape shape;
  const Skirt s = makeSkirt(shape);
  EXPECT_EQ(s.mesh.triangles.size(), static_cast<std::size_t>(2 * shape.segments * shape.rings));
  const Topology t = Topology::build(s.mesh);
  ASSERT_EQ(t.boundaryLoops.size(), 2u);  // waist and hem
  for (std::size_t f = 0; f < s.mesh.triangles.size(); ++f) {
    const auto& tri = s.mesh.triangles[f];
    const Vec3 c = (s.mesh.positions[tri[0]] + s.mesh.positions[tri[1]] + s.mesh.positions[tri[2]]) / 3.0;
    Vec3 radial = c - shape.waistCentre;
    radial.y() = 0;
    EXPECT_GT(s.mesh.triangleNormalArea(f).dot(radial), 0.0) << "triangle " << f;
  }
  // The waistband mask is the waist ring: the first ring's vertices.
  EXPECT_EQ(s.waistband.positions.size(), static_cast<std::size_t>(shape.segments));
  for (std::size_t i = 0; i < s.waistband.positions.size(); ++i) EXPECT_EQ(s.waistband.positions[i], s.mesh.positions[i]);
}

}  // namespace
}  // namespace drape::mesh
