#pragma once
// The distance-field voxel a new scene (`drape make-skirt`, `drape make-scene`) gives its
// avatar: 5 mm, as the paper's offsets (T0..T3 at 1, 2, 3 and 6 voxels) suit a person; for
// an avatar under 1 m tall (a toy robot: Choreonoid's GR001 is 0.26 m) the voxel shrinks
// with its height against a person's 1.7 m, since offsets of 3 cm around parts a few
// centimetres across overlap each other and the cloth between them goes unstable.

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <fmt/format.h>

#include "drape/scene/avatar.hpp"

namespace drape::cli {

inline constexpr double kPersonsVoxel_m = 0.005;

/// The avatar's height at rest: its body parts from the lowest point to the highest.
inline double restHeight_m(const scene::Avatar& avatar) {
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (const scene::Segment& s : avatar.segments) {
    const RigidTransform rest = avatar.joints[static_cast<std::size_t>(s.joint)].restWorld();
    for (const Vec3& v : s.mesh.positions) {
      const double y = rest.apply(v).y();
      low = std::min(low, y);
      high = std::max(high, y);
    }
  }
  return high > low ? high - low : 0.0;
}

/// The voxel for `avatar`'s scene, to 0.01 mm.
inline double voxelFor_m(const scene::Avatar& avatar) {
  constexpr double kPerson = 1.7, kSmall = 1.0;
  const double height = restHeight_m(avatar);
  if (!(height > 0.0) || height >= kSmall) return kPersonsVoxel_m;
  return std::round(kPersonsVoxel_m * height / kPerson * 1e5) / 1e5;
}

/// Says on standard output that `voxel` (voxelFor_m's) is scaled from a person's, if it is;
/// `more`: what else was scaled with it ("; clearance 3.0 mm (a person's: 20 mm)").
inline void sayWhereTheVoxelIsScaled(const scene::Avatar& avatar, const std::string& whose, double voxel,
                                     const std::string& more = "") {
  if (voxel == kPersonsVoxel_m) return;
  fmt::print("{} is {:.2f} m tall: distance-field voxel {:.2f} mm, offsets T0..T3 {:.2f} to {:.2f} mm (a person's: 5 "
             "mm, 5 to 30 mm){}\n",
             whose, restHeight_m(avatar), 1e3 * voxel, 1e3 * voxel, 6e3 * voxel, more);
}

}  // namespace drape::cli
