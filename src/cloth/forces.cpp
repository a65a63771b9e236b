#include "drape/cloth/forces.hpp"

#include <algorithm>
#include <cmath>

namespace drape::cloth {
namespace {

struct V3 {
  double x, y, z;
};
inline V3 sub(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 add(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 mul(V3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline V3 load(const double* x, const double* y, const double* z, std::int64_t i) { return {x[i], y[i], z[i]}; }
inline void addTo(double* x, double* y, double* z, std::int64_t i, V3 f) {
  x[i] += f.x;
  y[i] += f.y;
  z[i] += f.z;
}

/// Symmetric 2x2 tensor (11, 22, 12).
struct Sym2 {
  double a, b, c;
};

/// Scales the compressive principal part of the stress S by `scale` (S and the strain share
/// principal directions, so a tension direction keeps its full stress).
inline Sym2 softenCompression(Sym2 s, double scale) {
  const double mean = 0.5 * (s.a + s.b);
  const double half = 0.5 * (s.a - s.b);
  const double radius = std::sqrt(half * half + s.c * s.c);
  const double s1 = mean + radius, s2 = mean - radius;
  if (s2 >= 0.0) return s;
  if (s1 <= 0.0) return {s.a * scale, s.b * scale, s.c * scale};
  // Unit eigenvector of s2: (s.c, s2 - s.a) or (s2 - s.b, s.c), whichever is longer.
  double nx = s.c, ny = s2 - s.a;
  if (nx * nx + ny * ny < 1e-300) {
    nx = s2 - s.b;
    ny = s.c;
  }
  const double inv = 1.0 / std::sqrt(nx * nx + ny * ny);
  nx *= inv;
  ny *= inv;
  const double k = (scale - 1.0) * s2;
  return {s.a + k * nx * nx, s.b + k * ny * ny, s.c + k * nx * ny};
}

}  // namespace

void clearForces(ClothState& io) {
  std::fill(io.fx.begin(), io.fx.end(), 0.0);
  std::fill(io.fy.begin(), io.fy.end(), 0.0);
  std::fill(io.fz.begin(), io.fz.end(), 0.0);
}

// Membrane, pass 1 (per triangle, no scatter, vectorises): f1 and f2 into the workspace.
// Pass 2 (scalar) scatters f1, f2 and f0 = -(f1 + f2) to the vertices.
template <bool kDamp, bool kSoften>
void membraneKernel(const ClothModel& model, ClothState& io) {
  const MembraneArrays& el = model.membraneArrays();
  const std::size_t n = el.area.size();
  const double lambda = model.lambdaT(), mu = model.muT();
  const double beta = model.material().damping_s;
  const double softScale = model.material().compressionScale;
  const double* __restrict x = io.x.data();
  const double* __restrict y = io.y.data();
  const double* __restrict z = io.z.data();
  const double* __restrict vx = io.vx.data();
  const double* __restrict vy = io.vy.data();
  const double* __restrict vz = io.vz.data();
  const std::int32_t* __restrict i0 = el.v0.data();
  const std::int32_t* __restrict i1 = el.v1.data();
  const std::int32_t* __restrict i2 = el.v2.data();
  const double* __restrict g1u = el.g1u.data();
  const double* __restrict g1v = el.g1v.data();
  const double* __restrict g2u = el.g2u.data();
  const double* __restrict g2v = el.g2v.data();
  const double* __restrict area = el.area.data();
  double* __restrict w = io.work.data();
  for (std::size_t t = 0; t < n; ++t) {
    // Deformation gradient columns Fu, Fv (F = d1 (x) g1 + d2 (x) g2).
    const V3 p0 = load(x, y, z, i0[t]);
    const V3 d1 = sub(load(x, y, z, i1[t]), p0);
    const V3 d2 = sub(load(x, y, z, i2[t]), p0);
    const V3 fu = add(mul(d1, g1u[t]), mul(d2, g2u[t]));
    const V3 fv = add(mul(d1, g1v[t]), mul(d2, g2v[t]));

    // Green strain E = (F^T F - I) / 2 and St Venant-Kirchhoff plane stress S (N/m).
    const double e11 = 0.5 * (dot(fu, fu) - 1.0), e22 = 0.5 * (dot(fv, fv) - 1.0), e12 = 0.5 * dot(fu, fv);
    const double tr = e11 + e22;
    Sym2 s{lambda * tr + 2.0 * mu * e11, lambda * tr + 2.0 * mu * e22, 2.0 * mu * e12};
    if constexpr (kSoften) s = softenCompression(s, softScale);

    // Internal damping: the same constitutive law applied to the strain rate, times beta (s).
    if constexpr (kDamp) {
      const V3 w0 = load(vx, vy, vz, i0[t]);
      const V3 w1 = sub(load(vx, vy, vz, i1[t]), w0);
      const V3 w2 = sub(load(vx, vy, vz, i2[t]), w0);
      const V3 du = add(mul(w1, g1u[t]), mul(w2, g2u[t]));
      const V3 dv = add(mul(w1, g1v[t]), mul(w2, g2v[t]));
      const double r11 = dot(fu, du), r22 = dot(fv, dv), r12 = 0.5 * (dot(du, fv) + dot(fu, dv));
      const double rtr = r11 + r22;
      s.a += beta * (lambda * rtr + 2.0 * mu * r11);
      s.b += beta * (lambda * rtr + 2.0 * mu * r22);
      s.c += beta * 2.0 * mu * r12;
    }

    // First Piola stress P = F S; f_i = -A P g_i = c_i1 Fu + c_i2 Fv. Only the four
    // coefficients are stored (see the bending kernel); pass 2 rebuilds Fu, Fv.
    const double A = area[t];
    w[t] = -A * (s.a * g1u[t] + s.c * g1v[t]);          // f1 = w0 Fu + w1 Fv
    w[n + t] = -A * (s.c * g1u[t] + s.b * g1v[t]);
    w[2 * n + t] = -A * (s.a * g2u[t] + s.c * g2v[t]);  // f2 = w2 Fu + w3 Fv
    w[3 * n + t] = -A * (s.c * g2u[t] + s.b * g2v[t]);
  }
  double* fx = io.fx.data();
  double* fy = io.fy.data();
  double* fz = io.fz.data();
  for (std::size_t t = 0; t < n; ++t) {
    const V3 p0 = load(x, y, z, i0[t]);
    const V3 d1 = sub(load(x, y, z, i1[t]), p0);
    const V3 d2 = sub(load(x, y, z, i2[t]), p0);
    const V3 fu = add(mul(d1, g1u[t]), mul(d2, g2u[t]));
    const V3 fv = add(mul(d1, g1v[t]), mul(d2, g2v[t]));
    const V3 f1 = add(mul(fu, w[t]), mul(fv, w[n + t]));
    const V3 f2 = add(mul(fu, w[2 * n + t]), mul(fv, w[3 * n + t]));
    addTo(fx, fy, fz, i1[t], f1);
    addTo(fx, fy, fz, i2[t], f2);
    addTo(fx, fy, fz, i0[t], mul(add(f1, f2), -1.0));
  }
}

void accumulateMembraneForces(const ClothModel& model, ClothState& io) {
  const bool damp = model.material().damping_s > 0.0;
  const bool soften = model.material().compressionScale < 1.0;
  if (damp && soften) membraneKernel<true, true>(model, io);
  else if (damp) membraneKernel<true, false>(model, io);
  else if (soften) membraneKernel<false, true>(model, io);
  else membraneKernel<false, false>(model, io);
}

// Bending, pass 1 (per hinge, no scatter, vectorises): the four hinge forces into the
// workspace. Pass 2 (scalar) scatters them.
void accumulateBendingForces(const ClothModel& model, ClothState& io) {
  const BendArrays& h = model.bendArrays();
  const std::size_t n = h.stiffness.size();
  const double* __restrict x = io.x.data();
  const double* __restrict y = io.y.data();
  const double* __restrict z = io.z.data();
  const std::int32_t* __restrict ie0 = h.e0.data();
  const std::int32_t* __restrict ie1 = h.e1.data();
  const std::int32_t* __restrict ia = h.a.data();
  const std::int32_t* __restrict ib = h.b.data();
  const double* __restrict restPsi = h.restPsi.data();
  const double* __restrict k = h.stiffness.data();
  double* __restrict w = io.work.data();
  for (std::size_t i = 0; i < n; ++i) {
    // Hinge normals with edge-local orientation (see BendElement) and the edge vector.
    const V3 x3 = load(x, y, z, ie0[i]), x4 = load(x, y, z, ie1[i]);
    const V3 x1 = load(x, y, z, ia[i]), x2 = load(x, y, z, ib[i]);
    const V3 e = sub(x4, x3);
    const V3 n1 = cross(sub(x1, x3), sub(x1, x4));
    const V3 n2 = cross(sub(x2, x4), sub(x2, x3));
    // A collapsed hinge has no direction: its force is zero (selects, not a branch).
    const double n1sq = dot(n1, n1), n2sq = dot(n2, n2), esq = dot(e, e);
    const bool ok = n1sq > 1e-300 && n2sq > 1e-300 && esq > 1e-300;
    const double n1s = ok ? n1sq : 1.0, n2s = ok ? n2sq : 1.0, es = ok ? esq : 1.0;

    // cos(theta) and the sign of theta; psi = 2 sin(theta/2), dpsi/dtheta = cos(theta/2).
    const double c = std::min(1.0, std::max(-1.0, dot(n1, n2) / std::sqrt(n1s * n2s)));
    const double psiAbs = std::sqrt(2.0 * (1.0 - c));
    const double psi = dot(cross(n1, n2), e) < 0.0 ? -psiAbs : psiAbs;
    const double cosHalf = std::sqrt(0.5 * (1.0 + c));

    // dtheta/dx_i = -u_i with Bridson et al. (2003)'s u_i, which sum to zero exactly:
    //   u_a = |e| N1 / |N1|^2, u_b = |e| N2 / |N2|^2,
    //   u_e0 = ((a - e1).e N1 / |N1|^2 + (b - e1).e N2 / |N2|^2) / |e|, u_e1 = -(u_a + u_b + u_e0).
    // f_i = -k (psi - psi0) dpsi/dx_i = k (psi - psi0) cos(theta/2) u_i. Every force is a
    // combination of N1 and N2, so only four coefficients are stored (GCC 12 stops
    // vectorising this loop beyond about four output streams).
    const double m = ok ? k[i] * (psi - restPsi[i]) * cosHalf : 0.0;
    const double elen = std::sqrt(es), invE = 1.0 / elen;
    const double r1 = m / n1s, r2 = m / n2s;
    w[i] = r1 * elen;                                   // f_a = w0 N1
    w[n + i] = r2 * elen;                               // f_b = w1 N2
    w[2 * n + i] = r1 * dot(sub(x1, x4), e) * invE;     // f_e0 = w2 N1 + w3 N2
    w[3 * n + i] = r2 * dot(sub(x2, x4), e) * invE;
  }
  double* fx = io.fx.data();
  double* fy = io.fy.data();
  double* fz = io.fz.data();
  for (std::size_t i = 0; i < n; ++i) {
    const V3 x3 = load(x, y, z, ie0[i]), x4 = load(x, y, z, ie1[i]);
    const V3 x1 = load(x, y, z, ia[i]), x2 = load(x, y, z, ib[i]);
    const V3 n1 = cross(sub(x1, x3), sub(x1, x4));
    const V3 n2 = cross(sub(x2, x4), sub(x2, x3));
    const V3 fa = mul(n1, w[i]), fb = mul(n2, w[n + i]);
    const V3 fe0 = add(mul(n1, w[2 * n + i]), mul(n2, w[3 * n + i]));
    addTo(fx, fy, fz, ia[i], fa);
    addTo(fx, fy, fz, ib[i], fb);
    addTo(fx, fy, fz, ie0[i], fe0);
    addTo(fx, fy, fz, ie1[i], mul(add(add(fa, fb), fe0), -1.0));
  }
}

void accumulateDragForces(const ClothModel& model, const StepSettings& settings, ClothState& io) {
  const double c = settings.airViscosity_Ns_m3;
  if (c <= 0.0) return;
  const double wx = settings.wind_m_s.x(), wy = settings.wind_m_s.y(), wz = settings.wind_m_s.z();
  const std::size_t n = io.size();
  const double* __restrict area = model.vertexArea().data();
  const double* __restrict vx = io.vx.data();
  const double* __restrict vy = io.vy.data();
  const double* __restrict vz = io.vz.data();
  double* __restrict fx = io.fx.data();
  double* __restrict fy = io.fy.data();
  double* __restrict fz = io.fz.data();
  for (std::size_t i = 0; i < n; ++i) {
    const double k = c * area[i];
    fx[i] -= k * (vx[i] - wx);
    fy[i] -= k * (vy[i] - wy);
    fz[i] -= k * (vz[i] - wz);
  }
}

double membraneEnergy(const ClothModel& model, const ClothState& s) {
  const double lambda = model.lambdaT(), mu = model.muT();
  double energy = 0.0;
  for (const MembraneElement& el : model.membrane()) {
    const V3 p0 = load(s.x.data(), s.y.data(), s.z.data(), el.v0);
    const V3 d1 = sub(load(s.x.data(), s.y.data(), s.z.data(), el.v1), p0);
    const V3 d2 = sub(load(s.x.data(), s.y.data(), s.z.data(), el.v2), p0);
    const V3 fu = add(mul(d1, el.g1u), mul(d2, el.g2u));
    const V3 fv = add(mul(d1, el.g1v), mul(d2, el.g2v));
    const double e11 = 0.5 * (dot(fu, fu) - 1.0), e22 = 0.5 * (dot(fv, fv) - 1.0), e12 = 0.5 * dot(fu, fv);
    const double tr = e11 + e22;
    // W = A (mu E:E + lambda/2 tr(E)^2)
    energy += el.restArea_m2 * (mu * (e11 * e11 + e22 * e22 + 2.0 * e12 * e12) + 0.5 * lambda * tr * tr);
  }
  return energy;
}

double bendingEnergy(const ClothModel& model, const ClothState& s) {
  double energy = 0.0;
  for (const BendElement& h : model.bending()) {
    const V3 x3 = load(s.x.data(), s.y.data(), s.z.data(), h.e0), x4 = load(s.x.data(), s.y.data(), s.z.data(), h.e1);
    const V3 x1 = load(s.x.data(), s.y.data(), s.z.data(), h.a), x2 = load(s.x.data(), s.y.data(), s.z.data(), h.b);
    const V3 e = sub(x4, x3);
    const V3 n1 = cross(sub(x1, x3), sub(x1, x4));
    const V3 n2 = cross(sub(x2, x4), sub(x2, x3));
    const double n1sq = dot(n1, n1), n2sq = dot(n2, n2);
    if (n1sq <= 1e-300 || n2sq <= 1e-300) continue;
    const double c = std::clamp(dot(n1, n2) / std::sqrt(n1sq * n2sq), -1.0, 1.0);
    const double sign = dot(cross(n1, n2), e) < 0.0 ? -1.0 : 1.0;
    const double d = sign * std::sqrt(2.0 * (1.0 - c)) - h.restPsi;
    energy += 0.5 * h.stiffness_Nm * d * d;
  }
  return energy;
}

double kineticEnergy(const ClothModel& model, const ClothState& s) {
  double energy = 0.0;
  const auto& m = model.mass();
  for (std::size_t i = 0; i < s.size(); ++i)
    energy += 0.5 * m[i] * (s.vx[i] * s.vx[i] + s.vy[i] * s.vy[i] + s.vz[i] * s.vz[i]);
  return energy;
}

double gravityEnergy(const ClothModel& model, const ClothState& s, const Vec3& g) {
  double energy = 0.0;
  const auto& m = model.mass();
  for (std::size_t i = 0; i < s.size(); ++i) energy -= m[i] * (g.x() * s.x[i] + g.y() * s.y[i] + g.z() * s.z[i]);
  return energy;
}

double maxEdgeStrain(const ClothModel& model, const ClothState& s) {
  double worst = 0.0;
  const auto& a = model.edgeV0();
  const auto& b = model.edgeV1();
  const auto& rest = model.edgeRestLength();
  for (std::size_t e = 0; e < rest.size(); ++e) {
    if (!(rest[e] > 0.0)) continue;
    const double dx = s.x[b[e]] - s.x[a[e]], dy = s.y[b[e]] - s.y[a[e]], dz = s.z[b[e]] - s.z[a[e]];
    const double strain = std::abs(std::sqrt(dx * dx + dy * dy + dz * dz) - rest[e]) / rest[e];
    if (!(strain <= worst)) worst = strain;  // also propagates NaN
  }
  return worst;
}

}  // namespace drape::cloth
