// The force kernels' runs (MembraneArrays, BendArrays): elements whose corners are
// consecutive vertices are loaded as vectors instead of gathered. The forces must not depend
// on it: a structured mesh (runs) against the same mesh with its vertices renumbered at
// random (no runs), on many random states.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <numeric>
#include <random>

#include <tbb/global_control.h>

#include "cloth_fixture.hpp"

namespace drape::cloth {
namespace {

using testing::makeModel;

/// A cylinder of `around` x `rows` cells, every cell split along the same diagonal, vertex
/// (i, j) at j * around + i: the structure of a generated skirt, whose rows are runs.
mesh::TriMesh tube(int around, int rows) {
  mesh::TriMesh m;
  m.name = "tube";
  for (int j = 0; j <= rows; ++j)
    for (int i = 0; i < around; ++i) {
      const double a = 2.0 * 3.141592653589793 * i / around;
      m.positions.emplace_back(0.2 * std::cos(a), -0.04 * j, 0.2 * std::sin(a));
    }
  const auto v = [&](int i, int j) { return static_cast<std::uint32_t>(j * around + i % around); };
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < around; ++i) {
      m.triangles.push_back({v(i, j), v(i, j + 1), v(i + 1, j)});
      m.triangles.push_back({v(i + 1, j), v(i, j + 1), v(i + 1, j + 1)});
    }
  return m;
}

Material dampedSoftKnit() {
  Material m = testing::knit();
  m.damping_s = 2e-4;
  m.compressionScale = 0.1;
  return m;
}

/// The kernel arrays hold every element once, and the runs are what they claim.
TEST(KernelRuns, EveryElementOnceAndRunsConsecutive) {
  auto model = makeModel(tube(24, 10), dampedSoftKnit());
  const MembraneArrays& m = model->membraneArrays();
  ASSERT_GT(m.runEnd, 0);
  std::map<std::array<std::int32_t, 3>, int> kernel, listed;
  for (std::size_t t = 0; t < m.v0.size(); ++t) ++kernel[{m.v0[t], m.v1[t], m.v2[t]}];
  for (const MembraneElement& el : model->membrane())
    ++listed[{static_cast<std::int32_t>(el.v0), static_cast<std::int32_t>(el.v1), static_cast<std::int32_t>(el.v2)}];
  EXPECT_EQ(kernel, listed);
  // The blocks cover the runs, and within a block every corner goes up by one.
  std::vector<int> covered(static_cast<std::size_t>(m.runEnd), 0);
  for (const std::int32_t f : m.runBlocks) {
    ASSERT_LE(f + kKernelRun, m.runEnd);
    for (std::int32_t l = 0; l < kKernelRun; ++l) {
      covered[static_cast<std::size_t>(f + l)] = 1;
      if (l == 0) continue;
      EXPECT_EQ(m.v0[f + l], m.v0[f + l - 1] + 1) << f + l;
      EXPECT_EQ(m.v1[f + l], m.v1[f + l - 1] + 1) << f + l;
      EXPECT_EQ(m.v2[f + l], m.v2[f + l - 1] + 1) << f + l;
    }
  }
  EXPECT_TRUE(std::all_of(covered.begin(), covered.end(), [](int c) { return c == 1; }));
  // Vertex blocks: corner lists in parallel; every vertex in a block or among the singles.
  ASSERT_FALSE(m.vertexBlocks.empty());
  std::vector<int> summed(model->vertexCount(), 0);
  for (const std::int32_t v : m.vertexBlocks)
    for (std::int32_t l = 0; l < kKernelRun; ++l) {
      ++summed[static_cast<std::size_t>(v + l)];
      ASSERT_EQ(m.cornerStart[v + l + 1] - m.cornerStart[v + l], m.cornerStart[v + 1] - m.cornerStart[v]);
      for (std::int32_t k = 0; k < m.cornerStart[v + 1] - m.cornerStart[v]; ++k)
        EXPECT_EQ(m.cornerOffset[m.cornerStart[v + l] + k], m.cornerOffset[m.cornerStart[v] + k] + l);
    }
  for (const std::int32_t v : m.singleVertices) ++summed[static_cast<std::size_t>(v)];
  EXPECT_TRUE(std::all_of(summed.begin(), summed.end(), [](int c) { return c == 1; }));

  const BendArrays& b = model->bendArrays();
  ASSERT_GT(b.runEnd, 0);
  // Every hinge once, and each of its four corners once in its vertex's list.
  std::map<std::array<std::int32_t, 4>, int> kernelHinges, listedHinges;
  for (std::size_t i = 0; i < b.e0.size(); ++i) ++kernelHinges[{b.e0[i], b.e1[i], b.a[i], b.b[i]}];
  for (const BendElement& h : model->bending())
    ++listedHinges[{static_cast<std::int32_t>(h.e0), static_cast<std::int32_t>(h.e1), static_cast<std::int32_t>(h.a),
                    static_cast<std::int32_t>(h.b)}];
  EXPECT_EQ(kernelHinges, listedHinges);
  const std::size_t hinges = b.e0.size();
  std::vector<int> seen(4 * hinges, 0);
  for (std::size_t v = 0; v + 1 < b.cornerStart.size(); ++v)
    for (std::int32_t k = b.cornerStart[v]; k < b.cornerStart[v + 1]; ++k) {
      const auto offset = static_cast<std::size_t>(b.cornerOffset[k]);
      const std::size_t column = offset / (3 * hinges), i = offset % (3 * hinges);
      ASSERT_LT(i, hinges);
      const std::int32_t vertex = std::array{b.a[i], b.b[i], b.e0[i], b.e1[i]}[column];
      EXPECT_EQ(vertex, static_cast<std::int32_t>(v)) << "hinge " << i << " corner " << column;
      ++seen[column * hinges + i];
    }
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int c) { return c == 1; }));
  for (const std::int32_t f : b.runBlocks)
    for (std::int32_t l = 1; l < kKernelRun; ++l) {
      EXPECT_EQ(b.e0[f + l], b.e0[f + l - 1] + 1) << f + l;
      EXPECT_EQ(b.e1[f + l], b.e1[f + l - 1] + 1) << f + l;
      EXPECT_EQ(b.a[f + l], b.a[f + l - 1] + 1) << f + l;
      EXPECT_EQ(b.b[f + l], b.b[f + l - 1] + 1) << f + l;
    }
}

TEST(KernelRuns, ForcesDoNotDependOnTheRuns) {
  const mesh::TriMesh structured = tube(24, 10);
  // The same mesh with its vertices renumbered at random: no runs.
  const std::size_t n = structured.vertexCount();
  std::vector<std::uint32_t> renumber(n);
  std::iota(renumber.begin(), renumber.end(), 0U);
  std::mt19937 rng(7);
  std::shuffle(renumber.begin(), renumber.end(), rng);
  mesh::TriMesh shuffled = structured;
  for (std::size_t v = 0; v < n; ++v) shuffled.positions[renumber[v]] = structured.positions[v];
  for (mesh::Triangle& t : shuffled.triangles)
    for (std::uint32_t& v : t) v = renumber[v];

  auto a = makeModel(structured, dampedSoftKnit());
  auto b = makeModel(shuffled, dampedSoftKnit());
  ASSERT_GT(a->membraneArrays().runEnd, 0);
  ASSERT_FALSE(a->membraneArrays().vertexBlocks.empty());
  ASSERT_GT(a->bendArrays().runEnd, 0);
  ASSERT_EQ(b->membraneArrays().runEnd, 0);
  ASSERT_TRUE(b->membraneArrays().vertexBlocks.empty());
  ASSERT_EQ(b->bendArrays().runEnd, 0);

  std::normal_distribution<double> move(0.0, 0.01), speed(0.0, 0.5);
  for (int trial = 0; trial < 50; ++trial) {
    ClothState sa = ClothState::atRest(*a), sb = ClothState::atRest(*b);
    for (std::size_t v = 0; v < n; ++v) {  // stretched, compressed and bent, and moving
      const std::size_t w = renumber[v];
      sb.x[w] = sa.x[v] += move(rng);
      sb.y[w] = sa.y[v] += move(rng);
      sb.z[w] = sa.z[v] += move(rng);
      sb.vx[w] = sa.vx[v] = speed(rng);
      sb.vy[w] = sa.vy[v] = speed(rng);
      sb.vz[w] = sa.vz[v] = speed(rng);
    }
    for (auto [model, s] : {std::pair{a.get(), &sa}, std::pair{b.get(), &sb}}) {
      clearForces(*s);
      accumulateMembraneForces(*model, *s);
      accumulateBendingForces(*model, *s, 1.0);
    }
    double largest = 0.0;
    for (std::size_t v = 0; v < n; ++v)
      largest = std::max({largest, std::abs(sa.fx[v]), std::abs(sa.fy[v]), std::abs(sa.fz[v])});
    ASSERT_GT(largest, 0.0);
    // The renumbered mesh adds each vertex's contributions in another order and orients
    // some hinges the other way: rounding, amplified where large element forces cancel
    // (a wrong vertex in a run gives differences of the order of the forces).
    const double tolerance = 1e-9 * largest;
    for (std::size_t v = 0; v < n; ++v) {
      const std::size_t w = renumber[v];
      ASSERT_NEAR(sa.fx[v], sb.fx[w], tolerance) << "trial " << trial << " vertex " << v;
      ASSERT_NEAR(sa.fy[v], sb.fy[w], tolerance) << "trial " << trial << " vertex " << v;
      ASSERT_NEAR(sa.fz[v], sb.fz[w], tolerance) << "trial " << trial << " vertex " << v;
    }
  }
}

TEST(KernelRuns, PiecesOnThreadsGiveTheSameForcesToTheBit) {
  // A model above kParallelFrom_elements, with runs and renumbered (no runs): its forces
  // computed in pieces on two threads (ForceLoops) and at once must be equal, not close.
  const tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
  const mesh::TriMesh structured = tube(64, 20);
  mesh::TriMesh shuffled = structured;
  std::vector<std::uint32_t> renumber(structured.vertexCount());
  std::iota(renumber.begin(), renumber.end(), 0U);
  std::mt19937 rng(11);
  std::shuffle(renumber.begin(), renumber.end(), rng);
  for (std::size_t v = 0; v < renumber.size(); ++v) shuffled.positions[renumber[v]] = structured.positions[v];
  for (mesh::Triangle& t : shuffled.triangles)
    for (std::uint32_t& v : t) v = renumber[v];
  std::normal_distribution<double> move(0.0, 0.01), speed(0.0, 0.5);
  const std::array<const mesh::TriMesh*, 2> meshes{&structured, &shuffled};
  for (const mesh::TriMesh* mesh : meshes) {
    auto model = makeModel(*mesh, dampedSoftKnit());
    ASSERT_GE(model->membraneArrays().area.size(), kParallelFrom_elements);
    ASSERT_GE(model->bendArrays().stiffness.size(), kParallelFrom_elements);
    ForceLoops loops;
    for (int trial = 0; trial < 5; ++trial) {
      ClothState once = ClothState::atRest(*model);
      for (std::size_t v = 0; v < once.size(); ++v) {
        once.x[v] += move(rng);
        once.y[v] += move(rng);
        once.z[v] += move(rng);
        once.vx[v] = speed(rng);
        once.vy[v] = speed(rng);
        once.vz[v] = speed(rng);
      }
      ClothState pieces = once;
      for (auto [s, l] : {std::pair{&once, static_cast<ForceLoops*>(nullptr)}, std::pair{&pieces, &loops}}) {
        clearForces(*s);
        accumulateMembraneForces(*model, *s, l);
        accumulateBendingForces(*model, *s, 1.0, l);
      }
      for (std::size_t v = 0; v < once.size(); ++v) {
        ASSERT_EQ(once.fx[v], pieces.fx[v]) << "trial " << trial << " vertex " << v;
        ASSERT_EQ(once.fy[v], pieces.fy[v]) << "trial " << trial << " vertex " << v;
        ASSERT_EQ(once.fz[v], pieces.fz[v]) << "trial " << trial << " vertex " << v;
      }
    }
  }
}

}  // namespace
}  // namespace drape::cloth
