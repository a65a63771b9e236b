#pragma once
// ClothState: how one garment instance moves (STYLE habit 1). Structure of arrays, one
// double per vertex per component (positions m, velocities m/s, forces N), 72 bytes per
// vertex in all, so every per-vertex loop is a plain vectorisable loop. Sized once; the
// step never allocates.

#include <cstdint>
#include <span>
#include <vector>

#include "drape/core/math.hpp"

namespace drape::cloth {

class ClothModel;

struct ClothState {
  std::vector<double> x, y, z;     ///< positions, m
  std::vector<double> vx, vy, vz;  ///< velocities, m/s
  std::vector<double> fx, fy, fz;  ///< force accumulators of the current substep, N
  /// Workspace of the force kernels (per-element forces before they are scattered to the
  /// vertices); sized by atRest, not part of the state proper (hash() ignores it).
  std::vector<double> work;

  /// Rest positions, zero velocity; sizes the workspace for the model's elements.
  [[nodiscard]] static ClothState atRest(const ClothModel& model);
  [[nodiscard]] std::size_t size() const { return x.size(); }
  [[nodiscard]] Vec3 position(std::size_t i) const { return {x[i], y[i], z[i]}; }
  [[nodiscard]] Vec3 velocity(std::size_t i) const { return {vx[i], vy[i], vz[i]}; }
  void setPosition(std::size_t i, const Vec3& p) { x[i] = p.x(); y[i] = p.y(); z[i] = p.z(); }
  void setVelocity(std::size_t i, const Vec3& v) { vx[i] = v.x(); vy[i] = v.y(); vz[i] = v.z(); }
  /// Copies positions into `out` (resized once), e.g. for writing a frame.
  void copyPositions(std::vector<Vec3>& out) const;
  /// FNV-1a hash of the bytes of positions and velocities (determinism checks).
  [[nodiscard]] std::uint64_t hash() const;
};

}  // namespace drape::cloth
