#include "drape/cloth/collider.hpp"

#include <algorithm>
#include <cmath>

namespace drape::cloth {

SphereCollider::SphereCollider(const Vec3& centre_m, double radius_m, double margin_m)
    : centre_(centre_m), radius_(radius_m + margin_m) {}

void SphereCollider::collide(const ClothModel& model, double, double, ClothState& io) {
  const double cx = centre_.x(), cy = centre_.y(), cz = centre_.z();
  const double r = radius_, r2 = r * r;
  const double muStatic = model.material().staticFriction;
  const double muDynamic = model.material().dynamicFriction;
  const std::size_t n = io.size();
  ++counters_.calls;
  counters_.pointsTested += n;
  for (std::size_t i = 0; i < n; ++i) {
    const double dx = io.x[i] - cx, dy = io.y[i] - cy, dz = io.z[i] - cz;
    const double d2 = dx * dx + dy * dy + dz * dz;
    if (d2 >= r2 || d2 <= 0.0) continue;
    // Project onto the surface along the radial normal.
    const double d = std::sqrt(d2), inv = 1.0 / d;
    const double nx = dx * inv, ny = dy * inv, nz = dz * inv;
    counters_.maxPenetration_m = std::max(counters_.maxPenetration_m, r - d);
    ++counters_.contacts;
    io.x[i] = cx + nx * r;
    io.y[i] = cy + ny * r;
    io.z[i] = cz + nz * r;
    // Remove the inward normal velocity; Coulomb friction on the tangential part.
    double vx = io.vx[i], vy = io.vy[i], vz = io.vz[i];
    const double vn = vx * nx + vy * ny + vz * nz;
    if (vn >= 0.0) continue;
    vx -= vn * nx;
    vy -= vn * ny;
    vz -= vn * nz;
    const double vt = std::sqrt(vx * vx + vy * vy + vz * vz);
    const double lost = -vn;  // normal speed removed, m/s (the impulse per mass)
    const double keep = vt <= muStatic * lost ? 0.0 : std::max(0.0, 1.0 - muDynamic * lost / vt);
    io.vx[i] = vx * keep;
    io.vy[i] = vy * keep;
    io.vz[i] = vz * keep;
  }
}

}  // namespace drape::cloth
