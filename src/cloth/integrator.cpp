#include "drape/cloth/integrator.hpp"

#include "drape/cloth/backward_euler.hpp"

namespace drape::cloth {
namespace {

enum class Order { VelocityFirst, PositionFirst };

/// One explicit step over structure-of-arrays state. A function with restrict parameters:
/// GCC 12 vectorises it so, and not with the same pointers as locals of the member
/// function (it found no vector type for the loads there).
template <Order order>
void step(std::size_t n, double dt, double gx, double gy, double gz, const double* __restrict w,
          const double* __restrict fx, const double* __restrict fy, const double* __restrict fz, double* __restrict x,
          double* __restrict y, double* __restrict z, double* __restrict vx, double* __restrict vy,
          double* __restrict vz) {
  for (std::size_t i = 0; i < n; ++i) {
    if constexpr (order == Order::PositionFirst) {
      x[i] += dt * vx[i];
      y[i] += dt * vy[i];
      z[i] += dt * vz[i];
    }
    vx[i] += dt * (fx[i] * w[i] + gx);
    vy[i] += dt * (fy[i] * w[i] + gy);
    vz[i] += dt * (fz[i] * w[i] + gz);
    if constexpr (order == Order::VelocityFirst) {
      x[i] += dt * vx[i];
      y[i] += dt * vy[i];
      z[i] += dt * vz[i];
    }
  }
}

template <Order order>
void step(const ClothModel& model, const Vec3& g, double dt, ClothState& s) {
  step<order>(s.size(), dt, g.x(), g.y(), g.z(), model.inverseMass().data(), s.fx.data(), s.fy.data(), s.fz.data(),
              s.x.data(), s.y.data(), s.z.data(), s.vx.data(), s.vy.data(), s.vz.data());
}

/// Symplectic (semi-implicit) Euler: v(t+dt) = v + dt a(x), x(t+dt) = x + dt v(t+dt).
/// Bounded energy error for oscillators; the default.
class SymplecticEuler final : public Integrator {
 public:
  [[nodiscard]] IntegratorKind kind() const override { return IntegratorKind::SymplecticEuler; }
  void advance(const ClothModel& model, const Vec3& g, double dt, ClothState& s) override {
    step<Order::VelocityFirst>(model, g, dt, s);
  }
};

/// Forward (explicit) Euler, the paper's solver: x(t+dt) = x + dt v, v(t+dt) = v + dt a(x).
/// Its energy grows for undamped oscillators; damping must outweigh that.
class ForwardEuler final : public Integrator {
 public:
  [[nodiscard]] IntegratorKind kind() const override { return IntegratorKind::ForwardEuler; }
  void advance(const ClothModel& model, const Vec3& g, double dt, ClothState& s) override {
    step<Order::PositionFirst>(model, g, dt, s);
  }
};

}  // namespace

std::unique_ptr<Integrator> makeIntegrator(IntegratorKind kind) {
  switch (kind) {
    case IntegratorKind::ForwardEuler: return std::make_unique<ForwardEuler>();
    case IntegratorKind::BackwardEuler: return std::make_unique<BackwardEuler>();
    case IntegratorKind::SymplecticEuler: break;
  }
  return std::make_unique<SymplecticEuler>();
}

}  // namespace drape::cloth
