// Strain limiting (strain_limit.hpp): edges within the limit are not touched, an edge
// beyond it comes back to it exactly and loses only the velocity that stretches it, held
// vertices stay put, momentum and the centre of mass are kept, and enough sweeps bring every
// edge of a crumpled sheet within the limit (each edge's limit is a convex set of
// configurations, and cyclic projection onto convex sets that meet converges). In the
// solver, a frame no refinement keeps stable is computed again with the limit on.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <fmt/format.h>

#include "cloth_fixture.hpp"
#include "drape/cloth/strain_limit.hpp"
#include "drape/core/error.hpp"

namespace drape::cloth {
namespace {

using testing::knit;
using testing::makeModel;

constexpr double kLimit = 0.5;

struct Sheet {
  SheetSpec spec{0.3, 0.2, 6, 4, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), "sheet"};
  std::shared_ptr<const ClothModel> model = makeModel(irregularSheet(spec, 0.3, 5), knit());
  ClothState state = ClothState::atRest(*model);
  std::vector<double> weight = model->inverseMass();
};

/// Largest length / rest length over the model's edges.
double largestStretch(const ClothModel& model, const ClothState& s) {
  double most = 0.0;
  for (std::size_t e = 0; e < model.edgeRestLength().size(); ++e) {
    const std::uint32_t i = model.edgeV0()[e], j = model.edgeV1()[e];
    most = std::max(most, (s.position(j) - s.position(i)).norm() / model.edgeRestLength()[e]);
  }
  return most;
}

/// Every vertex moved by up to `reach` (m) and given a velocity of up to 1 m/s per axis.
void crumple(ClothState& s, double reach, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> move(-reach, reach), speed(-1.0, 1.0);
  for (std::size_t i = 0; i < s.size(); ++i) {
    s.setPosition(i, s.position(i) + Vec3(move(rng), move(rng), move(rng)));
    s.setVelocity(i, Vec3(speed(rng), speed(rng), speed(rng)));
  }
}

Vec3 momentum(const ClothModel& model, const ClothState& s) {
  Vec3 p = Vec3::Zero();
  for (std::size_t i = 0; i < s.size(); ++i) p += model.mass()[i] * s.velocity(i);
  return p;
}

Vec3 centreOfMass(const ClothModel& model, const ClothState& s) {
  Vec3 c = Vec3::Zero();
  for (std::size_t i = 0; i < s.size(); ++i) c += model.mass()[i] * s.position(i);
  return c / model.totalMass_kg();
}

TEST(StrainLimit, EdgesWithinTheLimitAreNotTouched) {
  Sheet s;
  crumple(s.state, 0.002, 1);  // a few per cent of the 5 cm cells
  ASSERT_LT(largestStretch(*s.model, s.state), 1.0 + kLimit);
  const std::uint64_t before = s.state.hash();
  EXPECT_EQ(limitStrain(*s.model, s.weight, kLimit, kStrainLimitSweeps, s.state), 0u);
  EXPECT_EQ(s.state.hash(), before);
}

TEST(StrainLimit, AnEdgeBeyondTheLimitComesBackToItAndLosesOnlyItsStretchingVelocity) {
  // One triangle: edge 0-1 stretched to twice its rest length, vertex 2 near its middle so
  // that the other two edges stay within the limit.
  mesh::TriMesh m;
  m.name = "triangle";
  m.positions = {Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0.05, 0.0866, 0)};
  m.triangles = {{0, 1, 2}};
  const auto model = makeModel(m, knit());
  const std::vector<double> weight = model->inverseMass();
  std::size_t edge = 0;
  while (!(model->edgeV0()[edge] + model->edgeV1()[edge] == 1)) ++edge;
  const double rest = model->edgeRestLength()[edge];
  for (const double apart : {1.0, -1.0}) {  // the ends moving apart, or towards each other
    ClothState s = ClothState::atRest(*model);
    s.setPosition(0, Vec3(-0.05, 0, 0));
    s.setPosition(1, Vec3(0.15, 0, 0));
    s.setPosition(2, Vec3(0.05, 0.02, 0));
    s.setVelocity(0, Vec3(-apart, 0.3, 0));
    s.setVelocity(1, Vec3(apart, -0.2, 0));
    const Vec3 v2 = s.velocity(2);
    EXPECT_EQ(limitStrain(*model, weight, kLimit, 1, s), 1u) << "one edge beyond the limit";
    EXPECT_NEAR((s.position(1) - s.position(0)).norm(), (1.0 + kLimit) * rest, 1e-15);
    const double along = s.velocity(1).x() - s.velocity(0).x();
    if (apart > 0) EXPECT_NEAR(along, 0.0, 1e-15) << "the stretching velocity goes";
    else EXPECT_DOUBLE_EQ(along, -2.0) << "a closing velocity stays";
    EXPECT_DOUBLE_EQ(s.velocity(0).y(), 0.3) << "across the edge nothing changes";
    EXPECT_DOUBLE_EQ(s.velocity(1).y(), -0.2);
    EXPECT_EQ(s.velocity(2), v2) << "vertex 2's edges were within the limit";
  }
}

TEST(StrainLimit, KeepsMomentumAndTheCentreOfMass) {
  Sheet s;
  crumple(s.state, 0.05, 2);
  ASSERT_GT(largestStretch(*s.model, s.state), 1.0 + kLimit) << "nothing to limit: the test would mean nothing";
  const Vec3 p0 = momentum(*s.model, s.state), c0 = centreOfMass(*s.model, s.state);
  ASSERT_GT(limitStrain(*s.model, s.weight, kLimit, kStrainLimitSweeps, s.state), 0u);
  EXPECT_LT((momentum(*s.model, s.state) - p0).norm(), 1e-12 * s.model->totalMass_kg());  // of 1 m/s
  EXPECT_LT((centreOfMass(*s.model, s.state) - c0).norm(), 1e-12);
}

TEST(StrainLimit, HeldVerticesStayWhereTheyAre) {
  Sheet s;
  crumple(s.state, 0.05, 3);
  const std::vector<std::uint32_t> held = testing::row(s.spec, 0);
  for (const std::uint32_t v : held) s.weight[v] = 0.0;
  const ClothState before = s.state;
  ASSERT_GT(limitStrain(*s.model, s.weight, kLimit, kStrainLimitSweeps, s.state), 0u);
  for (const std::uint32_t v : held) {
    EXPECT_EQ(s.state.position(v), before.position(v)) << v;
    EXPECT_EQ(s.state.velocity(v), before.velocity(v)) << v;
  }
}

TEST(StrainLimit, EnoughSweepsBringEveryEdgeWithinTheLimit) {
  for (std::uint32_t seed = 10; seed < 30; ++seed) {
    Sheet s;
    crumple(s.state, 0.08, seed);
    const double stretched = largestStretch(*s.model, s.state);
    ASSERT_GT(stretched, 1.0 + kLimit);
    limitStrain(*s.model, s.weight, kLimit, kStrainLimitSweeps, s.state);
    const double afterTwo = largestStretch(*s.model, s.state);
    EXPECT_LT(afterTwo, stretched) << seed;
    limitStrain(*s.model, s.weight, kLimit, 2000, s.state);
    EXPECT_LT(largestStretch(*s.model, s.state), (1.0 + kLimit) * (1.0 + 1e-6)) << seed;
  }
}

TEST(StrainLimit, SettingsAreValidated) {
  StepSettings s;
  s.strainLimit = -0.1;
  EXPECT_THROW(s.validate("--"), Error);
  s.strainLimit = 0.0;
  s.rescueStrainLimit = 11.0;
  EXPECT_THROW(s.validate("--"), Error);
}

// ---------------------------------------------------------------------------------------
// In the solver: a strip whose bottom row is pulled down to `pull` times its height in the
// first tenth of a second and then held there. St Venant-Kirchhoff stiffens as it stretches,
// so a substep stable at rest can be unstable once the strip is stretched: the case the
// rescue is for.

/// The bottom row's frame: down by (pull - 1) times the strip's height over 0.1 s, then held.
class PullDown final : public FixtureMotion {
 public:
  explicit PullDown(double distance_m) : distance_(distance_m) {}
  [[nodiscard]] RigidTransform poseAt(double t) const override {
    RigidTransform pose;
    pose.translation = Vec3(0, -distance_ * std::min(1.0, t / 0.1), 0);
    return pose;
  }

 private:
  double distance_;
};

struct PulledStrip {
  SheetSpec spec{0.1, 0.1, 4, 4, Vec3::Zero(), Vec3::UnitX(), Vec3(0, -1, 0), "strip"};
  std::shared_ptr<const ClothModel> model = makeModel(gridSheet(spec), knit());
  StepSettings settings;

  PulledStrip(int substeps, double rescue) {
    settings.substepsPerFrame = substeps;
    settings.maxRefinement = 1;
    settings.rescueStrainLimit = rescue;
    settings.airViscosity_Ns_m3 = 0.0;
    settings.gravity_m_s2 = Vec3::Zero();
  }
  [[nodiscard]] std::unique_ptr<ClothSolver> solver(double pull) const {
    const auto& rx = model->restX();
    const auto& ry = model->restY();
    const auto& rz = model->restZ();
    return std::make_unique<ClothSolver>(
        model, settings,
        std::vector<PinGroup>{PinGroup::atRest(testing::row(spec, 0), rx, ry, rz),
                              PinGroup::atRest(testing::row(spec, spec.cellsV), rx, ry, rz,
                                               std::make_shared<PullDown>((pull - 1.0) * spec.sizeV_m))});
  }
};

constexpr long kPullFrames = 15;
constexpr double kPull = 1.4;

long firstUnstableFrame(ClothSolver& solver) { return testing::firstUnstableFrame(solver, kPullFrames); }

/// The fewest substeps per frame that keep the strip stable at rest but not once pulled; 0 if none.
int stableAtRestNotPulled() {
  for (int n = 1; n <= 200; ++n) {
    const PulledStrip strip(n, 0.0);
    if (firstUnstableFrame(*strip.solver(1.0)) == 0 && firstUnstableFrame(*strip.solver(kPull)) > 0) return n;
  }
  return 0;
}

TEST(StrainLimit, AFrameNoSubstepsKeepStableIsComputedAgainWithTheLimitWhichStaysOn) {
  const int n = stableAtRestNotPulled();
  ASSERT_GT(n, 0) << "no substep count is stable at rest and unstable pulled: the test would mean nothing";
  const PulledStrip without(n, 0.0), with(n, kLimit);
  const auto stops = without.solver(kPull);
  const long bad = firstUnstableFrame(*stops);
  ASSERT_GT(bad, 0);
  EXPECT_EQ(stops->strainLimitedFrom(), 0);
  EXPECT_EQ(stops->instability().strainLimit, 0.0);

  const auto rescued = with.solver(kPull);
  for (long f = 1; f <= kPullFrames; ++f) {
    ASSERT_TRUE(rescued->stepFrame(f)) << rescued->instability().describe("strip", 50);
    if (f < bad) {
      EXPECT_EQ(rescued->strainLimit(), 0.0) << "off until a frame needs it";
      EXPECT_EQ(describeStrainLimitRescue(*rescued, "strip", f), "");
    } else if (f == bad) {
      const std::string line = describeStrainLimitRescue(*rescued, "strip", f);
      EXPECT_NE(line.find(fmt::format("in frame {}", bad)), std::string::npos) << line;
      EXPECT_NE(line.find("computed again with its edges held to 1.5 times their rest length"), std::string::npos)
          << line;
    }
  }
  EXPECT_EQ(rescued->strainLimitedFrom(), bad);
  EXPECT_EQ(rescued->strainLimitedBecause().frame, bad);
  EXPECT_EQ(rescued->strainLimit(), kLimit) << "on for the rest of the run";
  EXPECT_GT(rescued->strainLimitCorrections(), 0u);
  // The fixtures' vertices are where the fixtures put them: the limit moved the others.
  const ClothModel& m = *with.model;
  for (const std::uint32_t v : testing::row(with.spec, 0))
    EXPECT_EQ(rescued->state().position(v), Vec3(m.restX()[v], m.restY()[v], m.restZ()[v])) << v;
  // The strip that stopped had torn itself apart; the rescued one is whole.
  EXPECT_GT(largestStretch(stops->model(), stops->state()), 3.0);
  EXPECT_LT(largestStretch(rescued->model(), rescued->state()), 2.0);
}

}  // namespace
}  // namespace drape::cloth
