// Physics against analytic answers.
#include <gtest/gtest.h>

#include <random>

#include "cloth_fixture.hpp"
#include "drape/core/error.hpp"

namespace drape::cloth {
namespace {

using testing::column;
using testing::fabric;
using testing::makeModel;
using testing::pinAt;
using testing::row;
using testing::run;
using testing::settingsWithStep;

// ---------------------------------------------------------------------------------------
TEST(FreeFall, CentreOfMassFallsAtGAndInternalForcesSumToZero) {
  SheetSpec spec;
  spec.cellsU = spec.cellsV = 8;
  auto model = makeModel(irregularSheet(spec), fabric(1e5, 1e-3, 300));
  StepSettings settings = settingsWithStep(1e-4);
  ClothSolver solver(model, settings);
  // Deform the sheet randomly so membrane and bending forces are far from zero.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> d(-0.01, 0.01);
  ClothState& s = solver.mutableState();
  for (std::size_t i = 0; i < s.size(); ++i) {
    s.x[i] += d(rng);
    s.y[i] += d(rng);
    s.z[i] += 3 * d(rng);
    s.vx[i] = d(rng);
  }
  clearForces(s);
  accumulateMembraneForces(*model, s);
  accumulateBendingForces(*model, s);
  Vec3 sum = Vec3::Zero();
  double magnitude = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    sum += Vec3(s.fx[i], s.fy[i], s.fz[i]);
    magnitude += Vec3(s.fx[i], s.fy[i], s.fz[i]).norm();
  }
  ASSERT_GT(magnitude, 1.0);
  EXPECT_LT(sum.norm(), 1e-12 * magnitude);

  auto comVelocity = [&] {
    Vec3 p = Vec3::Zero();
    for (std::size_t i = 0; i < s.size(); ++i) p += model->mass()[i] * s.velocity(i);
    return Vec3(p / model->totalMass_kg());
  };
  const Vec3 v0 = comVelocity();
  const long steps = 500;
  ASSERT_TRUE(run(solver, steps));
  const Vec3 accel = (comVelocity() - v0) / (steps * settings.substep_s());
  EXPECT_LT((accel - settings.gravity_m_s2).norm(), 1e-6 * settings.gravity_m_s2.norm()) << accel.transpose();
}

// ---------------------------------------------------------------------------------------
TEST(Membrane, ForcesAreMinusTheEnergyGradient) {
  SheetSpec spec;
  spec.cellsU = spec.cellsV = 3;
  auto model = makeModel(irregularSheet(spec, 0.3, 5), fabric(1e5, 1e-3, 300));
  ClothState s = ClothState::atRest(*model);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> d(-0.05, 0.05);
  for (std::size_t i = 0; i < s.size(); ++i) {
    s.x[i] += d(rng);
    s.y[i] += d(rng);
    s.z[i] += d(rng);
  }
  clearForces(s);
  accumulateMembraneForces(*model, s);
  accumulateBendingForces(*model, s);
  auto energy = [&](const ClothState& st) { return membraneEnergy(*model, st) + bendingEnergy(*model, st); };
  const double h = 1e-7;
  for (std::size_t i = 0; i < s.size(); ++i) {
    for (std::vector<double>* axis : {&s.x, &s.y, &s.z}) {
      ClothState p = s, m = s;
      (*(axis == &s.x ? &p.x : axis == &s.y ? &p.y : &p.z))[i] += h;
      (*(axis == &s.x ? &m.x : axis == &s.y ? &m.y : &m.z))[i] -= h;
      const double numeric = -(energy(p) - energy(m)) / (2 * h);
      const double analytic = (axis == &s.x ? s.fx : axis == &s.y ? s.fy : s.fz)[i];
      EXPECT_NEAR(analytic, numeric, 1e-5 * (1.0 + std::abs(numeric))) << "vertex " << i;
    }
  }
}

// ---------------------------------------------------------------------------------------
// A strip hanging from its top edge stretches by rho g L^2 / (2 E) (each cross-section
// carries the weight below it; rho is the bulk density, kg/m^3).
TEST(Membrane, HangingStripElongation) {
  const double L = 1.0, W = 0.1, E = 1e6, rho = 1000, t = 1e-3;
  SheetSpec spec{W, L, 4, 40, Vec3(0, -L, 0), Vec3::UnitX(), Vec3::UnitY(), "strip"};
  Material mat = fabric(E, t, rho);
  mat.damping_s = 2e-5;
  auto model = makeModel(gridSheet(spec), mat);
  StepSettings settings = settingsWithStep(0.5 * model->estimatedStableStep_s(), 10.0);
  ClothSolver solver(model, settings, {pinAt(*model, row(spec, spec.cellsV))});
  ASSERT_TRUE(run(solver, static_cast<long>(1.5 / settings.substep_s())));
  const double drop = testing::meanDrop(*model, solver.state(), row(spec, 0));
  const double expected = rho * 9.81 * L * L / (2 * E);
  EXPECT_NEAR(drop, expected, 0.05 * expected);
}

// ---------------------------------------------------------------------------------------
// A long strip stretched by strain e along x narrows by about nu e in its middle.
TEST(Membrane, PoissonContraction) {
  const double L = 1.0, W = 0.1, e = 0.01, nu = 0.3;
  SheetSpec spec{L, W, 40, 4, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), "strip"};
  Material mat = fabric(1e5, 1e-3, 300, nu);
  mat.damping_s = 2e-5;
  auto model = makeModel(gridSheet(spec), mat);
  StepSettings settings = settingsWithStep(0.5 * model->estimatedStableStep_s(), 1.0, Vec3::Zero());
  // Both ends pinned, the right one moved by e L; the state starts uniformly stretched.
  PinGroup left = pinAt(*model, column(spec, 0));
  PinGroup right = pinAt(*model, column(spec, spec.cellsU));
  for (double& x : right.localX) x *= 1 + e;
  ClothSolver solver(model, settings, {left, right});
  for (double& x : solver.mutableState().x) x *= 1 + e;
  ASSERT_TRUE(run(solver, static_cast<long>(0.5 / settings.substep_s())));
  const int mid = spec.cellsU / 2;
  const double width = solver.state().y[sheetVertex(spec, mid, spec.cellsV)] - solver.state().y[sheetVertex(spec, mid, 0)];
  const double contraction = (W - width) / W;
  EXPECT_NEAR(contraction, nu * e, 0.1 * nu * e);
}

// ---------------------------------------------------------------------------------------
// A horizontal cantilever plate (clamped by two rows of pins) bends under its own weight to
// q L^4 / (8 D) at the tip (Euler-Bernoulli per unit width, q = rho t g, plate modulus D).
// The plate is wide (W = 3 L) so that, as in cylindrical plate bending, anticlastic
// curvature is confined to the free edges; the tip is read on the centre line (ten elements
// along the beam: the hinge model is +14 % soft there, see docs/PHYSICS.md). A thick,
// soft plate keeps the deflection small (4 % of L, the linear theory's range).
TEST(Bending, CantileverTipDeflection) {
  const double L = 0.2, W = 0.6, E = 1e5, t = 0.03, rho = 1.0 / 0.03, h = 0.02;
  const int cellsL = static_cast<int>(std::lround(L / h)) + 1;  // one extra cell behind the clamp line
  const int cellsW = static_cast<int>(std::lround(W / h));
  SheetSpec spec{L + h, W, cellsL, cellsW, Vec3(-h, 0, 0), Vec3::UnitX(), Vec3::UnitZ(), "cantilever"};
  Material mat = fabric(E, t, rho);
  auto model = makeModel(gridSheet(spec), mat);
  StepSettings settings = settingsWithStep(0.5 * model->estimatedStableStep_s(), 80.0);
  std::vector<std::uint32_t> clamp = column(spec, 0);
  for (std::uint32_t v : column(spec, 1)) clamp.push_back(v);
  ClothSolver solver(model, settings, {pinAt(*model, clamp)});
  ASSERT_TRUE(run(solver, static_cast<long>(1.0 / settings.substep_s())));
  const double tip = -solver.state().y[sheetVertex(spec, cellsL, cellsW / 2)];
  const double D = mat.bendingModulus();
  // Two pinned rows h apart clamp the hinge line between them: the discrete beam is
  // clamped at their midpoint, so its length is L + h / 2.
  const double expected = rho * t * 9.81 * std::pow(L + 0.5 * h, 4) / (8 * D);
  EXPECT_NEAR(tip, expected, 0.2 * expected);
}

// ---------------------------------------------------------------------------------------
// A sheet held along two opposite edges sags under its weight; a regular grid and an
// irregular triangulation of it must agree within 5 %.
double sagOf(const mesh::TriMesh& m, const SheetSpec& spec) {
  Material mat = fabric(1e5, 5e-3, 200);
  mat.damping_s = 1e-5;
  auto model = makeModel(m, mat);
  StepSettings settings = settingsWithStep(0.5 * model->estimatedStableStep_s(), 4.0);
  std::vector<std::uint32_t> held = column(spec, 0);
  for (std::uint32_t v : column(spec, spec.cellsU)) held.push_back(v);
  ClothSolver solver(model, settings, {pinAt(*model, held)});
  EXPECT_TRUE(run(solver, static_cast<long>(2.0 / settings.substep_s())));
  // Mean drop of the vertices within 5 cm of the centre line x = 0.25.
  double sum = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < model->vertexCount(); ++i)
    if (std::abs(model->restX()[i] - 0.25) < 0.05) {
      sum -= solver.state().y[i];
      ++n;
    }
  return sum / n;
}

TEST(Membrane, MeshIndependentSag) {
  SheetSpec spec{0.5, 0.5, 12, 12, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), "sheet"};
  const double regular = sagOf(gridSheet(spec), spec);
  SheetSpec fine = spec;
  fine.cellsU = fine.cellsV = 15;
  const double irregular = sagOf(irregularSheet(fine, 0.3, 21), fine);
  ASSERT_GT(regular, 0.005);
  EXPECT_NEAR(irregular, regular, 0.05 * regular);
}

// ---------------------------------------------------------------------------------------
// Linear drag c (N s/m^3) on a flat sheet of mass per area rho t: v_terminal = rho t g / c.
TEST(Drag, TerminalVelocity) {
  SheetSpec spec{0.5, 0.5, 6, 6, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), "sheet"};
  Material mat = fabric(1e5, 1e-3, 300);
  auto model = makeModel(irregularSheet(spec), mat);
  const double c = 0.6;
  StepSettings settings = settingsWithStep(1e-3, c);
  ClothSolver solver(model, settings);
  const double tau = mat.arealDensity() / c;
  ASSERT_TRUE(run(solver, static_cast<long>(10 * tau / settings.substep_s())));
  double vy = 0.0;
  for (double v : solver.state().vy) vy += v;
  vy /= solver.state().size();
  const double expected = -mat.arealDensity() * 9.81 / c;
  EXPECT_NEAR(vy, expected, 0.05 * std::abs(expected));
}

// ---------------------------------------------------------------------------------------
// Without damping or drag, symplectic Euler keeps the total energy of a swinging sheet
// within a small band over 10,000 steps; forward Euler (the paper's) drifts much further.
double energyDrift(IntegratorKind kind, double* maxKinetic) {
  SheetSpec spec{0.3, 0.3, 6, 6, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), "sheet"};
  auto model = makeModel(gridSheet(spec), fabric(2e4, 1e-3, 300));
  StepSettings settings = settingsWithStep(0.3 * model->estimatedStableStep_s(), 0.0);
  settings.integrator = kind;
  ClothSolver solver(model, settings, {pinAt(*model, {sheetVertex(spec, 0, 0), sheetVertex(spec, 6, 0)})});
  const double e0 = solver.totalEnergy();
  double drift = 0.0;
  *maxKinetic = 0.0;
  for (int k = 0; k < 100; ++k) {
    if (!run(solver, 100)) return std::numeric_limits<double>::infinity();
    drift = std::max(drift, std::abs(solver.totalEnergy() - e0));
    *maxKinetic = std::max(*maxKinetic, kineticEnergy(*model, solver.state()));
  }
  return drift;
}

TEST(Integrators, SymplecticEulerEnergyBounded) {
  double kinetic = 0.0;
  const double drift = energyDrift(IntegratorKind::SymplecticEuler, &kinetic);
  ASSERT_GT(kinetic, 1e-3);
  EXPECT_LT(drift, 0.02 * kinetic);
  // Undamped, forward Euler gains energy in every mode at any step (DampedStep.
  // ForwardEulerHoldsOnlyInsideItsDampingWindow measures it): the solver refuses it.
  EXPECT_THROW((void)energyDrift(IntegratorKind::ForwardEuler, &kinetic), Error);
}

// ---------------------------------------------------------------------------------------
TEST(Fixtures, PinnedVerticesFollowTheirTransform) {
  struct Slide final : FixtureMotion {
    RigidTransform poseAt(double t) const override {
      RigidTransform r;
      r.translation = Vec3(0.5 * t, 0, 0);
      r.rotation = Quat(Eigen::AngleAxisd(0.3 * t, Vec3::UnitY()));
      return r;
    }
  };
  SheetSpec spec{0.2, 0.2, 4, 4, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), "sheet"};
  auto model = makeModel(gridSheet(spec), fabric(1e4, 1e-3, 300));
  auto motion = std::make_shared<Slide>();
  StepSettings settings = settingsWithStep(2e-4, 0.5);
  ClothSolver solver(model, settings,
                     {PinGroup::atRest(row(spec, spec.cellsV), model->restX(), model->restY(), model->restZ(), motion)});
  const long steps = 300;
  ASSERT_TRUE(run(solver, steps));
  const RigidTransform pose = motion->poseAt(steps * settings.substep_s());
  for (std::uint32_t v : row(spec, spec.cellsV)) {
    const Vec3 expected = pose.apply(Vec3(model->restX()[v], model->restY()[v], model->restZ()[v]));
    EXPECT_LT((solver.state().position(v) - expected).norm(), 1e-12);
  }
  // The pose fetches are timed apart (animation, which the collision share leaves out) and
  // are part of the fixtures' stage.
  EXPECT_GT(solver.stageTimes().fixturePoses_s, 0.0);
  EXPECT_LE(solver.stageTimes().fixturePoses_s, solver.stageTimes().fixtures_s);
}

// ---------------------------------------------------------------------------------------
TEST(Fixtures, BlendedVerticesFollowTheWeightedSumOfTheirGroups) {
  // One row bound to two frames turning and sliding apart, with weights 0.3 and 0.7 (linear
  // blend skinning); a group without weights places one vertex of the row alone, over the
  // blend.
  struct Turn final : FixtureMotion {
    double sign;
    explicit Turn(double s) : sign(s) {}
    RigidTransform poseAt(double t) const override {
      RigidTransform r;
      r.translation = Vec3(0.2 * sign * t, 0.1 * t, 0);
      r.rotation = Quat(Eigen::AngleAxisd(0.5 * sign * t, Vec3::UnitZ()));
      return r;
    }
  };
  SheetSpec spec{0.2, 0.2, 4, 4, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), "sheet"};
  auto model = makeModel(gridSheet(spec), fabric(1e4, 1e-3, 300));
  const auto a = std::make_shared<Turn>(1.0), b = std::make_shared<Turn>(-1.0);
  const std::vector<std::uint32_t> top = row(spec, spec.cellsV);
  PinGroup ga = PinGroup::atRest(top, model->restX(), model->restY(), model->restZ(), a);
  PinGroup gb = PinGroup::atRest(top, model->restX(), model->restY(), model->restZ(), b);
  ga.weight.assign(top.size(), 0.3);
  gb.weight.assign(top.size(), 0.7);
  const std::uint32_t alone = top.front();
  PinGroup still = PinGroup::atRest({alone}, model->restX(), model->restY(), model->restZ());
  StepSettings settings = settingsWithStep(2e-4, 0.5);
  ClothSolver solver(model, settings, {ga, gb, still});
  const long steps = 300;
  ASSERT_TRUE(run(solver, steps));
  const double t1 = steps * settings.substep_s(), t0 = (steps - 1) * settings.substep_s();
  const auto blendAt = [&](double t, std::uint32_t v) {
    const Vec3 rest(model->restX()[v], model->restY()[v], model->restZ()[v]);
    return Vec3(0.3 * a->poseAt(t).apply(rest) + 0.7 * b->poseAt(t).apply(rest));
  };
  for (std::uint32_t v : top) {
    const Vec3 rest(model->restX()[v], model->restY()[v], model->restZ()[v]);
    const Vec3 expected = v == alone ? rest : blendAt(t1, v);
    const Vec3 velocity = v == alone ? Vec3::Zero() : Vec3((blendAt(t1, v) - blendAt(t0, v)) / settings.substep_s());
    EXPECT_LT((solver.state().position(v) - expected).norm(), 1e-12) << "vertex " << v;
    EXPECT_LT((solver.state().velocity(v) - velocity).norm(), 1e-9) << "vertex " << v;
  }
  // Where the two frames have moved apart, the blend is neither of them.
  const std::uint32_t v = top.back();
  const Vec3 rest(model->restX()[v], model->restY()[v], model->restZ()[v]);
  const Vec3 onA = a->poseAt(t1).apply(rest), onB = b->poseAt(t1).apply(rest);
  ASSERT_GT((onA - onB).norm(), 0.01);
  EXPECT_NEAR((solver.state().position(v) - onA).norm(), 0.7 * (onA - onB).norm(), 1e-12);
  EXPECT_NEAR((solver.state().position(v) - onB).norm(), 0.3 * (onA - onB).norm(), 1e-12);
}

TEST(Fixtures, BlendWeightsMustSumToOne) {
  SheetSpec spec{0.2, 0.2, 2, 2, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), "sheet"};
  auto model = makeModel(gridSheet(spec), fabric(1e4, 1e-3, 300));
  PinGroup g = PinGroup::atRest(row(spec, spec.cellsV), model->restX(), model->restY(), model->restZ());
  g.weight.assign(g.vertices.size(), 0.6);
  EXPECT_THROW(ClothSolver(model, settingsWithStep(2e-4, 0.5), {g}), Error);
  g.weight.pop_back();
  EXPECT_THROW(ClothSolver(model, settingsWithStep(2e-4, 0.5), {g}), Error);
}

// ---------------------------------------------------------------------------------------
TEST(Collision, SheetDrapesOnSphereWithoutPenetrating) {
  SheetSpec spec{1.0, 1.0, 12, 12, Vec3(-0.5, 0, -0.5), Vec3::UnitX(), Vec3::UnitZ(), "sheet"};
  Material mat = fabric(2e4, 1e-3, 300);
  mat.damping_s = 1e-5;
  auto model = makeModel(gridSheet(spec), mat);
  SphereCollider sphere(Vec3(0.05, -0.4, 0.0), 0.25);
  StepSettings settings = settingsWithStep(0.5 * model->estimatedStableStep_s(), 1.0);
  ClothSolver solver(model, settings);
  solver.addCollider(sphere);
  ASSERT_TRUE(run(solver, static_cast<long>(1.0 / settings.substep_s())));
  EXPECT_GT(sphere.counters().contacts, 0u);
  for (std::size_t i = 0; i < solver.state().size(); ++i)
    EXPECT_GE((solver.state().position(i) - Vec3(0.05, -0.4, 0)).norm(), 0.25 - 1e-9);
}

// ---------------------------------------------------------------------------------------
// The same input gives bit-identical states; the hash also changes when the input does.
std::uint64_t runHash(double perturb) {
  SheetSpec spec{1.0, 1.0, 10, 10, Vec3(-0.5, 0, -0.5), Vec3::UnitX(), Vec3::UnitZ(), "sheet"};
  Material mat = fabric(2e4, 1e-3, 300);
  mat.damping_s = 1e-5;
  mat.compressionScale = 0.2;
  auto model = makeModel(irregularSheet(spec), mat);
  SphereCollider sphere(Vec3(0.05, -0.4, 0.0), 0.25);
  StepSettings settings;
  settings.substepsPerFrame = 66;
  ClothSolver solver(model, settings, {pinAt(*model, {sheetVertex(spec, 0, 0), sheetVertex(spec, 10, 0)})});
  solver.addCollider(sphere);
  solver.mutableState().vy[5] += perturb;
  for (long f = 1; f <= 20; ++f) EXPECT_TRUE(solver.stepFrame(f));
  return solver.state().hash();
}

TEST(Determinism, SameInputSameHash) {
  const std::uint64_t a = runHash(0.0);
  EXPECT_EQ(a, runHash(0.0));
  EXPECT_NE(a, runHash(1e-9));
}

// ---------------------------------------------------------------------------------------
TEST(Stability, GuardReportsVertexAndFrame) {
  SheetSpec spec{1.0, 1.0, 10, 10, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), "sheet"};
  auto model = makeModel(gridSheet(spec), fabric(1e9, 1e-3, 300));  // far too stiff for 33 substeps
  ClothSolver solver(model, StepSettings{}, {pinAt(*model, {0})});
  solver.mutableState().vy[60] = 1.0;
  bool ok = true;
  long f = 1;
  for (; f <= 30 && ok; ++f) ok = solver.stepFrame(f);
  ASSERT_FALSE(ok);
  const Instability& bad = solver.instability();
  EXPECT_TRUE(bad.detected);
  EXPECT_EQ(bad.frame, f - 1);
  EXPECT_EQ(bad.refinement, StepSettings{}.maxRefinement) << "unstable at every refinement too";
  EXPECT_EQ(bad.strainLimit, StepSettings{}.rescueStrainLimit) << "and with strain limiting";
  EXPECT_TRUE(bad.rescued);
  EXPECT_EQ(solver.strainLimitedFrom(), bad.frame);
  EXPECT_LT(bad.vertex, model->vertexCount());
  const std::string what = bad.describe("sheet", 50);
  EXPECT_NE(what.find("garment 'sheet': vertex"), std::string::npos) << what;
  EXPECT_NE(what.find("8 times the substeps and edges held to 1.5 times their rest length since the frame went "
                      "unstable without"),
            std::string::npos)
      << what;
}

TEST(Validation, MaterialAndSettingsNameTheOption) {
  Material m;
  m.poissonRatio = 0.5;
  try {
    m.validate("--");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "--poisson-ratio must be in [0, 0.5), got 0.5");
  }
  m = Material{};
  m.thickness_m = -1;
  EXPECT_THROW(m.validate(), Error);
  StepSettings s;
  s.substepsPerFrame = 0;
  EXPECT_THROW(s.validate(), Error);
}

}  // namespace
}  // namespace drape::cloth
