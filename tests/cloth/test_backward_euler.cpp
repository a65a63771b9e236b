// Backward Euler (the implicit step): its linearisation against the forces' own
// derivative, its solve against a dense direct one, and its physics against analytic answers
// at substeps the explicit steps cannot take.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <limits>
#include <random>

#include "cloth_fixture.hpp"
#include "drape/cloth/backward_euler.hpp"
#include "drape/core/error.hpp"

namespace drape::cloth {
namespace {

using testing::fabric;
using testing::makeModel;
using testing::pinAt;
using testing::row;
using testing::run;
using testing::settingsWithStep;

/// Membrane and bending forces at s's positions (no damping: s's velocities are zero).
std::vector<double> forcesAt(const ClothModel& model, ClothState s) {
  clearForces(s);
  accumulateMembraneForces(model, s);
  accumulateBendingForces(model, s);
  std::vector<double> f(3 * s.size());
  for (std::size_t i = 0; i < s.size(); ++i) f[i] = s.fx[i], f[s.size() + i] = s.fy[i], f[2 * s.size() + i] = s.fz[i];
  return f;
}

/// s moved by eps p (3 n values, x block, y block, z block).
ClothState moved(ClothState s, const std::vector<double>& p, double eps) {
  const std::size_t n = s.size();
  for (std::size_t i = 0; i < n; ++i) {
    s.x[i] += eps * p[i];
    s.y[i] += eps * p[n + i];
    s.z[i] += eps * p[2 * n + i];
  }
  return s;
}

/// -df/dx p by central differences of the forces.
std::vector<double> stiffnessByDifferences(const ClothModel& model, const ClothState& s, const std::vector<double>& p) {
  const double eps = 1e-7;
  const std::vector<double> plus = forcesAt(model, moved(s, p, eps)), minus = forcesAt(model, moved(s, p, -eps));
  std::vector<double> out(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) out[i] = -(plus[i] - minus[i]) / (2 * eps);
  return out;
}

double norm(const std::vector<double>& v) { return std::sqrt(std::inner_product(v.begin(), v.end(), v.begin(), 0.0)); }

std::vector<double> randomVector(std::size_t size, std::mt19937& rng) {
  std::normal_distribution<double> d(0.0, 1.0);
  std::vector<double> v(size);
  for (double& x : v) x = d(rng);
  return v;
}

/// A curved, irregular sheet (its rest shape bent, so the hinges carry a rest angle).
std::shared_ptr<const ClothModel> curvedSheet(const Material& material, std::uint32_t seed) {
  SheetSpec spec{0.2, 0.2, 6, 6, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), "sheet"};
  mesh::TriMesh m = irregularSheet(spec, 0.3, seed);
  for (Vec3& p : m.positions) p.z() = 0.4 * p.x() * p.x() + 0.2 * p.x() * p.y();
  return makeModel(m, material);
}

// ---------------------------------------------------------------------------------------
// Where it drops nothing the linearisation is the forces' exact derivative: at rest (the
// stress and every psi - psi0 are zero: only the material and Gauss-Newton terms remain),
// and stretched in every direction (no compressive stress to drop), without hinges.
TEST(BackwardEuler, StiffnessIsTheForcesDerivativeWhereNothingIsDropped) {
  std::mt19937 rng(11);
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    Material knit = fabric(5e4, 5e-4, 300);
    knit.bendingStiffness_Nm = 2e-4;  // a hinge force of the membrane's order, so both are checked
    const auto model = curvedSheet(knit, seed);
    BackwardEuler be;
    be.prepare(*model, StepSettings{}, {});
    const ClothState rest = ClothState::atRest(*model);
    be.linearise(*model, rest);
    const std::vector<double> p = randomVector(3 * model->vertexCount(), rng);
    std::vector<double> product(p.size());
    be.stiffnessTimes(*model, p, 1.0, 1.0, product);
    const std::vector<double> reference = stiffnessByDifferences(*model, rest, p);
    std::vector<double> error(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) error[i] = product[i] - reference[i];
    ASSERT_GT(norm(reference), 1.0);
    EXPECT_LT(norm(error), 1e-5 * norm(reference)) << "at rest, seed " << seed;

    // Stretched by 3 to 8 % in every direction, without hinges.
    Material flat = knit;
    flat.bendingStiffness_Nm = 0.0;
    const auto membrane = curvedSheet(flat, seed);
    BackwardEuler stretched;
    stretched.prepare(*membrane, StepSettings{}, {});
    ClothState s = ClothState::atRest(*membrane);
    std::uniform_real_distribution<double> stretch(1.03, 1.08);
    const double a = stretch(rng), b = stretch(rng);
    for (std::size_t i = 0; i < s.size(); ++i) s.x[i] *= a, s.y[i] *= b, s.z[i] *= std::sqrt(a * b);
    stretched.linearise(*membrane, s);
    stretched.stiffnessTimes(*membrane, p, 1.0, 1.0, product);
    const std::vector<double> tense = stiffnessByDifferences(*membrane, s, p);
    for (std::size_t i = 0; i < p.size(); ++i) error[i] = product[i] - tense[i];
    EXPECT_LT(norm(error), 1e-5 * norm(tense)) << "stretched, seed " << seed;
  }
}

// Crumpled at random (compressed and folded), the linearisation is still symmetric and
// positive semi-definite: what lets conjugate gradients solve the step.
TEST(BackwardEuler, StiffnessStaysSymmetricAndPositiveWhereTheClothCrumples) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02), squeeze(0.7, 1.0);
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    const auto model = curvedSheet(fabric(5e4, 5e-4, 300), seed);
    BackwardEuler be;
    be.prepare(*model, StepSettings{}, {});
    ClothState s = ClothState::atRest(*model);
    const double sx = squeeze(rng);
    for (std::size_t i = 0; i < s.size(); ++i) {
      s.x[i] = sx * s.x[i] + jitter(rng);
      s.y[i] += jitter(rng);
      s.z[i] += jitter(rng);
    }
    be.linearise(*model, s);
    const std::size_t size = 3 * model->vertexCount();
    const std::vector<double> p = randomVector(size, rng), q = randomVector(size, rng);
    std::vector<double> kp(size), kq(size);
    be.stiffnessTimes(*model, p, 1.0, 1.0, kp);
    be.stiffnessTimes(*model, q, 1.0, 1.0, kq);
    const double qkp = std::inner_product(q.begin(), q.end(), kp.begin(), 0.0);
    const double pkq = std::inner_product(p.begin(), p.end(), kq.begin(), 0.0);
    const double pkp = std::inner_product(p.begin(), p.end(), kp.begin(), 0.0);
    EXPECT_NEAR(qkp, pkq, 1e-10 * (std::abs(qkp) + std::abs(pkq))) << "seed " << seed;
    EXPECT_GE(pkp, 0.0) << "seed " << seed;
  }
}

// A flat sheet pressed together in its plane: its exact stiffness is negative for every
// motion out of the plane (the compressive stress pulls a buckle further: the material
// term is zero there to first order), where the linearisation's is zero, not negative.
TEST(BackwardEuler, DropsWhatMakesACompressedSheetIndefinite) {
  std::mt19937 rng(9);
  Material flat = fabric(5e4, 5e-4, 300);
  flat.bendingStiffness_Nm = 0.0;
  SheetSpec spec{0.2, 0.2, 6, 6, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), "sheet"};
  const auto model = makeModel(irregularSheet(spec), flat);
  ClothState s = ClothState::atRest(*model);
  for (std::size_t i = 0; i < s.size(); ++i) s.x[i] *= 0.9, s.y[i] *= 0.95;
  BackwardEuler be;
  be.prepare(*model, StepSettings{}, {});
  be.linearise(*model, s);
  const std::size_t n = model->vertexCount();
  std::vector<double> p(3 * n, 0.0), kp(3 * n);
  std::normal_distribution<double> d(0.0, 1.0);
  for (int k = 0; k < 10; ++k) {
    for (std::size_t i = 0; i < n; ++i) p[2 * n + i] = d(rng);
    const std::vector<double> exact = stiffnessByDifferences(*model, s, p);
    be.stiffnessTimes(*model, p, 1.0, 1.0, kp);
    const double exactCurvature = std::inner_product(p.begin(), p.end(), exact.begin(), 0.0);
    const double curvature = std::inner_product(p.begin(), p.end(), kp.begin(), 0.0);
    EXPECT_LT(exactCurvature, 0.0);
    EXPECT_NEAR(curvature, 0.0, 1e-9 * std::abs(exactCurvature));
  }
}

// One step's velocity change against a dense direct solve of the same linear system,
// assembled column by column from the products.
/// A randomly displaced and moving irregular sheet with its top row held, its forces
/// accumulated, and the backward-Euler system at ten times its explicit step, dense: A = M +
/// (h^2 + h beta) K_material + h^2 K_geometric + h c A_v over all 3 n unknowns (x block, y
/// block, z block), b = h (f0 + M g) - h^2 K v0.
struct DenseCase {
  std::shared_ptr<const ClothModel> model;
  StepSettings settings;
  std::vector<std::uint32_t> top;
  std::vector<std::uint8_t> fixed;
  ClothState s;
  double h = 0.0;
  Eigen::MatrixXd A;
  Eigen::VectorXd b;

  DenseCase() {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> d(-0.01, 0.01);
    SheetSpec spec{0.2, 0.2, 5, 5, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), "sheet"};
    Material m = fabric(5e4, 5e-4, 300);
    m.damping_s = 1e-3;
    model = makeModel(irregularSheet(spec), m);
    const std::size_t n = model->vertexCount(), size = 3 * n;
    settings.airViscosity_Ns_m3 = 0.5;
    settings.implicitTolerance = 1e-9;  // the solve to its end, to compare with the direct one
    top = row(spec, spec.cellsV);
    fixed.assign(n, 0);
    for (const std::uint32_t v : top) fixed[v] = 1;
    s = ClothState::atRest(*model);
    for (std::size_t i = 0; i < n; ++i) {
      s.x[i] += d(rng), s.y[i] += d(rng), s.z[i] += d(rng);
      s.vx[i] = 10 * d(rng), s.vy[i] = 10 * d(rng), s.vz[i] = 10 * d(rng);
    }
    clearForces(s);
    accumulateMembraneForces(*model, s);
    accumulateBendingForces(*model, s);
    accumulateDragForces(*model, settings, s);
    h = 10 * model->estimatedStableStep_s();

    BackwardEuler dense;
    dense.prepare(*model, settings, fixed);
    dense.linearise(*model, s);
    A = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(size), static_cast<Eigen::Index>(size));
    std::vector<double> e(size), kMat(size), kGeo(size);
    for (std::size_t j = 0; j < size; ++j) {
      std::fill(e.begin(), e.end(), 0.0);
      e[j] = 1.0;
      dense.stiffnessTimes(*model, e, 1.0, 0.0, kMat);
      dense.stiffnessTimes(*model, e, 0.0, 1.0, kGeo);
      for (std::size_t i = 0; i < size; ++i)
        A(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) =
            (h * h + h * m.damping_s) * kMat[i] + h * h * kGeo[i];
      A(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(j)) +=
          model->mass()[j % n] + h * settings.airViscosity_Ns_m3 * model->vertexArea()[j % n];
    }
    std::vector<double> v0(size);
    for (std::size_t i = 0; i < n; ++i) v0[i] = s.vx[i], v0[n + i] = s.vy[i], v0[2 * n + i] = s.vz[i];
    std::vector<double> kv(size);
    dense.stiffnessTimes(*model, v0, 1.0, 1.0, kv);
    const Vec3 g = settings.gravity_m_s2;
    const double gc[3] = {g.x(), g.y(), g.z()};
    const double* f0[3] = {s.fx.data(), s.fy.data(), s.fz.data()};
    b.resize(static_cast<Eigen::Index>(size));
    for (std::size_t c = 0; c < 3; ++c)
      for (std::size_t i = 0; i < n; ++i)
        b(static_cast<Eigen::Index>(c * n + i)) = h * (f0[c][i] + model->mass()[i] * gc[c]) - h * h * kv[c * n + i];
  }

  /// The velocity change a step took, all 3 n values.
  [[nodiscard]] Eigen::VectorXd change(const ClothState& stepped) const {
    const std::size_t n = s.size();
    Eigen::VectorXd dv(static_cast<Eigen::Index>(3 * n));
    for (std::size_t i = 0; i < n; ++i) {
      dv(static_cast<Eigen::Index>(i)) = stepped.vx[i] - s.vx[i];
      dv(static_cast<Eigen::Index>(n + i)) = stepped.vy[i] - s.vy[i];
      dv(static_cast<Eigen::Index>(2 * n + i)) = stepped.vz[i] - s.vz[i];
    }
    return dv;
  }
};

TEST(BackwardEuler, ConjugateGradientsSolveTheLinearisedSystem) {
  const DenseCase c;
  const std::size_t n = c.model->vertexCount();
  std::vector<Eigen::Index> free;
  for (std::size_t k = 0; k < 3 * n; ++k)
    if (!c.fixed[k % n]) free.push_back(static_cast<Eigen::Index>(k));
  const Eigen::MatrixXd Af = c.A(free, free);
  const Eigen::VectorXd expected = Af.llt().solve(c.b(free));

  BackwardEuler be;
  be.prepare(*c.model, c.settings, c.fixed);
  ClothState stepped = c.s;
  be.advance(*c.model, c.settings.gravity_m_s2, c.h, stepped);
  const Eigen::VectorXd got = c.change(stepped)(free);
  EXPECT_LT((got - expected).norm(), 1e-7 * expected.norm());
  EXPECT_EQ(be.solveStats().solves, 1);
  EXPECT_EQ(be.solveStats().unconverged, 0);
  EXPECT_EQ(be.solveStats().indefinite, 0);
  // Positions follow the new velocities; the held vertices took gravity alone.
  for (std::size_t i = 0; i < n; ++i) EXPECT_DOUBLE_EQ(stepped.y[i], c.s.y[i] + c.h * stepped.vy[i]);
  for (const std::uint32_t v : c.top) EXPECT_DOUBLE_EQ(stepped.vy[v], c.s.vy[v] + c.h * c.settings.gravity_m_s2.y());
}

// A point pinched between two parts is held along their normals for one solve (Baraff and
// Witkin's filter with one or two directions): the step is the linearised system's solution
// over the velocity changes that leave those directions alone, against a dense solve in a
// basis of them; the next solve frees it.
TEST(BackwardEuler, PinchedPointsAreHeldAlongTheirPartsNormalsForOneSolve) {
  const DenseCase c;
  const std::size_t n = c.model->vertexCount();
  std::mt19937 rng(11);
  std::normal_distribution<double> gauss;
  const auto unit = [&] { return Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized(); };
  // Vertex 8 between two parts (free along their crease), vertex 15 on one part's normal
  // alone, a fixed vertex, which stays held as before, and vertex 8 again (from another
  // collider): its first hold stands.
  const std::vector<PinchedPoint> pinched = {
      {8, {unit(), unit()}}, {15, {unit(), Vec3::Zero()}}, {c.top[0], {unit()}}, {8, {unit(), unit()}}};
  ASSERT_FALSE(c.fixed[8] || c.fixed[15]);
  // A basis of the velocity changes the filter lets through: each free vertex's axes, the
  // pinched ones' directions orthogonal to theirs.
  std::vector<Eigen::VectorXd> basis;
  const auto add = [&](std::size_t v, const Vec3& direction) {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(3 * n));
    for (int axis = 0; axis < 3; ++axis) e(static_cast<Eigen::Index>(axis * n + v)) = direction(axis);
    basis.push_back(e);
  };
  for (std::size_t v = 0; v < n; ++v) {
    if (c.fixed[v]) continue;
    if (v == 8) {
      add(v, pinched[0].along[0].cross(pinched[0].along[1]).normalized());
    } else if (v == 15) {
      const Vec3 a = pinched[1].along[0].unitOrthogonal();
      add(v, a);
      add(v, pinched[1].along[0].cross(a));
    } else {
      for (int axis = 0; axis < 3; ++axis) add(v, Vec3::Unit(axis));
    }
  }
  Eigen::MatrixXd Q(static_cast<Eigen::Index>(3 * n), static_cast<Eigen::Index>(basis.size()));
  for (std::size_t k = 0; k < basis.size(); ++k) Q.col(static_cast<Eigen::Index>(k)) = basis[k];
  const Eigen::VectorXd expected = Q * (Q.transpose() * c.A * Q).llt().solve(Q.transpose() * c.b);

  BackwardEuler be;
  be.prepare(*c.model, c.settings, c.fixed);
  be.holdPinched(pinched);
  ClothState stepped = c.s;
  be.advance(*c.model, c.settings.gravity_m_s2, c.h, stepped);
  Eigen::VectorXd got = c.change(stepped);
  for (const std::uint32_t v : c.top)  // the fixed vertices took gravity, as before
    got(static_cast<Eigen::Index>(n + v)) -= c.h * c.settings.gravity_m_s2.y();
  EXPECT_LT((got - expected).norm(), 1e-7 * expected.norm());
  const auto dvOf = [&](const Eigen::VectorXd& dv, std::size_t v) {
    return Vec3(dv(static_cast<Eigen::Index>(v)), dv(static_cast<Eigen::Index>(n + v)),
                dv(static_cast<Eigen::Index>(2 * n + v)));
  };
  for (const Vec3& along : pinched[0].along) EXPECT_NEAR(dvOf(got, 8).dot(along), 0.0, 1e-12);
  EXPECT_NEAR(dvOf(got, 15).dot(pinched[1].along[0]), 0.0, 1e-12);
  EXPECT_GT(dvOf(got, 15).norm(), 1e-6) << "free along the part's surface";

  // The next solve, with no pinch, moves them along those directions again.
  ClothState next = stepped;
  clearForces(next);
  accumulateMembraneForces(*c.model, next);
  accumulateBendingForces(*c.model, next);
  const ClothState before = next;
  be.advance(*c.model, c.settings.gravity_m_s2, c.h, next);
  const Vec3 dv8(next.vx[8] - before.vx[8], next.vy[8] - before.vy[8], next.vz[8] - before.vz[8]);
  EXPECT_GT(std::abs(dv8.dot(pinched[0].along[0])), 1e-6);
}

// ---------------------------------------------------------------------------------------
// Free fall: no internal force acts on a rigid translation, so the centre of mass falls at g
// exactly as the explicit steps have it: x_k = x_0 + h^2 g k (k + 1) / 2.
TEST(BackwardEuler, CentreOfMassFallsAtG) {
  SheetSpec spec{0.3, 0.3, 6, 6, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), "sheet"};
  const auto model = makeModel(irregularSheet(spec), fabric(1e5, 1e-3, 300));
  StepSettings settings = settingsWithStep(20 * model->estimatedStableStep_s());
  settings.integrator = IntegratorKind::BackwardEuler;
  ClothSolver solver(model, settings);
  const int steps = 40;
  ASSERT_TRUE(run(solver, steps));
  const double h = settings.substep_s();
  double y = 0.0;
  for (std::size_t i = 0; i < model->vertexCount(); ++i) y += model->mass()[i] * solver.state().y[i];
  y /= model->totalMass_kg();
  const double expected = -9.81 * h * h * steps * (steps + 1) / 2.0;
  EXPECT_NEAR(y, expected, 1e-6 * std::abs(expected));
  EXPECT_EQ(solver.solveStats().solves, steps);
}

// A strip hanging from its top edge settles to rho g L^2 / (2 E) at a substep 30 times the
// explicit steps' stable one, at which symplectic Euler diverges within a few substeps.
TEST(BackwardEuler, HangingStripElongationAtThirtyTimesTheExplicitStep) {
  const double L = 1.0, W = 0.1, E = 1e6, rho = 1000, t = 1e-3;
  SheetSpec spec{W, L, 4, 40, Vec3(0, -L, 0), Vec3::UnitX(), Vec3::UnitY(), "strip"};
  const auto model = makeModel(gridSheet(spec), fabric(E, t, rho));
  const double h = 30 * model->estimatedStableStep_s();
  StepSettings settings = settingsWithStep(h, 10.0);
  settings.maxRefinement = 1;
  settings.rescueStrainLimit = 0.0;
  const PinGroup top = pinAt(*model, row(spec, spec.cellsV));

  ClothSolver explicitStep(model, settings, {top});
  EXPECT_FALSE(run(explicitStep, 200)) << "symplectic Euler was stable at 30 times its estimated step";

  settings.integrator = IntegratorKind::BackwardEuler;
  ClothSolver solver(model, settings, {top});
  ASSERT_TRUE(run(solver, static_cast<long>(1.5 / settings.substep_s())));
  const double drop = testing::meanDrop(*model, solver.state(), row(spec, 0));
  const double expected = rho * 9.81 * L * L / (2 * E);
  EXPECT_NEAR(drop, expected, 0.05 * expected);
  EXPECT_EQ(solver.solveStats().unconverged, 0);
  EXPECT_EQ(solver.solveStats().indefinite, 0);
}

// Undamped and without drag, a swinging sheet's energy never grows under backward Euler
// (beyond the solve's tolerance): the step dissipates, it does not blow up, at ten times the
// explicit step.
TEST(BackwardEuler, SwingingSheetLosesEnergyInsteadOfGainingIt) {
  SheetSpec spec{0.3, 0.3, 6, 6, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), "sheet"};
  const auto model = makeModel(gridSheet(spec), fabric(2e4, 1e-3, 300));
  StepSettings settings = settingsWithStep(10 * model->estimatedStableStep_s(), 0.0);
  settings.integrator = IntegratorKind::BackwardEuler;
  ClothSolver solver(model, settings, {pinAt(*model, {sheetVertex(spec, 0, 0), sheetVertex(spec, 6, 0)})});
  const double e0 = solver.totalEnergy();
  double previous = e0, kinetic = 0.0;
  for (int k = 0; k < 100; ++k) {
    ASSERT_TRUE(run(solver, 5));
    const double e = solver.totalEnergy();
    EXPECT_LE(e, previous + 1e-6 * std::abs(e0)) << "after " << 5 * (k + 1) << " substeps";
    previous = e;
    kinetic = std::max(kinetic, kineticEnergy(*model, solver.state()));
  }
  EXPECT_GT(kinetic, 1e-3);  // it swung
  EXPECT_LT(previous, e0);
}

// Each solve starts from the last one's dv, unless that start is worse than none: after a
// substep that went unstable (which the solver's guard catches, and then computes the frame
// again from its start), the next step from a sound state is sound.
TEST(BackwardEuler, AStepAfterAnUnstableOneStartsAfresh) {
  SheetSpec spec{0.2, 0.2, 4, 4, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), "sheet"};
  const auto model = makeModel(irregularSheet(spec), fabric(5e4, 5e-4, 300));
  BackwardEuler be;
  StepSettings still;
  still.airViscosity_Ns_m3 = 0.0;
  still.implicitTolerance = 1e-9;
  be.prepare(*model, still, {});
  const auto step = [&](ClothState s) {
    clearForces(s);
    accumulateMembraneForces(*model, s);
    accumulateBendingForces(*model, s);
    be.advance(*model, Vec3(0, -9.81, 0), 1e-2, s);
    return s;
  };
  ClothState broken = ClothState::atRest(*model);
  broken.vx[3] = 1e150;  // a vertex thrown far beyond any speed the guard lets through
  EXPECT_GT(std::abs(step(broken).vx[3]), 1e100);
  const ClothState sound = step(ClothState::atRest(*model));
  for (std::size_t i = 0; i < sound.size(); ++i)
    ASSERT_TRUE(std::isfinite(sound.x[i]) && std::isfinite(sound.vy[i])) << "vertex " << i;
  EXPECT_NEAR(sound.vy[0], -9.81e-2, 1e-9);  // at rest, free, no drag: the step is gravity's
}

TEST(BackwardEuler, RefusesABendingRhythm) {
  StepSettings settings;
  settings.integrator = IntegratorKind::BackwardEuler;
  settings.bendEvery = 8;
  EXPECT_NE(testing::refusal(settings).find("--bend-every must be 1 with the backward-euler integrator"),
            std::string::npos)
      << "refused with '" << testing::refusal(settings) << "'";
  EXPECT_EQ(parseIntegrator("backward-euler"), IntegratorKind::BackwardEuler);
  EXPECT_EQ(integratorName(IntegratorKind::BackwardEuler), "backward-euler");
}

}  // namespace
}  // namespace drape::cloth
