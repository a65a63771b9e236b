// The DVDP lookup table (paper Figures 3-5, Table 1, conditions (1) and (2)).

#include <gtest/gtest.h>

#include <set>
#include <tuple>

#include "drape/field/propagation.hpp"

namespace drape::field {
namespace {

int length2(int x, int y, int z) { return x * x + y * y + z * z; }

TEST(LookupTable, EveryOffsetOfTheTetrahedronOnceInNonDecreasingLength) {
  const int radius = 20;
  const LookupTable t = LookupTable::build(radius);
  std::set<std::tuple<int, int, int>> seen;
  for (std::size_t i = 0; i < t.offsets.size(); ++i) {
    const TableOffset& o = t.offsets[i];
    ASSERT_TRUE(0 <= o.y && o.y <= o.z && o.z <= o.x);
    ASSERT_EQ(o.length2, length2(o.x, o.y, o.z));
    ASSERT_LE(o.length2, radius * radius);
    ASSERT_TRUE(seen.insert({o.x, o.y, o.z}).second) << "duplicate offset";
    if (i > 0) {
      ASSERT_LE(t.offsets[i - 1].length2, o.length2);
    }
  }
  std::size_t expected = 0;
  for (int x = 0; x <= radius; ++x)
    for (int z = 0; z <= x; ++z)
      for (int y = 0; y <= z; ++y) expected += length2(x, y, z) <= radius * radius;
  EXPECT_EQ(t.offsets.size(), expected);
}

TEST(LookupTable, OneIterationPerDistinctLength) {
  const LookupTable t = LookupTable::build(15);
  ASSERT_EQ(t.iterationLength2.front(), 0);
  for (int i = 0; i < t.iterationCount(); ++i) {
    if (i > 0) {
      EXPECT_LT(t.iterationLength2[i - 1], t.iterationLength2[i]);
    }
    for (int k = t.iterationOffsetStart[i]; k < t.iterationOffsetStart[i + 1]; ++k)
      EXPECT_EQ(t.offsets[k].length2, t.iterationLength2[i]);
  }
  // The 2D example of Figure 3: length^2 25 holds two offsets, (5,0,0) and (4,0,3).
  const int i25 = t.iterationOfLength2[25];
  EXPECT_EQ(t.iterationOffsetStart[i25 + 1] - t.iterationOffsetStart[i25], 2);
  // Sums of three squares only: 7 = 4^0 (8 * 0 + 7) has no offset.
  EXPECT_EQ(t.iterationOfLength2[7], -1);
}

TEST(LookupTable, SourcesSatisfyConditionsOneAndTwo) {
  const LookupTable t = LookupTable::build(24);
  for (const TableOffset& d : t.offsets) {
    if (d.length2 == 0) continue;
    const TableOffset s = d.source();
    // The source lies in the tetrahedron and its step to d has the action's connectivity.
    ASSERT_TRUE(0 <= s.y && s.y <= s.z && s.z <= s.x);
    const int steps = (d.x != s.x) + (d.y != s.y) + (d.z != s.z);
    ASSERT_EQ(steps, static_cast<int>(d.connectivity) + 1);
    ASSERT_LE(std::abs(d.x - s.x) + std::abs(d.y - s.y) + std::abs(d.z - s.z), 3);
    // (1) |v_s| < |v_d|.
    ASSERT_LT(s.length2, d.length2);
    // (2) every neighbour of v_s with that connectivity is no farther than v_d.
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if ((dx != 0) + (dy != 0) + (dz != 0) != steps) continue;
          ASSERT_LE(length2(s.x + dx, s.y + dy, s.z + dz), d.length2)
              << "offset " << d.x << "," << d.y << "," << d.z;
        }
  }
}

TEST(LookupTable, ActionsSourceEarlierIterationsAndSetsAreReleasedAfterTheirLastUse) {
  const LookupTable t = LookupTable::build(30);
  for (int i = 1; i < t.iterationCount(); ++i) {
    ASSERT_GT(t.actionStart[i + 1], t.actionStart[i]) << "iteration " << i << " has no action";
    for (int a = t.actionStart[i]; a < t.actionStart[i + 1]; ++a) {
      const int j = t.actions[a].sourceIteration;
      ASSERT_LT(j, i);
      if (t.lastUse[j] >= 0) {
        ASSERT_LE(i, t.lastUse[j]);
      }
    }
  }
  // The cached table grows and keeps the iterations of smaller ones.
  const LookupTable& small = LookupTable::forRadius(10);
  const LookupTable& large = LookupTable::forRadius(small.radius * 2);
  for (int i = 0; i < small.iterationCount(); ++i) EXPECT_EQ(small.iterationLength2[i], large.iterationLength2[i]);
}

}  // namespace
}  // namespace drape::field
