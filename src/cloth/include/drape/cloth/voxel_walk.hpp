#pragma once
// The voxel walks of the collision trace (paper section 4.3.3): the 3D Bresenham line, and
// the lookup-table walk the paper names as the potentially faster alternative. The table
// holds, for every offset of up to kWalkTableReach voxels along each axis, the unit steps
// the Bresenham line takes; it is built once from walkVoxels itself, so both walks visit the
// same voxels (tested on every offset in reach). Longer walks go to Bresenham.

#include <array>
#include <cstdint>

#include "drape/core/math.hpp"

namespace drape::cloth {

/// The voxels of a 3D Bresenham line from voxel `from` to voxel `to` (both included),
/// stopping early after a voxel for which `visit` returns false. Returns the number of
/// voxels visited.
template <typename Visit>
int walkVoxels(const Vec3i& from, const Vec3i& to, Visit&& visit) {
  Vec3i p = from;
  const Vec3i d = (to - from).cwiseAbs();
  const Vec3i s((to.x() > from.x()) - (to.x() < from.x()), (to.y() > from.y()) - (to.y() < from.y()),
                (to.z() > from.z()) - (to.z() < from.z()));
  int axis = 0;
  if (d.y() > d[axis]) axis = 1;
  if (d.z() > d[axis]) axis = 2;
  const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  const int n = d[axis];
  int e1 = 2 * d[a1] - n, e2 = 2 * d[a2] - n;
  int visited = 1;
  if (!visit(p)) return visited;
  for (int i = 0; i < n; ++i) {
    if (e1 > 0) {
      p[a1] += s[a1];
      e1 -= 2 * n;
    }
    if (e2 > 0) {
      p[a2] += s[a2];
      e2 -= 2 * n;
    }
    e1 += 2 * d[a1];
    e2 += 2 * d[a2];
    p[axis] += s[axis];
    ++visited;
    if (!visit(p)) break;
  }
  return visited;
}

/// Longest offset per axis the walk table holds, voxels.
inline constexpr int kWalkTableReach = 4;

/// One offset's walk: its number of steps and each step's unit move.
struct WalkTableEntry {
  std::uint8_t steps = 0;
  std::array<std::array<std::int8_t, 3>, kWalkTableReach> step{};
};

/// The table, (2 kWalkTableReach + 1)^3 entries indexed by the offset (built on first use,
/// shared, read-only after).
[[nodiscard]] const WalkTableEntry* walkTable();

/// The same walk as walkVoxels, with the steps of short walks read from walkTable().
template <typename Visit>
int walkVoxelsByTable(const Vec3i& from, const Vec3i& to, Visit&& visit) {
  constexpr int r = kWalkTableReach, side = 2 * kWalkTableReach + 1;
  const Vec3i d = to - from;
  if (d.x() < -r || d.x() > r || d.y() < -r || d.y() > r || d.z() < -r || d.z() > r)
    return walkVoxels(from, to, visit);
  const WalkTableEntry& e = walkTable()[((d.z() + r) * side + (d.y() + r)) * side + (d.x() + r)];
  Vec3i p = from;
  int visited = 1;
  if (!visit(p)) return visited;
  for (int k = 0; k < e.steps; ++k) {
    p += Vec3i(e.step[k][0], e.step[k][1], e.step[k][2]);
    ++visited;
    if (!visit(p)) break;
  }
  return visited;
}

}  // namespace drape::cloth
