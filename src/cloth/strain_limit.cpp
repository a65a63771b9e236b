#include "drape/cloth/strain_limit.hpp"

#include <cmath>
#include <cstdint>

namespace drape::cloth {
namespace {

/// Moves vertex i by wi * amount along n and vertex j by wj * amount against it, in the
/// arrays (x, y, z): positions or velocities.
inline void drawTogether(double* x, double* y, double* z, std::uint32_t i, std::uint32_t j, double wi, double wj,
                         double amount, double nx, double ny, double nz) {
  x[i] += wi * amount * nx;
  y[i] += wi * amount * ny;
  z[i] += wi * amount * nz;
  x[j] -= wj * amount * nx;
  y[j] -= wj * amount * ny;
  z[j] -= wj * amount * nz;
}

/// Pulls vertices i and j, `most` apart at most, back to `most` (limitStrain, holdStitches);
/// false when they are within it (or a value is NaN: the stability guard's), or both held.
inline bool pullWithin(double* x, double* y, double* z, double* vx, double* vy, double* vz, std::uint32_t i,
                       std::uint32_t j, double most, double wi, double wj) {
  const double dx = x[j] - x[i], dy = y[j] - y[i], dz = z[j] - z[i];
  const double length2 = dx * dx + dy * dy + dz * dz;
  if (!(length2 > most * most)) return false;  // within the limit (the common case), or NaN
  const double w = wi + wj;
  if (!(w > 0.0)) return false;  // both ends held
  const double length = std::sqrt(length2);
  const double nx = dx / length, ny = dy / length, nz = dz / length;
  // Both ends move along the line between them, inversely to their masses, until they are
  // `most` apart.
  drawTogether(x, y, z, i, j, wi, wj, (length - most) / w, nx, ny, nz);
  // A relative velocity that draws them further apart would undo the pull in the next
  // substep: it goes, shared the same way (an inelastic impulse along the line).
  const double apart = (vx[j] - vx[i]) * nx + (vy[j] - vy[i]) * ny + (vz[j] - vz[i]) * nz;
  if (apart > 0.0) drawTogether(vx, vy, vz, i, j, wi, wj, apart / w, nx, ny, nz);
  return true;
}

}  // namespace

std::size_t limitStrain(const ClothModel& model, std::span<const double> weight, double limit, int sweeps,
                        ClothState& io) {
  const std::vector<std::uint32_t>& a = model.edgeV0();
  const std::vector<std::uint32_t>& b = model.edgeV1();
  const std::vector<double>& rest = model.edgeRestLength();
  const double stretch = 1.0 + limit;
  double *x = io.x.data(), *y = io.y.data(), *z = io.z.data();
  double *vx = io.vx.data(), *vy = io.vy.data(), *vz = io.vz.data();
  std::size_t corrections = 0;
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    for (std::size_t e = 0; e < rest.size(); ++e) {
      const std::uint32_t i = a[e], j = b[e];
      corrections += pullWithin(x, y, z, vx, vy, vz, i, j, stretch * rest[e], weight[i], weight[j]);
    }
  }
  return corrections;
}

std::vector<Stitch> stitchesDrawnTogether(std::span<const std::array<std::uint32_t, 2>> pairs) {
  std::vector<Stitch> stitches;
  stitches.reserve(pairs.size());
  for (const auto& [a, b] : pairs) stitches.push_back({a, b, 0.0});
  return stitches;
}

std::size_t holdStitches(std::span<const Stitch> stitches, std::span<const double> weight, int sweeps,
                         ClothState& io) {
  double *x = io.x.data(), *y = io.y.data(), *z = io.z.data();
  double *vx = io.vx.data(), *vy = io.vy.data(), *vz = io.vz.data();
  std::size_t corrections = 0;
  for (int sweep = 0; sweep < sweeps; ++sweep)
    for (const Stitch& s : stitches)
      corrections += pullWithin(x, y, z, vx, vy, vz, s.a, s.b, s.length_m, weight[s.a], weight[s.b]);
  return corrections;
}

}  // namespace drape::cloth
