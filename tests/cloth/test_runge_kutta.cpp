// The classical Runge-Kutta step against analytic answers: its order on an oscillator, its
// stability bound, free fall, a hanging strip's elongation past symplectic Euler's step.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "cloth_fixture.hpp"
#include "drape/core/error.hpp"

namespace drape::cloth {
namespace {

using testing::fabric;
using testing::makeModel;
using testing::pinAt;
using testing::row;
using testing::run;
using testing::settingsWithStep;

/// A spring to the origin at every vertex, f = -m omega^2 x: each coordinate an undamped
/// oscillator of angular frequency omega, whatever the vertex's mass.
class OriginSprings final : public StageForces {
 public:
  OriginSprings(const ClothModel& model, double omega) : model_(model), omega2_(omega * omega) {}
  void accumulate(ClothState& io) override {
    for (std::size_t i = 0; i < io.size(); ++i) {
      const double k = model_.mass()[i] * omega2_;
      io.fx[i] = -k * io.x[i];
      io.fy[i] = -k * io.y[i];
      io.fz[i] = -k * io.z[i];
    }
  }

 private:
  const ClothModel& model_;
  double omega2_;
};

std::shared_ptr<const ClothModel> smallSheet() {
  SheetSpec spec;
  spec.cellsU = spec.cellsV = 3;
  return makeModel(irregularSheet(spec), fabric(1e5, 1e-3, 300));
}

/// Steps every vertex of `model` as an oscillator of angular frequency omega from x0 = its
/// rest position plus (0.1, 0, 0), v0 = (0, 0.2, 0), `steps` steps of omega dt = `phase`,
/// with `kind`; gives the state at the end.
ClothState oscillate(const ClothModel& model, IntegratorKind kind, double omega, double phase, long steps) {
  const std::unique_ptr<Integrator> integrator = makeIntegrator(kind);
  StepSettings settings;
  integrator->prepare(model, settings, {});
  OriginSprings springs(model, omega);
  ClothState s = ClothState::atRest(model);
  for (std::size_t i = 0; i < s.size(); ++i) {
    s.x[i] += 0.1;
    s.vy[i] = 0.2;
  }
  const double dt = phase / omega;
  for (long k = 0; k < steps; ++k) {
    springs.accumulate(s);  // the step's own forces, as the solver's phase before integrate
    integrator->useStageForces(&springs);
    integrator->advance(model, Vec3::Zero(), dt, s);
  }
  return s;
}

/// The largest distance of any vertex from the exact oscillator's position at t.
double oscillatorError(const ClothModel& model, const ClothState& s, double omega, double t) {
  const ClothState start = ClothState::atRest(model);
  double worst = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const Vec3 x0(start.x[i] + 0.1, start.y[i], start.z[i]);
    const Vec3 v0(0.0, 0.2, 0.0);
    const Vec3 exact = x0 * std::cos(omega * t) + v0 * (std::sin(omega * t) / omega);
    worst = std::max(worst, (s.position(i) - exact).norm());
  }
  return worst;
}

// ---------------------------------------------------------------------------------------
// Fourth order: halving the step divides the error at a fixed time by 2^4. Symplectic Euler,
// first order in the positions, divides it by about 2.
TEST(RungeKutta4, AnOscillatorsErrorFallsSixteenfoldWhenTheStepHalves) {
  const auto model = smallSheet();
  const double omega = 3.0;
  const double t = 2.0;  // about one period
  std::vector<double> errors;
  for (const long steps : {100L, 200L, 400L}) {
    const ClothState s = oscillate(*model, IntegratorKind::RungeKutta4, omega, omega * t / steps, steps);
    errors.push_back(oscillatorError(*model, s, omega, t));
  }
  ASSERT_GT(errors[2], 1e-11);  // far above rounding: the ratios measure the method
  EXPECT_NEAR(std::log2(errors[0] / errors[1]), 4.0, 0.1) << errors[0] << " " << errors[1];
  EXPECT_NEAR(std::log2(errors[1] / errors[2]), 4.0, 0.1) << errors[1] << " " << errors[2];

  const double symplecticCoarse = oscillatorError(
      *model, oscillate(*model, IntegratorKind::SymplecticEuler, omega, omega * t / 200, 200), omega, t);
  const double symplecticFine = oscillatorError(
      *model, oscillate(*model, IntegratorKind::SymplecticEuler, omega, omega * t / 400, 400), omega, t);
  EXPECT_NEAR(std::log2(symplecticCoarse / symplecticFine), 1.0, 0.15);
  EXPECT_GT(symplecticFine, 1000.0 * errors[2]);
}

// On an undamped oscillator the step's amplification |R(i omega dt)| is at most 1 up to
// omega dt = 2 sqrt(2) (2.828), beyond it above 1; symplectic Euler's bound is 2.
TEST(RungeKutta4, HoldsAnOscillatorUpToTwoRootTwoRadiansPerStep) {
  const auto model = smallSheet();
  const double omega = 50.0;
  const auto amplitude = [&](IntegratorKind kind, double phase) {
    const ClothState s = oscillate(*model, kind, omega, phase, 3000);
    double worst = 0.0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      const Vec3 x = s.position(i);
      const Vec3 v = s.velocity(i);
      const double a = std::sqrt(x.squaredNorm() + v.squaredNorm() / (omega * omega));
      if (!std::isfinite(a)) return std::numeric_limits<double>::infinity();
      worst = std::max(worst, a);
    }
    return worst;
  };
  const double initial = amplitude(IntegratorKind::RungeKutta4, 1e-6);  // 3000 tiny steps: the start, nearly
  EXPECT_LE(amplitude(IntegratorKind::RungeKutta4, 2.80), initial * 1.0001);
  EXPECT_GT(amplitude(IntegratorKind::RungeKutta4, 2.86), initial * 10.0);
  EXPECT_GT(amplitude(IntegratorKind::SymplecticEuler, 2.10), initial * 10.0);
}

// ---------------------------------------------------------------------------------------
// A point the colliders found pinched between two parts is held along their normals for one
// step, as the implicit solve holds it: every stage's velocity, and so the step's, keeps the
// component the colliders gave it there, and its position moves that far along them. It is
// free across them, the other vertices step as without the hold (to the bit: the springs act
// on each vertex alone), a fixed vertex is never held, and the next step frees it.
TEST(RungeKutta4, APinchedPointKeepsItsVelocityAlongItsPartsNormalsForOneStep) {
  const auto model = smallSheet();
  const std::size_t n = model->vertexCount();
  const double omega = 40.0, dt = 0.01;
  std::mt19937 rng(20261207);
  std::normal_distribution<double> gauss;
  const auto unit = [&] { return Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized(); };
  ClothState start = ClothState::atRest(*model);
  for (std::size_t i = 0; i < n; ++i) {
    start.setPosition(i, start.position(i) + 0.05 * Vec3(gauss(rng), gauss(rng), gauss(rng)));
    start.setVelocity(i, 0.3 * Vec3(gauss(rng), gauss(rng), gauss(rng)));
  }
  // Vertex 5 between two parts, vertex 7 on one part's normal, vertex 0 fixed, and vertex 5
  // again (from another collider): its first hold stands.
  const std::vector<PinchedPoint> pinched = {
      {5, {unit(), unit()}}, {7, {unit(), Vec3::Zero()}}, {0, {unit(), unit()}}, {5, {unit(), unit()}}};
  std::vector<std::uint8_t> fixed(n, 0);
  fixed[0] = 1;
  const Vec3 gravity(0.0, -9.81, 0.0);
  OriginSprings springs(*model, omega);
  const auto step = [&](ClothState s, bool hold, Integrator& rk) {
    if (hold) rk.holdPinched(pinched);
    springs.accumulate(s);
    rk.useStageForces(&springs);
    rk.advance(*model, gravity, dt, s);
    return s;
  };
  const std::unique_ptr<Integrator> held = makeIntegrator(IntegratorKind::RungeKutta4);
  const std::unique_ptr<Integrator> free = makeIntegrator(IntegratorKind::RungeKutta4);
  held->prepare(*model, StepSettings{}, fixed);
  free->prepare(*model, StepSettings{}, fixed);
  const ClothState withHold = step(start, true, *held), without = step(start, false, *free);

  const auto dv = [&](const ClothState& s, std::size_t i) { return Vec3(s.velocity(i) - start.velocity(i)); };
  for (const Vec3& e : pinched[0].along) {
    EXPECT_NEAR(dv(withHold, 5).dot(e), 0.0, 1e-12);
    EXPECT_NEAR((withHold.position(5) - start.position(5)).dot(e), dt * start.velocity(5).dot(e), 1e-14);
    EXPECT_GT(std::abs(dv(without, 5).dot(e)), 1e-3) << "the springs and gravity would move it along e";
  }
  const Vec3 crease = pinched[0].along[0].cross(pinched[0].along[1]).normalized();
  EXPECT_GT(std::abs(dv(withHold, 5).dot(crease)), 1e-3) << "free along the crease";
  EXPECT_NEAR(dv(withHold, 7).dot(pinched[1].along[0]), 0.0, 1e-12);
  EXPECT_GT((dv(withHold, 7) - dv(withHold, 7).dot(pinched[1].along[0]) * pinched[1].along[0]).norm(), 1e-3)
      << "free along the part's surface";
  for (std::size_t i = 0; i < n; ++i) {
    if (i == 5 || i == 7) continue;
    EXPECT_EQ(withHold.position(i), without.position(i)) << "vertex " << i;
    EXPECT_EQ(withHold.velocity(i), without.velocity(i)) << "vertex " << i;
  }

  // The next step, with no pinch, moves vertex 5 along those directions again.
  const ClothState next = step(withHold, false, *held);
  EXPECT_GT(std::abs((next.velocity(5) - withHold.velocity(5)).dot(pinched[0].along[0])), 1e-3);
}

// ---------------------------------------------------------------------------------------
// No internal force acts on the centre of mass, and the step integrates constant
// acceleration exactly: it falls g t^2 / 2 (and moves v0 t), where symplectic Euler's falls
// g h^2 k (k + 1) / 2, g h t / 2 further (here a relative 2e-3). The sheet is deformed and
// moving, so the stages' internal forces are far from zero.
TEST(RungeKutta4, TheCentreOfMassFallsExactly) {
  SheetSpec spec{0.3, 0.3, 6, 6, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), "sheet"};
  const auto model = makeModel(irregularSheet(spec), fabric(1e5, 1e-3, 300));
  StepSettings settings = settingsWithStep(0.5 * model->estimatedStableStep_s());
  const auto centre = [&](const ClothState& s) {
    Vec3 p = Vec3::Zero(), v = Vec3::Zero();
    for (std::size_t i = 0; i < s.size(); ++i) {
      p += model->mass()[i] * s.position(i);
      v += model->mass()[i] * s.velocity(i);
    }
    return std::pair<Vec3, Vec3>(p / model->totalMass_kg(), v / model->totalMass_kg());
  };
  const auto fall = [&](IntegratorKind kind) {
    settings.integrator = kind;
    ClothSolver solver(model, settings);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> d(-0.005, 0.005);
    ClothState& s = solver.mutableState();
    for (std::size_t i = 0; i < s.size(); ++i) {
      s.y[i] += d(rng);
      s.z[i] += d(rng);
      s.vx[i] = 20 * d(rng);
    }
    const auto [p0, v0] = centre(s);
    EXPECT_TRUE(run(solver, 200));
    const auto [p, v] = centre(solver.state());
    return std::pair<Vec3, Vec3>(p - p0, v - v0);
  };
  const double t = 200.0 * settings.substep_s();
  const auto [moved, dv] = fall(IntegratorKind::RungeKutta4);
  const Vec3 g(0, -9.81, 0);
  EXPECT_LT((dv - g * t).norm(), 1e-10 * 9.81 * t) << dv.transpose();
  EXPECT_NEAR(moved.y(), -0.5 * 9.81 * t * t, 1e-10 * 0.5 * 9.81 * t * t);

  const auto [symplecticMoved, symplecticDv] = fall(IntegratorKind::SymplecticEuler);
  const double h = settings.substep_s();
  EXPECT_NEAR(symplecticMoved.y() - moved.y(), -0.5 * 9.81 * h * t, 1e-8);
}

// A strip hanging from its top edge settles to rho g L^2 / (2 E) at omega dt = 2.5, omega the
// membrane's stiffest mode with the top held: beyond symplectic Euler's bound of 2, within
// the Runge-Kutta step's 2 sqrt(2).
TEST(RungeKutta4, HangingStripElongationBeyondSymplecticEulersStep) {
  const double L = 1.0, W = 0.1, E = 1e6, rho = 1000, t = 1e-3;
  SheetSpec spec{W, L, 4, 40, Vec3(0, -L, 0), Vec3::UnitX(), Vec3::UnitY(), "strip"};
  Material mat = fabric(E, t, rho);
  mat.damping_s = 2e-5;
  const auto model = makeModel(gridSheet(spec), mat);
  const PinGroup top = pinAt(*model, row(spec, spec.cellsV));
  std::vector<std::uint8_t> held(model->vertexCount(), 0);
  for (const std::uint32_t v : top.vertices) held[v] = 1;
  const double omega = model->membraneFrequency_rad_s(held);
  StepSettings settings = settingsWithStep(2.5 / omega, 10.0);
  settings.maxRefinement = 1;
  settings.rescueStrainLimit = 0.0;
  ASSERT_GT(omega * settings.substep_s(), 2.2);  // the frame's whole substeps round the step down
  const long steps = static_cast<long>(1.5 / settings.substep_s());

  ClothSolver symplectic(model, settings, {top});
  EXPECT_FALSE(run(symplectic, steps)) << "symplectic Euler was stable at omega dt = " << omega * settings.substep_s();

  settings.integrator = IntegratorKind::RungeKutta4;
  ClothSolver solver(model, settings, {top});
  ASSERT_TRUE(run(solver, steps));
  const double drop = testing::meanDrop(*model, solver.state(), row(spec, 0));
  const double expected = rho * 9.81 * L * L / (2 * E);
  EXPECT_NEAR(drop, expected, 0.05 * expected);
}

// Undamped and without drag, a swinging sheet's total energy stays within a small band (the
// step dissipates at fourth order in the step; it never gains).
TEST(RungeKutta4, SwingingSheetKeepsItsEnergy) {
  SheetSpec spec{0.3, 0.3, 6, 6, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), "sheet"};
  const auto model = makeModel(gridSheet(spec), fabric(2e4, 1e-3, 300));
  StepSettings settings = settingsWithStep(0.3 * model->estimatedStableStep_s(), 0.0);
  settings.integrator = IntegratorKind::RungeKutta4;
  ClothSolver solver(model, settings, {pinAt(*model, {sheetVertex(spec, 0, 0), sheetVertex(spec, 6, 0)})});
  const double e0 = solver.totalEnergy();
  double drift = 0.0, kinetic = 0.0;
  for (int k = 0; k < 100; ++k) {
    ASSERT_TRUE(run(solver, 100));
    drift = std::max(drift, std::abs(solver.totalEnergy() - e0));
    kinetic = std::max(kinetic, kineticEnergy(*model, solver.state()));
  }
  ASSERT_GT(kinetic, 1e-3);
  EXPECT_LT(drift, 0.02 * kinetic);
}

TEST(RungeKutta4, RefusesABendingRhythmAndNeedsItsStageForces) {
  StepSettings settings;
  settings.integrator = IntegratorKind::RungeKutta4;
  settings.bendEvery = 4;
  EXPECT_NE(testing::refusal(settings).find("--bend-every must be 1 with the runge-kutta-4 integrator"),
            std::string::npos)
      << "refused with '" << testing::refusal(settings) << "'";
  settings.bendEvery = 8;
  settings.useIntegrator(IntegratorKind::RungeKutta4);
  EXPECT_EQ(settings.bendEvery, 1);
  EXPECT_EQ(parseIntegrator("runge-kutta-4"), IntegratorKind::RungeKutta4);
  EXPECT_EQ(integratorName(IntegratorKind::RungeKutta4), "runge-kutta-4");

  const auto model = smallSheet();
  const std::unique_ptr<Integrator> integrator = makeIntegrator(IntegratorKind::RungeKutta4);
  ClothState s = ClothState::atRest(*model);
  EXPECT_THROW(integrator->advance(*model, Vec3::Zero(), 1e-3, s), Error);
}

}  // namespace
}  // namespace drape::cloth
