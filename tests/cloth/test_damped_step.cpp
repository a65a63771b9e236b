// Internal damping and the explicit step: the membrane's highest frequency (power iteration
// on the linearised stiffness) against a dense eigensolve, the linearised stiffness against
// finite differences of the force kernel, and the stability bound against the integrator
// itself: a little below it the stiffest mode dies away, a little above it grows.
#include <gtest/gtest.h>

// GCC 12 warns of an uninitialised register in Eigen's AVX-512 reductions (a false positive
// in the dense eigensolver, inlined here).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "cloth_fixture.hpp"
#include "drape/cloth/integrator.hpp"
#include "drape/core/error.hpp"

#include <fmt/format.h>

namespace drape::cloth {
namespace {

Material dampedKnit(double damping_s = 0.0) {
  Material m;
  m.youngsModulus_Pa = 5e4;
  m.thickness_m = 5e-4;
  m.density_kg_m3 = 300;
  m.compressionScale = 1.0;  // the linearisation is of the plain St Venant-Kirchhoff law
  m.damping_s = damping_s;
  return m;
}

/// A 0.2 m sheet of n x n cells with its interior vertices jittered in the plane by up to a
/// third of a cell and lifted into a shallow random bump: irregular, curved, no two
/// triangles alike.
mesh::TriMesh irregularSheet(int n, std::uint32_t seed) {
  const SheetSpec spec{0.2, 0.2, n, n, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), "irregular"};
  mesh::TriMesh m = gridSheet(spec);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-1.0 / 3.0, 1.0 / 3.0);
  const double cell = 0.2 / n;
  for (int i = 1; i < n; ++i)
    for (int j = 1; j < n; ++j) {
      Vec3& p = m.positions[sheetVertex(spec, i, j)];
      p.x() += jitter(rng) * cell;
      p.y() += jitter(rng) * cell;
    }
  const double a = 0.1 * jitter(rng), b = 0.1 * jitter(rng);
  for (Vec3& p : m.positions) p.z() = a * p.x() * p.x() / 0.2 + b * p.x() * p.y() / 0.2;
  return m;
}

/// M^-1/2 K M^-1/2 assembled column by column from membraneStiffnessTimes, with the fixed
/// vertices' rows and columns zero.
Eigen::MatrixXd scaledStiffness(const ClothModel& model, const std::vector<std::uint8_t>& fixed) {
  const std::size_t n = 3 * model.vertexCount();
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
  std::vector<double> e(n, 0.0), column(n);
  const auto weight = [&](std::size_t i) { return fixed[i / 3] ? 0.0 : std::sqrt(model.inverseMass()[i / 3]); };
  for (std::size_t j = 0; j < n; ++j) {
    e[j] = weight(j);
    model.membraneStiffnessTimes(e, column);
    e[j] = 0.0;
    for (std::size_t i = 0; i < n; ++i)
      a(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = weight(i) * column[i];
  }
  return a;
}

std::vector<std::uint8_t> randomlyFixed(std::size_t n, std::uint32_t seed, double fraction) {
  std::mt19937 rng(seed);
  std::bernoulli_distribution pick(fraction);
  std::vector<std::uint8_t> fixed(n);
  for (auto& f : fixed) f = pick(rng) ? 1 : 0;
  return fixed;
}

TEST(MembraneStiffness, IsTheDerivativeOfTheMembraneForcesAtRest) {
  for (std::uint32_t seed = 1; seed <= 5; ++seed) {
    const mesh::TriMesh sheet = irregularSheet(6, seed);
    const auto model = testing::makeModel(sheet, dampedKnit());
    const std::size_t n = 3 * model->vertexCount();
    std::mt19937 rng(seed);
    std::normal_distribution<double> normal;
    for (int trial = 0; trial < 4; ++trial) {
      std::vector<double> u(n), ku(n);
      for (double& e : u) e = normal(rng);
      model->membraneStiffnessTimes(u, ku);
      // Central differences of the force kernel along u: f(x + h u) - f(x - h u) = -2 h K u.
      const double h = 1e-7;
      std::vector<double> df(n, 0.0);
      for (const double side : {1.0, -1.0}) {
        ClothState s = ClothState::atRest(*model);
        for (std::size_t v = 0; v < model->vertexCount(); ++v) {
          s.x[v] += side * h * u[3 * v];
          s.y[v] += side * h * u[3 * v + 1];
          s.z[v] += side * h * u[3 * v + 2];
        }
        clearForces(s);
        accumulateMembraneForces(*model, s);
        for (std::size_t v = 0; v < model->vertexCount(); ++v) {
          df[3 * v] += side * s.fx[v];
          df[3 * v + 1] += side * s.fy[v];
          df[3 * v + 2] += side * s.fz[v];
        }
      }
      double scale = 0.0, worst = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        scale = std::max(scale, std::abs(ku[i]));
        worst = std::max(worst, std::abs(-df[i] / (2 * h) - ku[i]));
      }
      EXPECT_LT(worst, 1e-5 * scale) << "seed " << seed << ", trial " << trial;
    }
  }
}

TEST(MembraneFrequency, MatchesADenseEigensolveOnRandomSheets) {
  for (std::uint32_t seed = 1; seed <= 12; ++seed) {
    const mesh::TriMesh sheet = irregularSheet(4 + static_cast<int>(seed % 3), seed);
    const auto model = testing::makeModel(sheet, dampedKnit());
    const std::vector<std::uint8_t> fixed = randomlyFixed(model->vertexCount(), seed, seed % 2 ? 0.2 : 0.0);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(scaledStiffness(*model, fixed),
                                                             Eigen::EigenvaluesOnly);
    const double exact = std::sqrt(eig.eigenvalues().maxCoeff());
    EXPECT_NEAR(model->membraneFrequency_rad_s(fixed), exact, 1e-3 * exact) << "seed " << seed;
  }
}

/// The amplitude, relative to its start, of the stiffest mode after `steps` steps of the
/// membrane with its internal damping (symplectic Euler unless told), started from that mode
/// at rest.
double growthOfTheStiffestMode(const mesh::TriMesh& sheet, double damping_s, double dt, int steps,
                               IntegratorKind kind = IntegratorKind::SymplecticEuler) {
  const auto model = testing::makeModel(sheet, dampedKnit(damping_s));
  const std::vector<std::uint8_t> none(model->vertexCount(), 0);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(scaledStiffness(*model, none));
  Eigen::Index top = 0;
  eig.eigenvalues().maxCoeff(&top);
  const Eigen::VectorXd mode = eig.eigenvectors().col(top);
  ClothState s = ClothState::atRest(*model);
  const double amplitude = 1e-9;  // small enough to stay linear over a million-fold growth
  for (std::size_t v = 0; v < model->vertexCount(); ++v) {
    const double w = std::sqrt(model->inverseMass()[v]) * amplitude;
    s.x[v] += w * mode(static_cast<Eigen::Index>(3 * v));
    s.y[v] += w * mode(static_cast<Eigen::Index>(3 * v + 1));
    s.z[v] += w * mode(static_cast<Eigen::Index>(3 * v + 2));
  }
  const auto displacement = [&] {
    double most = 0.0;
    for (std::size_t v = 0; v < model->vertexCount(); ++v) {
      const double d = (s.position(v) - Vec3(model->restX()[v], model->restY()[v], model->restZ()[v])).norm();
      if (!std::isfinite(d)) return std::numeric_limits<double>::infinity();  // grown past doubles
      most = std::max(most, d);
    }
    return most;
  };
  const double start = displacement();
  const auto integrator = makeIntegrator(kind);
  StepSettings tight;
  tight.implicitTolerance = 1e-9;  // backward Euler's solve to its end: the mode's decay is what it measures
  integrator->prepare(*model, tight, {});
  for (int k = 0; k < steps; ++k) {
    clearForces(s);
    accumulateMembraneForces(*model, s);
    integrator->advance(*model, Vec3::Zero(), dt, s);
  }
  return displacement() / start;
}

TEST(DampedStep, TheBoundHoldsForTheStiffestModeAndNoFurther) {
  // With omega^2 dt (dt + 2 beta) = 4 the stiffest mode is neutral; 10 % less damping and
  // it dies away, 10 % more and it grows. (Without margin: dampedStableStep_s keeps 0.9.)
  const mesh::TriMesh sheet = irregularSheet(5, 7);
  const auto model = testing::makeModel(sheet, dampedKnit());
  const double omega = model->membraneFrequency_rad_s();
  const double dt = 0.5 / omega;  // a quarter of the undamped bound 2 / omega
  const double neutral = (4.0 / (omega * omega) - dt * dt) / (2.0 * dt);
  EXPECT_LT(growthOfTheStiffestMode(sheet, 0.9 * neutral, dt, 400), 1.0);
  EXPECT_GT(growthOfTheStiffestMode(sheet, 1.1 * neutral, dt, 400), 1e3);
  // The margin of the public bound, both ways round.
  EXPECT_NEAR(largestStableDamping_s(omega, dt), (4.0 / std::pow(omega / kDampedStepMargin, 2) - dt * dt) / (2 * dt),
              1e-15);
  EXPECT_NEAR(dampedStableStep_s(omega, largestStableDamping_s(omega, dt)), dt, 1e-12 * dt);
  EXPECT_NEAR(dampedStableStep_s(omega, 0.0), 2.0 * kDampedStepMargin / omega, 1e-15);
}

TEST(DampedStep, BackwardEulerDampsTheStiffestModeAtAnySubstep) {
  // Backward Euler maps the mode (x, v) by the inverse of [[1, -dt], [omega^2 dt, 1]], whose
  // eigenvalues have modulus 1 / sqrt(1 + omega^2 dt^2): undamped, the mode decays at any
  // substep, where symplectic Euler's grows beyond 2 / omega.
  const mesh::TriMesh sheet = irregularSheet(5, 7);
  const double omega = testing::makeModel(sheet, dampedKnit(0.0))->membraneFrequency_rad_s();
  for (const double omegaDt : {4.0, 10.0}) {
    const double dt = omegaDt / omega;
    const int steps = omegaDt < 5 ? 6 : 3;
    const double decay = std::pow(1.0 + omegaDt * omegaDt, -0.5 * steps);
    const double growth = growthOfTheStiffestMode(sheet, 0.0, dt, steps, IntegratorKind::BackwardEuler);
    EXPECT_LT(growth, 2.0 * decay) << "omega dt " << omegaDt;
    EXPECT_GT(growth, 0.1 * decay) << "omega dt " << omegaDt;  // the step's own decay, not a frozen mode
    EXPECT_GT(growthOfTheStiffestMode(sheet, 0.0, dt, 40), 1e3) << "symplectic Euler, omega dt " << omegaDt;
  }
}

TEST(DampedStep, TheSolverRefusesDampingItsSubstepCannotCarryAndSaysWhatWould) {
  const mesh::TriMesh sheet = irregularSheet(5, 3);
  const double omega = testing::makeModel(sheet, dampedKnit())->membraneFrequency_rad_s();
  StepSettings settings;
  settings.frameRate_hz = 30;
  settings.substepsPerFrame = static_cast<int>(std::ceil(omega / (30.0 * 0.5)));  // dt <= 0.5 / omega
  const double dt = settings.substep_s();
  const double most = largestStableDamping_s(omega, dt);
  EXPECT_NO_THROW(ClothSolver(testing::makeModel(sheet, dampedKnit(0.99 * most)), settings));
  try {
    ClothSolver solver(testing::makeModel(sheet, dampedKnit(1.5 * most)), settings);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("internal damping"), std::string::npos) << what;
    EXPECT_NE(what.find(fmt::format("set damping to {:.3g} s or less", most)), std::string::npos) << what;
    const long needed = static_cast<long>(std::ceil(1.0 / (30.0 * dampedStableStep_s(omega, 1.5 * most))));
    EXPECT_NE(what.find(fmt::format("use {} substeps per frame or more", needed)), std::string::npos) << what;
  }
  // Pinned vertices do not vibrate: pinning the stiffest corner lowers the frequency and lets
  // more damping through.
  const auto model = testing::makeModel(sheet, dampedKnit());
  std::vector<std::uint8_t> pinned(model->vertexCount(), 0);
  for (std::uint32_t v = 0; v < model->vertexCount(); v += 2) pinned[v] = 1;
  EXPECT_LT(model->membraneFrequency_rad_s(pinned), omega);
}

// Forward Euler's window, (dt, dt / 2 + 2 / (omega^2 dt)): just inside either end the
// stiffest mode dies away, just outside it grows (below the step every mode grows, undamped
// too). The solver refuses what lies outside, naming the window or the substeps that open one.
TEST(DampedStep, ForwardEulerHoldsOnlyInsideItsDampingWindow) {
  const mesh::TriMesh sheet = irregularSheet(5, 7);
  const auto model = testing::makeModel(sheet, dampedKnit());
  const double omega = model->membraneFrequency_rad_s();
  const double dt = 0.5 / omega;
  const double upper = 0.5 * dt + 2.0 / (omega * omega * dt);  // neutral, without margin
  constexpr IntegratorKind kForward = IntegratorKind::ForwardEuler;
  EXPECT_LT(growthOfTheStiffestMode(sheet, 1.1 * dt, dt, 400, kForward), 1.0);
  EXPECT_LT(growthOfTheStiffestMode(sheet, 0.95 * upper, dt, 400, kForward), 1.0);
  EXPECT_GT(growthOfTheStiffestMode(sheet, 0.0, dt, 400, kForward), 1e3);
  EXPECT_GT(growthOfTheStiffestMode(sheet, 0.5 * dt, dt, 400, kForward), 1e3);
  EXPECT_GT(growthOfTheStiffestMode(sheet, 1.05 * upper, dt, 400, kForward), 1e3);
  const ForwardEulerDampingWindow window = forwardEulerDampingWindow(omega, dt);
  EXPECT_DOUBLE_EQ(window.least_s, dt);
  EXPECT_NEAR(window.most_s, 0.5 * dt + 2.0 / (std::pow(omega / kDampedStepMargin, 2) * dt), 1e-15);
  EXPECT_TRUE(forwardEulerDampingWindow(omega, 1.01 * 2.0 * kDampedStepMargin / omega).empty());

  StepSettings settings;
  settings.integrator = kForward;
  settings.frameRate_hz = 30;
  settings.substepsPerFrame = static_cast<int>(std::ceil(omega / (30.0 * 0.5)));
  const ForwardEulerDampingWindow at = forwardEulerDampingWindow(omega, settings.substep_s());
  EXPECT_NO_THROW(ClothSolver(testing::makeModel(sheet, dampedKnit(0.5 * (at.least_s + at.most_s))), settings));
  for (const double damping : {0.0, 0.9 * at.least_s, 1.1 * at.most_s}) {
    try {
      ClothSolver solver(testing::makeModel(sheet, dampedKnit(damping)), settings);
      FAIL() << "expected an error at " << damping;
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("forward Euler is unstable"), std::string::npos) << what;
      EXPECT_NE(what.find(fmt::format("set damping above {:.3g} ms and at most {:.3g} ms", 1e3 * at.least_s,
                                      1e3 * at.most_s)),
                std::string::npos)
          << what;
    }
  }
  // A substep past 2 kDampedStepMargin / omega: no damping works, more substeps would.
  settings.substepsPerFrame = static_cast<int>(std::floor(omega / (30.0 * 2.0)));
  const long needed = static_cast<long>(std::floor(omega / (2.0 * kDampedStepMargin * 30.0)));
  try {
    ClothSolver solver(testing::makeModel(sheet, dampedKnit(settings.substep_s())), settings);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(fmt::format("use more than {} substeps per frame", needed)), std::string::npos)
        << e.what();
  }
  settings.substepsPerFrame = static_cast<int>(needed) + 1;
  const ForwardEulerDampingWindow opened = forwardEulerDampingWindow(omega, settings.substep_s());
  ASSERT_FALSE(opened.empty());
  EXPECT_NO_THROW(ClothSolver(testing::makeModel(sheet, dampedKnit(0.5 * (opened.least_s + opened.most_s))), settings));
}

TEST(DampedStep, TheFewestStableSubstepsCountTheDamping) {
  const mesh::TriMesh sheet = irregularSheet(5, 11);
  const mesh::Topology topology = mesh::Topology::build(sheet);
  const double rate = 30.0;
  const int undamped = fewestStableSubsteps(sheet, topology, dampedKnit(), rate, 0.0).substepsPerFrame;
  const auto model = testing::makeModel(sheet, dampedKnit());
  const double omega = model->membraneFrequency_rad_s();
  // Damping three times what the undamped count's substep allows.
  const double beta = 3.0 * std::max(largestStableDamping_s(omega, 1.0 / (rate * undamped)), 1e-6);
  const int damped = fewestStableSubsteps(sheet, topology, dampedKnit(beta), rate, 0.0).substepsPerFrame;
  EXPECT_GT(damped, undamped);
  EXPECT_LE(1.0 / (rate * damped), dampedStableStep_s(omega, beta));
  EXPECT_GT(1.0 / (rate * (damped - 1)), dampedStableStep_s(omega, beta));
  // With mass scaling allowed the ladder still ends on a count the damping allows.
  const SubstepChoice scaled = fewestStableSubsteps(sheet, topology, dampedKnit(beta), rate, 0.5);
  const auto scaledModel = ClothModel::build(sheet, topology, dampedKnit(beta),
                                             {1.0 / (rate * scaled.substepsPerFrame), 0.5});
  EXPECT_LE(1.0 / (rate * scaled.substepsPerFrame),
            dampedStableStep_s(scaledModel->membraneFrequency_rad_s(), beta) * (1 + 1e-12));
}

}  // namespace
}  // namespace drape::cloth
