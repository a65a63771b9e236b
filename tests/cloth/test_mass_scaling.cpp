// Mass scaling: sliver triangles get the mass that makes them stable at the target substep,
// element by element, and nothing else changes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "cloth_fixture.hpp"
#include "drape/core/error.hpp"

namespace drape::cloth {
namespace {

using testing::knit;
using testing::row;
using testing::run;

/// A 0.5 m sheet of 10 x 10 cells whose vertex (4, 5) is moved 47 % of a cell (or `shift`)
/// towards (5, 5): the triangles around it become slivers, as in garments modelled for
/// drawing. At 47 % the membrane's stiffest mode is 8 % faster than the regular sheet's; at
/// 95 % (a needle), 3.3 times.
struct SliverSheet {
  SheetSpec spec{0.5, 0.5, 10, 10, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), "sliver"};
  mesh::TriMesh mesh;
  explicit SliverSheet(double shift = 0.47) {
    mesh = gridSheet(spec);
    mesh.positions[sheetVertex(spec, 4, 5)].x() += shift * 0.05;
  }
};

/// The membrane step of one triangle as the model defines it: 0.5 altitude / wave speed.
double triangleStep(const mesh::TriMesh& m, std::size_t t, double waveSpeed) {
  const auto& [a, b, c] = m.triangles[t];
  const Vec3 e1 = m.positions[b] - m.positions[a], e2 = m.positions[c] - m.positions[a];
  const double longest = std::max({e1.norm(), e2.norm(), (e2 - e1).norm()});
  return 0.5 * e1.cross(e2).norm() / longest / waveSpeed;
}

TEST(MassScaling, ReachesTheTargetStepAddingOnlyWhatTheSliversNeed) {
  const SliverSheet s;
  const auto plain = testing::makeModel(s.mesh, knit());
  const double target = 1.8 * plain->estimatedStableStep_s();
  const auto scaled = ClothModel::build(s.mesh, mesh::Topology::build(s.mesh), knit(), MassScaling{target, 1.0});
  EXPECT_GE(scaled->estimatedStableStep_s(), target * (1 - 1e-9));
  EXPECT_LT(plain->estimatedStableStep_s(), target);

  // Brute force over the triangles: the membrane part of the added mass.
  const double c = plain->membraneWaveSpeed_m_s();
  std::vector<double> expected = plain->mass();
  for (std::size_t t = 0; t < s.mesh.triangleCount(); ++t) {
    const double dt = triangleStep(s.mesh, t, c);
    if (dt >= target) continue;
    const double added = knit().arealDensity() * s.mesh.triangleArea(t) / 3.0 * ((target / dt) * (target / dt) - 1);
    for (std::uint32_t v : s.mesh.triangles[t]) expected[v] += added;
  }
  std::size_t changed = 0;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_GE(scaled->mass()[i], expected[i] * (1 - 1e-12)) << "vertex " << i;
    if (expected[i] == plain->mass()[i] && scaled->mass()[i] == plain->mass()[i]) continue;
    ++changed;
  }
  EXPECT_GT(changed, 0u);
  EXPECT_LT(changed, 20u) << "only the slivers' corners gain mass";
  EXPECT_EQ(changed, scaled->massScaledVertexCount());
  EXPECT_NEAR(scaled->totalMass_kg(), plain->totalMass_kg() + scaled->addedMass_kg(), 1e-15);
  EXPECT_LT(scaled->addedMass_kg(), 0.05 * plain->totalMass_kg());
}

TEST(MassScaling, TooMuchAddedMassIsAnErrorThatNamesTheSubsteps) {
  const SliverSheet s;
  const auto plain = testing::makeModel(s.mesh, knit());
  const double target = 3.0 * plain->estimatedStableStep_s();
  try {
    (void)ClothModel::build(s.mesh, mesh::Topology::build(s.mesh), knit(), MassScaling{target, 1e-4, 30.0});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("sliver: keeping the substep"), std::string::npos) << what;
    EXPECT_NE(what.find("substeps per frame"), std::string::npos) << what;
  }
}

TEST(MassScaling, AScaledSheetHangsStablyAtTheTargetStep) {
  // At the step of the same sheet without its sliver, at least twice the sliver sheet's own
  // estimate: scaled, it hangs from its top row for 1 s without the stability guard firing.
  const SliverSheet s;
  const auto plain = testing::makeModel(s.mesh, knit());
  const auto regular = testing::makeModel(gridSheet(s.spec), knit());
  StepSettings settings = testing::settingsWithStep(0.9 * regular->estimatedStableStep_s());
  ASSERT_GT(settings.substep_s(), 1.5 * plain->estimatedStableStep_s());
  settings.maxAddedMass = 0.05;
  const auto scaled = ClothModel::build(s.mesh, mesh::Topology::build(s.mesh), knit(), settings.massScaling());
  ClothSolver solver(scaled, settings,
                     {PinGroup::atRest(row(s.spec, s.spec.cellsV), scaled->restX(), scaled->restY(), scaled->restZ())});
  ASSERT_TRUE(run(solver, 30L * settings.substepsPerFrame)) << solver.instability().describe("sliver", 30);
  double speed = 0;
  for (std::size_t i = 0; i < solver.state().size(); ++i) speed = std::max(speed, solver.state().velocity(i).norm());
  EXPECT_LT(speed, 1.0);
}

TEST(MassScaling, WithDampingTheStiffestModeKeepsTheDampedBound) {
  // A substep 1.5 times the sheet's own and damping three times what masses scaled for that
  // substep alone would carry: the scaled model's stiffest mode must still keep the damped
  // bound, the solver must take it, and the sheet must hang stably for 1 s.
  const SliverSheet s;
  const mesh::Topology topology = mesh::Topology::build(s.mesh);
  const double step = 1.5 * testing::makeModel(s.mesh, knit())->estimatedStableStep_s();
  const double unbounded = std::numeric_limits<double>::infinity();
  const auto forStepAlone = ClothModel::build(s.mesh, topology, knit(), MassScaling{step, unbounded});
  const double omegaAlone = forStepAlone->membraneFrequency_rad_s();
  Material damped = knit();
  damped.damping_s = 3.0 * largestStableDamping_s(omegaAlone, step);
  ASSERT_GT(damped.damping_s, 0.0);
  ASSERT_LT(dampedStableStep_s(omegaAlone, damped.damping_s), step);

  const auto scaled = ClothModel::build(s.mesh, topology, damped, MassScaling{step, unbounded});
  EXPECT_GE(dampedStableStep_s(scaled->membraneFrequency_rad_s(), damped.damping_s), step);
  // The frequency the scaling measured and keeps is the one a fresh iteration finds.
  const std::vector<std::uint8_t> noneHeld(scaled->vertexCount(), 0);
  EXPECT_DOUBLE_EQ(scaled->membraneFrequency_rad_s(), scaled->membraneFrequency_rad_s(noneHeld));
  EXPECT_GT(scaled->addedMass_kg(), forStepAlone->addedMass_kg());
  // Scaled for the measured mode, not every triangle for the undamped step of the same bound
  // (the per-triangle estimate is conservative and would add several times the mass).
  Material undamped = knit();
  const auto everyTriangle = ClothModel::build(
      s.mesh, topology, undamped, MassScaling{undampedEquivalentStep_s(step, damped.damping_s), unbounded});
  EXPECT_LT(scaled->addedMass_kg(), everyTriangle->addedMass_kg());

  StepSettings settings = testing::settingsWithStep(step);
  settings.maxAddedMass = 1.0;
  ClothSolver solver(scaled, settings,
                     {PinGroup::atRest(row(s.spec, s.spec.cellsV), scaled->restX(), scaled->restY(), scaled->restZ())});
  ASSERT_TRUE(run(solver, 30L * settings.substepsPerFrame)) << solver.instability().describe("sliver", 30);

  // The substep search, at the damping the scaled-for-the-step-alone masses just carry: the
  // sliver no longer sets the count (49 unscaled; 29 here, against 49 when the scaling
  // ignored the damping).
  Material justCarried = knit();
  justCarried.damping_s = largestStableDamping_s(omegaAlone, step);
  const double rate = 30.0;
  const int unscaled = fewestStableSubsteps(s.mesh, topology, justCarried, rate, 0.0).substepsPerFrame;
  const SubstepChoice withScaling = fewestStableSubsteps(s.mesh, topology, justCarried, rate, 0.2);
  EXPECT_LT(withScaling.substepsPerFrame, 0.7 * unscaled);
  // And it is the fewest, at that damping and at a tenth of it (where the damping adds little
  // mass, so the search's first rungs, passed over on undamped models, decide): one substep
  // fewer needs more mass than allowed or breaks the damped bound.
  for (const double share : {1.0, 0.1}) {
    Material m = justCarried;
    m.damping_s *= share;
    for (const double allowance : {0.01, 0.2}) {
      const int fewest = fewestStableSubsteps(s.mesh, topology, m, rate, allowance).substepsPerFrame;
      const double fewer = 1.0 / (rate * (fewest - 1));
      const auto below = ClothModel::build(s.mesh, topology, m, MassScaling{fewer, unbounded});
      const std::vector<std::uint8_t> free(below->vertexCount(), 0);
      EXPECT_TRUE(below->addedMassFraction() > allowance ||
                  dampedStableStep_s(below->membraneFrequency_rad_s(free), m.damping_s) < fewer)
          << "damping share " << share << ", allowance " << allowance << ": " << fewest - 1 << " would do";
    }
  }
  StepSettings chosen = testing::settingsWithStep(1.0 / (rate * withScaling.substepsPerFrame));
  chosen.maxAddedMass = 0.2;
  EXPECT_NO_THROW(ClothSolver(ClothModel::build(s.mesh, topology, justCarried, chosen.massScaling()), chosen));
}

TEST(MassScaling, ForTheRungeKuttaStepOnlyTheSliversGainMass) {
  // A needle that makes the membrane's stiffest mode 3.3 times the regular sheet's, and a
  // substep 0.9 sqrt(2) times the regular sheet's element estimate (symplectic Euler's): the
  // Runge-Kutta step's scaling, for sqrt(2) times shorter a step, leaves the regular triangles
  // alone, and the stiffest mode keeps the step's bound with mass on the needle's corners
  // only, under half what scaling for symplectic Euler at the same step adds.
  // The sheet hangs stably for 1 s under the Runge-Kutta step, where the unscaled sheet is
  // refused. Undamped, and damped so that the needle's mode is overdamped (zeta 1.5), and so
  // overdamped (zeta 3) that the element scaling alone leaves the mode past the bound: there
  // the measured mode is held to it.
  const SliverSheet s(0.95);
  const mesh::Topology topology = mesh::Topology::build(s.mesh);
  const double omega0 = testing::makeModel(s.mesh, knit())->membraneFrequency_rad_s();
  const auto regular = testing::makeModel(gridSheet(s.spec), knit());
  ASSERT_GT(omega0, 2.0 * regular->membraneFrequency_rad_s());
  const double unbounded = std::numeric_limits<double>::infinity();
  for (const double zeta : {0.0, 1.5, 3.0}) {
    SCOPED_TRACE(::testing::Message() << "zeta " << zeta);
    Material material = knit();
    material.damping_s = 2.0 * zeta / omega0;
    StepSettings settings = testing::settingsWithStep(0.9 * std::sqrt(2.0) * regular->estimatedStableStep_s());
    settings.useIntegrator(IntegratorKind::RungeKutta4);
    settings.maxAddedMass = 1.0;
    const double step = settings.substep_s();
    ASSERT_LT(rungeKuttaStableStep_s(omega0, material.damping_s), step);

    const auto scaled = ClothModel::build(s.mesh, topology, material, settings.massScaling());
    EXPECT_GE(rungeKuttaStableStep_s(scaled->membraneFrequency_rad_s(), material.damping_s), step);
    EXPECT_GT(scaled->addedMassFraction(), 0.0);
    EXPECT_LT(scaled->addedMassFraction(), 0.2);
    EXPECT_LT(scaled->massScaledVertexCount(), 20u) << "only the slivers' corners gain mass";
    const auto forSymplectic = ClothModel::build(s.mesh, topology, material, MassScaling{step, unbounded});
    EXPECT_LT(scaled->addedMass_kg(), 0.5 * forSymplectic->addedMass_kg());

    const auto top = [&](const ClothModel& m) {
      return std::vector<PinGroup>{PinGroup::atRest(row(s.spec, s.spec.cellsV), m.restX(), m.restY(), m.restZ())};
    };
    ClothSolver solver(scaled, settings, top(*scaled));
    ASSERT_TRUE(run(solver, 30L * settings.substepsPerFrame)) << solver.instability().describe("sliver", 30);
    double speed = 0;
    for (std::size_t i = 0; i < solver.state().size(); ++i) speed = std::max(speed, solver.state().velocity(i).norm());
    EXPECT_LT(speed, 1.0);
    const auto plain = ClothModel::build(s.mesh, topology, material);
    const std::string refused = testing::refusal([&] { ClothSolver unscaled(plain, settings, top(*plain)); });
    EXPECT_NE(refused.find("the runge-kutta-4 step is unstable"), std::string::npos) << refused;
  }
}

TEST(MassScaling, FewestRungeKuttaSubstepsWithinTheAllowance) {
  // The substep search for the Runge-Kutta step on the same needle: fewer substeps than
  // without mass scaling and than symplectic Euler's search within the same allowance; the
  // solver takes the count, and one fewer needs more mass than allowed or breaks the step's
  // bound on the stiffest mode (every vertex free).
  const SliverSheet s(0.95);
  const mesh::Topology topology = mesh::Topology::build(s.mesh);
  const double rate = 30.0;
  const double omega0 = testing::makeModel(s.mesh, knit())->membraneFrequency_rad_s();
  const double unbounded = std::numeric_limits<double>::infinity();
  for (const double zeta : {0.0, 0.5, 1.5}) {
    Material material = knit();
    material.damping_s = 2.0 * zeta / omega0;
    const int unscaled =
        fewestStableSubsteps(s.mesh, topology, material, rate, 0.0, 1, IntegratorKind::RungeKutta4).substepsPerFrame;
    EXPECT_EQ(unscaled, static_cast<int>(std::ceil(1.0 / (rate * rungeKuttaStableStep_s(omega0, material.damping_s)))));
    for (const double allowance : {0.2, 0.5}) {
      SCOPED_TRACE(::testing::Message() << "zeta " << zeta << ", allowance " << allowance);
      const SubstepChoice c =
          fewestStableSubsteps(s.mesh, topology, material, rate, allowance, 1, IntegratorKind::RungeKutta4);
      const SubstepChoice symplectic = fewestStableSubsteps(s.mesh, topology, material, rate, allowance);
      EXPECT_LT(c.substepsPerFrame, unscaled);
      EXPECT_LT(c.substepsPerFrame, symplectic.substepsPerFrame);
      EXPECT_GT(c.addedMassFraction, 0.0);
      EXPECT_LE(c.addedMassFraction, allowance);
      EXPECT_DOUBLE_EQ(c.addedMassFraction, addedMassFractionAt(s.mesh, topology, material, rate, c.substepsPerFrame,
                                                                IntegratorKind::RungeKutta4));
      StepSettings chosen = testing::settingsWithStep(1.0 / (rate * c.substepsPerFrame));
      chosen.useIntegrator(IntegratorKind::RungeKutta4);
      chosen.maxAddedMass = allowance;
      EXPECT_NO_THROW(ClothSolver(ClothModel::build(s.mesh, topology, material, chosen.massScaling()), chosen));
      const double fewer = 1.0 / (rate * (c.substepsPerFrame - 1));
      const auto below =
          ClothModel::build(s.mesh, topology, material, MassScaling{fewer, unbounded, 0.0, IntegratorKind::RungeKutta4});
      EXPECT_TRUE(below->addedMassFraction() > allowance ||
                  rungeKuttaStableStep_s(below->membraneFrequency_rad_s(), material.damping_s) < fewer)
          << c.substepsPerFrame - 1 << " would do";
    }
  }
}

/// Fraction of the mass that scaling adds at `substeps` per frame of `rate`.
double addedFraction(const mesh::TriMesh& m, const Material& material, double rate, int substeps) {
  const auto model = ClothModel::build(m, mesh::Topology::build(m), material,
                                       MassScaling{1.0 / (rate * substeps), std::numeric_limits<double>::infinity()});
  return model->addedMass_kg() / (model->totalMass_kg() - model->addedMass_kg());
}

TEST(MassScaling, FewestStableSubstepsWithinTheAllowance) {
  const SliverSheet s;
  const mesh::Topology topology = mesh::Topology::build(s.mesh);
  const double rate = 30.0;
  const int unscaled =
      static_cast<int>(std::ceil(1.0 / (rate * testing::makeModel(s.mesh, knit())->estimatedStableStep_s())));
  ASSERT_GT(unscaled, 4);

  // No allowance: the unscaled estimate, as before mass scaling existed.
  const SubstepChoice none = fewestStableSubsteps(s.mesh, topology, knit(), rate, 0.0);
  EXPECT_EQ(none.substepsPerFrame, unscaled);
  EXPECT_EQ(none.addedMassFraction, 0.0);
  EXPECT_EQ(fewestStableSubsteps(s.mesh, topology, knit(), rate, 0.0, unscaled + 7).substepsPerFrame, unscaled + 7);

  // With an allowance: fewer substeps, within it, and one substep fewer needs more than the
  // allowance (the ladder's rung narrowed by bisection).
  for (const double allowance : {0.001, 0.01, 0.05}) {
    const SubstepChoice c = fewestStableSubsteps(s.mesh, topology, knit(), rate, allowance);
    EXPECT_LT(c.substepsPerFrame, unscaled) << allowance;
    EXPECT_LE(c.addedMassFraction, allowance);
    EXPECT_DOUBLE_EQ(c.addedMassFraction, addedFraction(s.mesh, knit(), rate, c.substepsPerFrame));
    if (c.substepsPerFrame > 1) {
      EXPECT_GT(addedFraction(s.mesh, knit(), rate, c.substepsPerFrame - 1), allowance) << allowance;
    }
    // The model builds at that count within the allowance (no refusal).
    EXPECT_NO_THROW((void)ClothModel::build(s.mesh, topology, knit(),
                                            MassScaling{1.0 / (rate * c.substepsPerFrame), allowance}));
  }
}

}  // namespace
}  // namespace drape::cloth
