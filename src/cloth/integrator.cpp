#include "drape/cloth/integrator.hpp"

namespace drape::cloth {
namespace {

/// Symplectic (semi-implicit) Euler: v(t+dt) = v + dt a(x), x(t+dt) = x + dt v(t+dt).
/// Bounded energy error for oscillators; the default.
class SymplecticEuler final : public Integrator {
 public:
  [[nodiscard]] IntegratorKind kind() const override { return IntegratorKind::SymplecticEuler; }
  void advance(const ClothModel& model, const Vec3& g, double dt, ClothState& s) const override {
    const std::size_t n = s.size();
    const double* w = model.inverseMass().data();
    const double gx = g.x(), gy = g.y(), gz = g.z();
    double* __restrict x = s.x.data();
    double* __restrict y = s.y.data();
    double* __restrict z = s.z.data();
    double* __restrict vx = s.vx.data();
    double* __restrict vy = s.vy.data();
    double* __restrict vz = s.vz.data();
    const double* __restrict fx = s.fx.data();
    const double* __restrict fy = s.fy.data();
    const double* __restrict fz = s.fz.data();
    for (std::size_t i = 0; i < n; ++i) {
      vx[i] += dt * (fx[i] * w[i] + gx);
      vy[i] += dt * (fy[i] * w[i] + gy);
      vz[i] += dt * (fz[i] * w[i] + gz);
      x[i] += dt * vx[i];
      y[i] += dt * vy[i];
      z[i] += dt * vz[i];
    }
  }
};

/// Forward (explicit) Euler, the paper's solver: x(t+dt) = x + dt v, v(t+dt) = v + dt a(x).
/// Its energy grows for undamped oscillators; damping must outweigh that.
class ForwardEuler final : public Integrator {
 public:
  [[nodiscard]] IntegratorKind kind() const override { return IntegratorKind::ForwardEuler; }
  void advance(const ClothModel& model, const Vec3& g, double dt, ClothState& s) const override {
    const std::size_t n = s.size();
    const double* w = model.inverseMass().data();
    const double gx = g.x(), gy = g.y(), gz = g.z();
    double* __restrict x = s.x.data();
    double* __restrict y = s.y.data();
    double* __restrict z = s.z.data();
    double* __restrict vx = s.vx.data();
    double* __restrict vy = s.vy.data();
    double* __restrict vz = s.vz.data();
    const double* __restrict fx = s.fx.data();
    const double* __restrict fy = s.fy.data();
    const double* __restrict fz = s.fz.data();
    for (std::size_t i = 0; i < n; ++i) {
      x[i] += dt * vx[i];
      y[i] += dt * vy[i];
      z[i] += dt * vz[i];
      vx[i] += dt * (fx[i] * w[i] + gx);
      vy[i] += dt * (fy[i] * w[i] + gy);
      vz[i] += dt * (fz[i] * w[i] + gz);
    }
  }
};

}  // namespace

std::unique_ptr<Integrator> makeIntegrator(IntegratorKind kind) {
  switch (kind) {
    case IntegratorKind::ForwardEuler: return std::make_unique<ForwardEuler>();
    case IntegratorKind::SymplecticEuler: break;
  }
  return std::make_unique<SymplecticEuler>();
}

}  // namespace drape::cloth
