// Voxelization: surface voxels with normals and the inside fill, on closed meshes.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "drape/field/distance_field.hpp"
#include "drape/field/shapes.hpp"
#include "drape/field/voxelize.hpp"
#include "drape/formats/obj.hpp"
#include "drape/mesh/surface_distance.hpp"

namespace drape::field {
namespace {

Voxelization voxelizeWith(const mesh::TriMesh& m, double voxel) {
  FieldSettings s;
  s.voxelSize_m = voxel;
  return voxelize(m, placeGrid(m.bounds(), s, 3));
}

Vec3i voxelOf(const GridPlacement& g, const Vec3& p) {
  const Vec3 c = (p - g.origin) / g.voxelSize;
  return {static_cast<int>(std::floor(c.x())), static_cast<int>(std::floor(c.y())), static_cast<int>(std::floor(c.z()))};
}

void checkVoxelization(const mesh::TriMesh& m, double voxel, int randomPoints, int normalSamples) {
  const Voxelization v = voxelizeWith(m, voxel);
  const GridDims& d = v.grid.dims;
  // The voxel of every triangle's centroid is a surface voxel.
  for (std::size_t t = 0; t < m.triangleCount(); ++t) {
    const Vec3 c = (m.positions[m.triangles[t][0]] + m.positions[m.triangles[t][1]] + m.positions[m.triangles[t][2]]) / 3;
    const Vec3i i = voxelOf(v.grid, c);
    ASSERT_TRUE(v.flags[d.index(i.x(), i.y(), i.z())] & kVoxelSurface) << m.name << " triangle " << t;
  }
  // The inside fill agrees with the winding number wherever no triangle touches the voxel.
  std::mt19937 rng(3);
  const Vec3 size(d.nx * v.grid.voxelSize, d.ny * v.grid.voxelSize, d.nz * v.grid.voxelSize);
  std::uniform_real_distribution<double> unit(0, 1);
  int tested = 0, inside = 0;
  for (int k = 0; k < randomPoints; ++k) {
    const Vec3 p = v.grid.origin + Vec3(unit(rng), unit(rng), unit(rng)).cwiseProduct(size);
    const Vec3i i = voxelOf(v.grid, p);
    if (!d.contains(i.x(), i.y(), i.z())) continue;
    const std::uint8_t f = v.flags[d.index(i.x(), i.y(), i.z())];
    if (f & kVoxelSurface) continue;
    const bool truth = mesh::windingNumber(m.positions, m.triangles, p) > 0.5;
    ASSERT_EQ(static_cast<bool>(f & kVoxelInside), truth) << m.name;
    ++tested;
    inside += truth;
  }
  EXPECT_GT(tested, randomPoints / 4);
  EXPECT_GT(inside, 0);
  // Every listed normal points outward: a step along it leaves the body, a step against it enters.
  const std::size_t stride = std::max<std::size_t>(1, v.normals.size() / normalSamples);
  for (std::size_t k = 0; k < v.normals.size(); k += stride) {
    const mesh::Triangle& tri = m.triangles[v.normalTriangle[k]];
    const Vec3 c = (m.positions[tri[0]] + m.positions[tri[1]] + m.positions[tri[2]]) / 3;
    const Vec3 n = v.normals[k].cast<double>();
    ASSERT_NEAR(n.norm(), 1.0, 1e-5);
    const double eps = 1e-4 * voxel;
    ASSERT_LT(mesh::windingNumber(m.positions, m.triangles, c + eps * n), 0.5) << m.name;
    ASSERT_GT(mesh::windingNumber(m.positions, m.triangles, c - eps * n), 0.5) << m.name;
  }
}

TEST(Voxelize, SphereTubeAndBox) {
  checkVoxelization(makeSphere(0.1, Vec3(0.01, -0.02, 0.03)), 0.01, 3000, 300);
  checkVoxelization(makeRoundedTube(0.06, 0.04, 0.4), 0.008, 3000, 300);
  checkVoxelization(makeBox(Vec3(0, 0, 0), Vec3(0.1, 0.2, 0.05)), 0.01, 3000, 100);
}

TEST(Voxelize, MakeHumanProxyInDecimetres) {
  formats::ObjReadOptions o;
  o.metresPerUnit = 0.1;
  const mesh::TriMesh m = formats::readObj(std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_female_generic_proxy.obj", o);
  checkVoxelization(m, 0.02, 300, 60);
}

TEST(Voxelize, NormalsListedOnEdgesAndCorners) {
  // A box whose faces lie inside voxels: edge voxels list two normals, corner voxels three.
  const mesh::TriMesh box = makeBox(Vec3(0.0049, 0.0049, 0.0049), Vec3(0.0751, 0.0551, 0.0451));
  const Voxelization v = voxelizeWith(box, 0.01);
  std::size_t maxDistinct = 0;
  for (std::size_t k = 0; k < v.surfaceVoxels.size(); ++k) {
    std::vector<Vec3f> distinct;
    for (const Vec3f& n : v.normalsOf(k))
      if (std::none_of(distinct.begin(), distinct.end(), [&](const Vec3f& m) { return (m - n).norm() < 1e-4f; }))
        distinct.push_back(n);
    maxDistinct = std::max(maxDistinct, distinct.size());
  }
  EXPECT_EQ(maxDistinct, 3u);
}

TEST(Voxelize, TriangleBoxOverlapAgreesWithSampling) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  int overlaps = 0;
  for (int k = 0; k < 2000; ++k) {
    const Vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng)), c(u(rng), u(rng), u(rng));
    const bool hit = triangleOverlapsBox(Vec3::Zero(), Vec3::Constant(0.5), a, b, c);
    // Sampled points of the triangle inside the box prove an overlap.
    bool sampled = false;
    for (int i = 0; i <= 40 && !sampled; ++i)
      for (int j = 0; i + j <= 40 && !sampled; ++j) {
        const Vec3 p = a + (b - a) * (i / 40.0) + (c - a) * (j / 40.0);
        sampled = (p.array().abs() <= 0.5).all();
      }
    if (sampled) {
      ASSERT_TRUE(hit);
    }
    overlaps += hit;
  }
  EXPECT_GT(overlaps, 200);
}

}  // namespace
}  // namespace drape::field
