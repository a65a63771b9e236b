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
      const double dx = x[j] - x[i], dy = y[j] - y[i], dz = z[j] - z[i];
      const double most = stretch * rest[e];
      const double length2 = dx * dx + dy * dy + dz * dz;
      if (!(length2 > most * most)) continue;  // within the limit (the common case), or NaN: the guard's
      const double wi = weight[i], wj = weight[j], w = wi + wj;
      if (!(w > 0.0)) continue;  // both ends held
      const double length = std::sqrt(length2);
      const double nx = dx / length, ny = dy / length, nz = dz / length;
      // Both ends move along the edge, inversely to their masses, until it is `most` long.
      drawTogether(x, y, z, i, j, wi, wj, (length - most) / w, nx, ny, nz);
      // A relative velocity that stretches the edge further would undo the pull in the next
      // substep: it goes, shared the same way (an inelastic impulse along the edge).
      const double apart = (vx[j] - vx[i]) * nx + (vy[j] - vy[i]) * ny + (vz[j] - vz[i]) * nz;
      if (apart > 0.0) drawTogether(vx, vy, vz, i, j, wi, wj, apart / w, nx, ny, nz);
      ++corrections;
    }
  }
  return corrections;
}

}  // namespace drape::cloth
