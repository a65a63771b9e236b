// DVDP and the exact feature transform against brute force (paper section 4.3.2).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <random>

#include "drape/core/math.hpp"
#include "drape/field/propagation.hpp"

namespace drape::field {
namespace {

// Squared distance from every voxel to the nearest surface voxel, by trying them all.
std::vector<std::int32_t> bruteForce(const GridDims& d, const std::vector<std::uint8_t>& surface) {
  std::vector<std::uint32_t> sites;
  for (std::uint32_t i = 0; i < surface.size(); ++i)
    if (surface[i]) sites.push_back(i);
  std::vector<std::int32_t> out(d.count(), std::numeric_limits<std::int32_t>::max());
  for (std::uint32_t v = 0; v < out.size(); ++v)
    for (std::uint32_t s : sites) out[v] = std::min(out[v], d.distance2(v, s));
  return out;
}

struct RandomGrid {
  GridDims dims;
  std::vector<std::uint8_t> surface;
};

// Random small grids of three kinds: scattered voxels, voxelized spheres (shells) and
// planes at random angles, the shapes a body surface is made of.
RandomGrid randomGrid(std::mt19937& rng, int kind) {
  std::uniform_int_distribution<int> side(3, 18);
  RandomGrid g;
  g.dims = {side(rng), side(rng), side(rng)};
  g.surface.assign(g.dims.count(), 0);
  std::uniform_real_distribution<double> unit(0, 1);
  const GridDims& d = g.dims;
  if (kind == 0) {
    const double density = 0.002 + 0.05 * unit(rng);
    for (auto& s : g.surface) s = unit(rng) < density;
  } else if (kind == 1) {
    const double cx = unit(rng) * d.nx, cy = unit(rng) * d.ny, cz = unit(rng) * d.nz;
    const double r = 1 + unit(rng) * 8;
    for (int z = 0; z < d.nz; ++z)
      for (int y = 0; y < d.ny; ++y)
        for (int x = 0; x < d.nx; ++x) {
          const double dist = std::sqrt((x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz));
          if (std::abs(dist - r) < 0.6) g.surface[d.index(x, y, z)] = 1;
        }
  } else {
    Vec3 n(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5);
    n.normalize();
    const double c = n.dot(Vec3(d.nx, d.ny, d.nz) * unit(rng));
    for (int z = 0; z < d.nz; ++z)
      for (int y = 0; y < d.ny; ++y)
        for (int x = 0; x < d.nx; ++x)
          if (std::abs(n.dot(Vec3(x, y, z)) - c) < 0.6) g.surface[d.index(x, y, z)] = 1;
  }
  if (std::none_of(g.surface.begin(), g.surface.end(), [](std::uint8_t s) { return s != 0; }))
    g.surface[d.index(d.nx / 2, d.ny / 2, d.nz / 2)] = 1;
  return g;
}

TEST(Propagation, ExactTransformEqualsBruteForceAndItsReferencesAreNearest) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 300; ++trial) {
    const RandomGrid g = randomGrid(rng, trial % 3);
    const std::vector<std::int32_t> truth = bruteForce(g.dims, g.surface);
    const Propagation p = exactFeatureTransform(g.dims, g.surface, {});
    ASSERT_EQ(p.distance2, truth) << "trial " << trial;
    EXPECT_EQ(exactDistance2(g.dims, g.surface), truth);
    for (std::size_t k = 0; k < p.shellVoxels.size(); ++k) {
      ASSERT_FALSE(p.refsOf(k).empty());
      for (std::uint32_t r : p.refsOf(k)) {
        ASSERT_TRUE(g.surface[r]);
        ASSERT_EQ(g.dims.distance2(p.shellVoxels[k], r), truth[p.shellVoxels[k]]);
      }
    }
  }
}

TEST(Propagation, DvdpIsExactWithinTheShellOnRandomGrids) {
  std::mt19937 rng(11);
  const int shell2 = 36;
  std::size_t shellVoxels = 0;
  for (int trial = 0; trial < 1200; ++trial) {
    const RandomGrid g = randomGrid(rng, trial % 3);
    const std::vector<std::int32_t> truth = bruteForce(g.dims, g.surface);
    const Propagation p = propagateDvdp(g.dims, g.surface, {shell2});
    std::size_t expectedShell = 0;
    for (std::size_t v = 0; v < truth.size(); ++v) {
      if (truth[v] <= shell2) {
        ++expectedShell;
        if (p.distance2[v] != truth[v]) {
          const GridDims& d = g.dims;
          std::printf("dims %d %d %d v (%d %d %d) got %d truth %d\n", d.nx, d.ny, d.nz, d.xOf(v), d.yOf(v), d.zOf(v), p.distance2[v], truth[v]);
          for (std::uint32_t s = 0; s < g.surface.size(); ++s)
            if (g.surface[s] && d.distance2(v, s) == truth[v]) {
              std::printf(" nearest site (%d %d %d)\n", d.xOf(s), d.yOf(s), d.zOf(s));
              for (int dz = -1; dz <= 1; ++dz) for (int dy = -1; dy <= 1; ++dy) for (int dx = -1; dx <= 1; ++dx) {
                int x = d.xOf(v) + dx, y = d.yOf(v) + dy, z = d.zOf(v) + dz;
                if (!d.contains(x, y, z)) continue;
                std::uint32_t u = d.index(x, y, z);
                if (d.distance2(u, s) < truth[v]) std::printf("  nb (%d %d %d) truth %d to-site %d\n", dx, dy, dz, truth[u], d.distance2(u, s));
              }
            }
        }
        ASSERT_EQ(p.distance2[v], truth[v]) << "trial " << trial << " voxel " << v;
      }
    }
    ASSERT_EQ(p.shellVoxels.size(), expectedShell) << "trial " << trial;
    for (std::size_t k = 0; k < p.shellVoxels.size(); ++k) {
      const std::uint32_t v = p.shellVoxels[k];
      ASSERT_FALSE(p.refsOf(k).empty()) << "trial " << trial;
      for (std::uint32_t r : p.refsOf(k)) {
        ASSERT_TRUE(g.surface[r]);
        // Compare distances, not indices: ties are common.
        ASSERT_EQ(g.dims.distance2(v, r), truth[v]) << "trial " << trial;
      }
    }
    shellVoxels += p.shellVoxels.size();
  }
  EXPECT_GT(shellVoxels, 100000u);
}

}  // namespace
}  // namespace drape::field
