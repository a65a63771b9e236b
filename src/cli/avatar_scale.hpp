#pragma once
// The distance-field voxel a new scene (`drape make-skirt`, `drape make-scene`) gives its
// avatar: 5 mm, as the paper's offsets (T0..T3 at 1, 2, 3 and 6 voxels) suit a person; for
// an avatar under 1 m tall (a toy robot: Choreonoid's GR001 is 0.26 m) the voxel shrinks
// with its height against a person's 1.7 m, since offsets of 3 cm around parts a few
// centimetres across overlap each other and the cloth between them goes unstable.

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "drape/scene/avatar.hpp"
#include "drape/sim/garment_layers.hpp"

namespace drape::cli {

inline constexpr double kPersonsVoxel_m = 0.005;

/// An avatar's size and the voxel its scene is given.
struct SceneScale {
  double height_m = 0.0;               ///< its body parts at rest, from the lowest point to the highest
  double voxel_m = kPersonsVoxel_m;    ///< to 0.01 mm
  /// What a person's lengths (a skirt's clearance) are multiplied by: 1 for a person.
  [[nodiscard]] double factor() const { return voxel_m / kPersonsVoxel_m; }
};

inline SceneScale sceneScaleOf(const scene::Avatar& avatar) {
  constexpr double kPerson = 1.7, kSmall = 1.0;
  const std::vector<Vec3> body = sim::restBodyPoints(avatar, avatar.segmentNames());
  SceneScale s;
  if (body.empty()) return s;
  const auto [low, high] =
      std::minmax_element(body.begin(), body.end(), [](const Vec3& a, const Vec3& b) { return a.y() < b.y(); });
  s.height_m = high->y() - low->y();
  if (s.height_m > 0.0 && s.height_m < kSmall)
    s.voxel_m = std::round(kPersonsVoxel_m * s.height_m / kPerson * 1e5) / 1e5;
  return s;
}

/// Says on standard output that the voxel is scaled from a person's, if it is; `more`:
/// what else was scaled with it ("; clearance 3.0 mm (a person's: 20 mm)").
inline void sayWhereTheVoxelIsScaled(const SceneScale& s, const std::string& whose, const std::string& more = "") {
  if (s.voxel_m == kPersonsVoxel_m) return;
  fmt::print("{} is {:.2f} m tall: distance-field voxel {:.2f} mm, offsets T0..T3 {:.2f} to {:.2f} mm (a person's: 5 "
             "mm, 5 to 30 mm){}\n",
             whose, s.height_m, 1e3 * s.voxel_m, 1e3 * s.voxel_m, 6e3 * s.voxel_m, more);
}

}  // namespace drape::cli
