#include "drape/cloth/integrator.hpp"

#include <algorithm>
#include <array>
#include <vector>

#include "drape/cloth/backward_euler.hpp"
#include "drape/core/error.hpp"

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

/// Sets a stage's state from the substep's start and the previous stage's slopes:
/// x = x0 + c v_prev, v = v0 + c (w f_prev + g), one component. The previous stage's
/// velocity and forces may be the stage's own arrays (read before they are written, element
/// by element), so no restrict on them.
void stageComponent(std::size_t n, double c, double g, const double* __restrict w, const double* __restrict x0,
                    const double* __restrict v0, const double* vPrev, const double* fPrev, double* x, double* v) {
  for (std::size_t i = 0; i < n; ++i) {
    const double a = fPrev[i] * w[i] + g;
    x[i] = x0[i] + c * vPrev[i];
    v[i] = v0[i] + c * a;
  }
}

/// Adds a stage's slopes, weighted, into the sums: dx += b v, dv += b (w f + g).
void addSlopes(std::size_t n, double b, double g, const double* __restrict w, const double* __restrict v,
               const double* __restrict f, double* __restrict dx, double* __restrict dv) {
  for (std::size_t i = 0; i < n; ++i) {
    dx[i] += b * v[i];
    dv[i] += b * (f[i] * w[i] + g);
  }
}

/// The classical fourth-order Runge-Kutta step on x' = v, v' = M^-1 f(x, v) + g:
///   k1 at (x0, v0), k2 at the midpoint by k1, k3 at the midpoint by k2, k4 at the end by k3,
///   (x, v) += dt / 6 (k1 + 2 k2 + 2 k3 + k4).
/// The first stage's forces are the ones the step accumulated; StageForces gives the other
/// three. Four force evaluations per substep for a stable step sqrt(2) times symplectic
/// Euler's on an undamped oscillator (|omega dt| <= 2 sqrt(2) against 2): the dearer per
/// simulated second on stiff cloth, but fourth-order accurate where the motion is smooth.
class RungeKutta4 final : public Integrator {
 public:
  [[nodiscard]] IntegratorKind kind() const override { return IntegratorKind::RungeKutta4; }
  void prepare(const ClothModel& model, const StepSettings& /*settings*/,
               std::span<const std::uint8_t> fixed) override {
    sizedFor_ = nullptr;
    size(model);
    skip_.assign(model.vertexCount(), 0);
    for (std::size_t v = 0; v < skip_.size(); ++v)
      skip_[v] = static_cast<std::uint8_t>((v < fixed.size() && fixed[v]) || !(model.inverseMass()[v] > 0.0));
    holds_.reserve(model.vertexCount());
  }
  void useStageForces(StageForces* forces) override { forces_ = forces; }
  // Its substep is longer than symplectic Euler's (sqrt(2) times the bound, and mass scaling
  // aims at it), and its stages feel no contact: a pinched point, pulled into the crease by
  // the cloth around it over the whole substep, ended a few hundredths of a millimetre
  // inside a part on two walks (docs/PERFORMANCE.md). Held as the implicit solve holds it.
  void holdPinched(std::span<const PinchedPoint> points) override { addHolds(points, skip_, isHeld_, holds_); }

  void advance(const ClothModel& model, const Vec3& g, double dt, ClothState& io) override {
    if (forces_ == nullptr)
      throw Error("the runge-kutta-4 step was given no stage forces", ExitCode::Internal);
    size(model);  // sized by prepare: allocates only for a step not prepared
    const std::size_t n = io.size();
    const double* w = model.inverseMass().data();
    const std::array<double, 3> gravity{g.x(), g.y(), g.z()};
    const std::array<const double*, 3> x0{io.x.data(), io.y.data(), io.z.data()};
    const std::array<const double*, 3> v0{io.vx.data(), io.vy.data(), io.vz.data()};
    const std::array<const double*, 3> f0{io.fx.data(), io.fy.data(), io.fz.data()};
    const std::array<double*, 3> x{stage_.x.data(), stage_.y.data(), stage_.z.data()};
    const std::array<double*, 3> v{stage_.vx.data(), stage_.vy.data(), stage_.vz.data()};
    const std::array<double*, 3> f{stage_.fx.data(), stage_.fy.data(), stage_.fz.data()};
    holdAccelerations(w, g, io);
    for (int c = 0; c < 3; ++c) {
      std::fill(dx_[c].begin(), dx_[c].end(), 0.0);
      std::fill(dv_[c].begin(), dv_[c].end(), 0.0);
      addSlopes(n, 1.0, gravity[c], w, v0[c], f0[c], dx_[c].data(), dv_[c].data());
    }
    // Stage 2 from stage 1's slopes (the substep's start); stages 3 and 4 from the stage before.
    const std::array<double, 3> reach{0.5 * dt, 0.5 * dt, dt};
    const std::array<double, 3> weight{2.0, 2.0, 1.0};
    for (int k = 0; k < 3; ++k) {
      for (int c = 0; c < 3; ++c) {
        const double* vPrev = k == 0 ? v0[c] : v[c];
        const double* fPrev = k == 0 ? f0[c] : f[c];
        stageComponent(n, reach[k], gravity[c], w, x0[c], v0[c], vPrev, fPrev, x[c], v[c]);
      }
      forces_->accumulate(stage_);
      holdAccelerations(w, g, stage_);
      for (int c = 0; c < 3; ++c) addSlopes(n, weight[k], gravity[c], w, v[c], f[c], dx_[c].data(), dv_[c].data());
    }
    const double sixth = dt / 6.0;
    const std::array<double*, 3> xo{io.x.data(), io.y.data(), io.z.data()};
    const std::array<double*, 3> vo{io.vx.data(), io.vy.data(), io.vz.data()};
    for (int c = 0; c < 3; ++c)
      for (std::size_t i = 0; i < n; ++i) {
        xo[c][i] += sixth * dx_[c][i];
        vo[c][i] += sixth * dv_[c][i];
      }
    forces_ = nullptr;  // given again before each advance
    clearHolds(isHeld_, holds_);  // for this step alone
  }

 private:
  /// The held points' forces in `s` less what would accelerate them along their held
  /// directions (gravity included): every stage's velocity, and so the step's, keeps the
  /// component the colliders gave it there.
  void holdAccelerations(const double* w, const Vec3& g, ClothState& s) const {
    for (const HeldPoint& h : holds_) {
      const std::size_t i = h.vertex;
      const Vec3 a = Vec3(s.fx[i], s.fy[i], s.fz[i]) * w[i] + g;
      const Vec3 drop = (a - h.filtered(a)) / w[i];
      s.fx[i] -= drop.x();
      s.fy[i] -= drop.y();
      s.fz[i] -= drop.z();
    }
  }

  void size(const ClothModel& model) {
    if (&model == sizedFor_) return;
    sizedFor_ = &model;
    stage_ = ClothState::atRest(model);
    isHeld_.assign(model.vertexCount(), 0);
    for (int c = 0; c < 3; ++c) {
      dx_[c].assign(model.vertexCount(), 0.0);
      dv_[c].assign(model.vertexCount(), 0.0);
    }
  }

  StageForces* forces_ = nullptr;
  const ClothModel* sizedFor_ = nullptr;      ///< the model the workspace was sized for
  ClothState stage_;                          ///< the stage's positions, velocities and forces
  std::array<std::vector<double>, 3> dx_, dv_;  ///< the weighted sums of the stages' slopes
  std::vector<std::uint8_t> skip_;    ///< per vertex: placed by a fixture, or massless (never held)
  std::vector<std::uint8_t> isHeld_;  ///< per vertex: in holds_
  std::vector<HeldPoint> holds_;      ///< for the next step alone (holdPinched)
};

}  // namespace

void addHolds(std::span<const PinchedPoint> points, std::span<const std::uint8_t> skip, std::vector<std::uint8_t>& held,
              std::vector<HeldPoint>& holds) {
  for (const PinchedPoint& p : points) {
    const bool skipped = p.vertex < skip.size() && skip[p.vertex];
    if (p.vertex >= held.size() || skipped || held[p.vertex]) continue;  // one hold a vertex
    HeldPoint h{p.vertex, 0, {}};
    for (const Vec3& along : p.along) {
      Vec3 e = along;
      for (int k = 0; k < h.directions; ++k) e -= e.dot(h.e[k]) * h.e[k];
      const double length = e.norm();
      if (length > 1e-3) h.e[h.directions++] = e / length;  // not along one it holds already
    }
    if (h.directions == 0) continue;
    held[p.vertex] = 1;
    holds.push_back(h);
  }
}

void clearHolds(std::vector<std::uint8_t>& held, std::vector<HeldPoint>& holds) {
  for (const HeldPoint& h : holds) held[h.vertex] = 0;
  holds.clear();
}

std::unique_ptr<Integrator> makeIntegrator(IntegratorKind kind) {
  switch (kind) {
    case IntegratorKind::ForwardEuler: return std::make_unique<ForwardEuler>();
    case IntegratorKind::BackwardEuler: return std::make_unique<BackwardEuler>();
    case IntegratorKind::RungeKutta4: return std::make_unique<RungeKutta4>();
    case IntegratorKind::SymplecticEuler: break;
  }
  return std::make_unique<SymplecticEuler>();
}

}  // namespace drape::cloth
