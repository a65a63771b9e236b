#include "drape/cloth/voxel_walk.hpp"

#include <vector>

namespace drape::cloth {

const WalkTableEntry* walkTable() {
  static const std::vector<WalkTableEntry> table = [] {
    constexpr int r = kWalkTableReach;
    std::vector<WalkTableEntry> t;
    t.reserve((2 * r + 1) * (2 * r + 1) * (2 * r + 1));
    for (int z = -r; z <= r; ++z)
      for (int y = -r; y <= r; ++y)
        for (int x = -r; x <= r; ++x) {
          WalkTableEntry e;
          Vec3i prev = Vec3i::Zero();
          walkVoxels(Vec3i::Zero(), Vec3i(x, y, z), [&](const Vec3i& p) {
            if (p != prev) {
              const Vec3i move = p - prev;
              e.step[e.steps++] = {static_cast<std::int8_t>(move.x()), static_cast<std::int8_t>(move.y()),
                                   static_cast<std::int8_t>(move.z())};
              prev = p;
            }
            return true;
          });
          t.push_back(e);
        }
    return t;
  }();
  return table.data();
}

}  // namespace drape::cloth
