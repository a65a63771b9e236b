// Strain limiting (strain_limit.hpp): edges within the limit are not touched, an edge
// beyond it comes back to it exactly and loses only the velocity that stretches it, held
// vertices stay put, momentum and the centre of mass are kept, and enough sweeps bring every
// edge of a crumpled sheet within the limit (each edge's limit is a convex set of
// configurations, and cyclic projection onto convex sets that meet converges). In the
// solver, a frame no refinement keeps stable is computed again with the limit on.

#include <gtest/gtest.h>

#include <algorithm>
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

long firstUnstablePullFrame(ClothSolver& solver) { return testing::firstUnstableFrame(solver, kPullFrames); }

/// The fewest substeps per frame that keep the strip stable at rest but not once pulled; 0 if none.
int stableAtRestNotPulled() {
  for (int n = 1; n <= 200; ++n) {
    const PulledStrip strip(n, 0.0);
    if (firstUnstablePullFrame(*strip.solver(1.0)) == 0 && firstUnstablePullFrame(*strip.solver(kPull)) > 0) return n;
  }
  return 0;
}

TEST(StrainLimit, AFrameNoSubstepsKeepStableIsComputedAgainWithTheLimitWhichStaysOn) {
  const int n = stableAtRestNotPulled();
  ASSERT_GT(n, 0) << "no substep count is stable at rest and unstable pulled: the test would mean nothing";
  const PulledStrip without(n, 0.0), with(n, kLimit);
  const auto stops = without.solver(kPull);
  const long bad = firstUnstablePullFrame(*stops);
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

// Stitches (holdStitches): the same projection as the strain limit's, to a length of its
// own, over pairs of vertices that need not share an edge.

TEST(Stitches, EveryStitchEndsWithinItsLengthKeepingMomentumAndTheCentreOfMass) {
  Sheet s;
  crumple(s.state, 0.05, 7);
  std::mt19937 rng(11);
  std::vector<std::uint32_t> order(s.state.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), rng);
  std::vector<Stitch> stitches;  // disjoint: one sweep settles each exactly
  std::uniform_real_distribution<double> length(0.0, 0.03);
  for (std::size_t i = 0; i + 1 < order.size(); i += 2) stitches.push_back({order[i], order[i + 1], length(rng)});
  s.weight[stitches[0].a] = 0.0;  // held by a fixture
  const Vec3 held = s.state.position(stitches[0].a);
  // Conserved over the other stitches' vertices (masses 1 / weight; the held vertex takes
  // up its stitch's pull).
  const auto sums = [&](const ClothState& st) {
    Vec3 p = Vec3::Zero(), c = Vec3::Zero();
    for (std::size_t i = 0; i < st.size(); ++i)
      if (s.weight[i] > 0.0 && i != stitches[0].b) {
        p += st.velocity(i) / s.weight[i];
        c += st.position(i) / s.weight[i];
      }
    return std::pair{p, c};
  };
  const auto [p0, c0] = sums(s.state);
  const ClothState before = s.state;
  const std::size_t corrected = holdStitches(stitches, s.weight, 1, s.state);
  EXPECT_GT(corrected, stitches.size() / 2) << "most random pairs start further apart than 3 cm";
  for (const Stitch& st : stitches) {
    const Vec3 d0 = before.position(st.b) - before.position(st.a);
    const Vec3 d = s.state.position(st.b) - s.state.position(st.a);
    if (d0.norm() <= st.length_m) {
      EXPECT_EQ(s.state.position(st.a), before.position(st.a)) << "within its length: untouched";
      continue;
    }
    EXPECT_NEAR(d.norm(), st.length_m, 1e-12);
    // Drawn together along the line between them, which keeps its direction, and no longer
    // moving apart along it.
    EXPECT_NEAR(d.normalized().dot(d0.normalized()), 1.0, 1e-9);
    EXPECT_LE((s.state.velocity(st.b) - s.state.velocity(st.a)).dot(d0.normalized()), 1e-12);
  }
  EXPECT_EQ(s.state.position(stitches[0].a), held);
  const auto [p1, c1] = sums(s.state);
  EXPECT_NEAR((p1 - p0).norm(), 0.0, 1e-12 * p0.norm() + 1e-15);
  EXPECT_NEAR((c1 - c0).norm(), 0.0, 1e-9 * c0.norm());
}

/// Two sheets hanging side by side, 1 cm apart, pinned along their top rows and thrown
/// apart out of their plane: the left one forwards, the right one backwards.
struct TwoSheets {
  SheetSpec left{0.2, 0.3, 4, 6, Vec3(0, -0.3, 0), Vec3::UnitX(), Vec3::UnitY(), "left"};
  SheetSpec right{0.2, 0.3, 4, 6, Vec3(0.21, -0.3, 0), Vec3::UnitX(), Vec3::UnitY(), "right"};
  mesh::TriMesh mesh = both();
  std::shared_ptr<const ClothModel> model = makeModel(mesh, knit());
  std::uint32_t offset = static_cast<std::uint32_t>(gridSheet(left).vertexCount());

  [[nodiscard]] mesh::TriMesh both() const {
    mesh::TriMesh m = gridSheet(left);
    const mesh::TriMesh r = gridSheet(right);
    const auto o = static_cast<std::uint32_t>(m.positions.size());
    m.positions.insert(m.positions.end(), r.positions.begin(), r.positions.end());
    for (const mesh::Triangle& t : r.triangles) m.triangles.push_back({t[0] + o, t[1] + o, t[2] + o});
    return m;
  }
  [[nodiscard]] std::unique_ptr<ClothSolver> solver(bool stitched) const {
    std::vector<std::uint32_t> top = testing::row(left, left.cellsV);
    for (const std::uint32_t v : testing::row(right, right.cellsV)) top.push_back(v + offset);
    auto s = std::make_unique<ClothSolver>(
        model, testing::settingsWithStep(1e-3),
        std::vector<PinGroup>{PinGroup::atRest(top, model->restX(), model->restY(), model->restZ())});
    if (stitched) {
      std::vector<Stitch> stitches;
      for (const auto& [a, b] : mesh::facingBoundaryPairs(mesh, mesh::Topology::build(mesh), 0.015))
        stitches.push_back({a, b, 0.0});
      s->setStitches(std::move(stitches), "two sheets");
    }
    for (std::uint32_t v = 0; v < model->vertexCount(); ++v)
      s->mutableState().setVelocity(v, Vec3(0, 0, v < offset ? 1.0 : -1.0));
    return s;
  }
  /// The bottom corners that face each other.
  [[nodiscard]] double bottomGap(const ClothSolver& s) const {
    return (s.state().position(offset + sheetVertex(right, 0, 0)) - s.state().position(sheetVertex(left, left.cellsU, 0)))
        .norm();
  }
};

TEST(Stitches, HoldTwoSheetsTogetherAlongTheEdgesThatFaceEachOther) {
  const TwoSheets sheets;
  const auto free = sheets.solver(false);
  const auto sewn = sheets.solver(true);
  ASSERT_EQ(sewn->stitches().size(), 7u) << "one per row";
  for (long f = 1; f <= 10; ++f) {
    ASSERT_TRUE(free->stepFrame(f)) << free->instability().describe("two sheets", 50);
    ASSERT_TRUE(sewn->stepFrame(f)) << sewn->instability().describe("two sheets", 50);
    for (const Stitch& st : sewn->stitches()) {
      if (sewn->pins()[0].vertices.end() !=
          std::find(sewn->pins()[0].vertices.begin(), sewn->pins()[0].vertices.end(), st.a))
        continue;  // the top row: both ends pinned where they were modelled
      EXPECT_LT((sewn->state().position(st.b) - sewn->state().position(st.a)).norm(), 1e-9) << f;
    }
  }
  EXPECT_GT(sheets.bottomGap(*free), 0.05) << "unsewn, the sheets swing apart";
  EXPECT_LT(sheets.bottomGap(*sewn), 1e-9);
  EXPECT_GT(sewn->stitchCorrections(), 0u);
  // Thrown alike in opposite directions, the sewn edge stays in the plane it hung in.
  for (const Stitch& st : sewn->stitches()) EXPECT_NEAR(sewn->state().position(st.a).z(), 0.0, 1e-3);
}

/// A sheet hanging from its two top corners, its tension pulling across the middle, and the
/// same sheet with a slit up its middle column from the bottom edge to row `slitTop`: the
/// column's vertices below it doubled, the copies 1 mm to the right and taken by the cells
/// right of the column. The copies are numbered after the sheet's own vertices.
struct SlitSheet {
  SheetSpec spec{0.4, 0.3, 8, 6, Vec3(-0.2, -0.3, 0), Vec3::UnitX(), Vec3::UnitY(), "sheet"};
  static constexpr int kColumn = 4, kSlitTop = 4;
  mesh::TriMesh whole = gridSheet(spec);
  mesh::TriMesh slit = cut();
  StepSettings settings = testing::settingsWithStep(1e-3, 2.0);

  [[nodiscard]] mesh::TriMesh cut() const {
    mesh::TriMesh m = whole;
    const double columnX = m.positions[sheetVertex(spec, kColumn, 0)].x();
    const double topY = m.positions[sheetVertex(spec, 0, kSlitTop)].y();
    std::vector<std::uint32_t> copy(kSlitTop);
    for (int j = 0; j < kSlitTop; ++j) {
      copy[static_cast<std::size_t>(j)] = static_cast<std::uint32_t>(m.positions.size());
      m.positions.push_back(m.positions[sheetVertex(spec, kColumn, j)] + Vec3(0.001, 0, 0));
    }
    for (mesh::Triangle& t : m.triangles) {
      const Vec3 centroid = (m.positions[t[0]] + m.positions[t[1]] + m.positions[t[2]]) / 3.0;
      if (centroid.x() < columnX || centroid.y() > topY) continue;  // left of the slit, or above it
      for (std::uint32_t& v : t)
        for (int j = 0; j < kSlitTop; ++j)
          if (v == sheetVertex(spec, kColumn, j)) v = copy[static_cast<std::size_t>(j)];
    }
    return m;
  }
  [[nodiscard]] std::unique_ptr<ClothSolver> hang(const mesh::TriMesh& m, bool sewn) const {
    const auto model = makeModel(m, knit());
    const std::vector<std::uint32_t> corners{sheetVertex(spec, 0, spec.cellsV), sheetVertex(spec, spec.cellsU, spec.cellsV)};
    auto s = std::make_unique<ClothSolver>(
        model, settings, std::vector<PinGroup>{PinGroup::atRest(corners, model->restX(), model->restY(), model->restZ())});
    if (sewn) {
      std::vector<Stitch> stitches;
      // Every row of the slit: row j's two vertices are 2 (kSlitTop - j) boundary edges apart.
      for (const auto& [a, b] : mesh::facingBoundaryPairs(m, mesh::Topology::build(m), 0.002, 2))
        stitches.push_back({a, b, 0.0});
      s->setStitches(std::move(stitches), "sheet");
    }
    return s;
  }
};

TEST(Stitches, ASlitSewnShutHangsAsTheUncutSheetDoes) {
  const SlitSheet sheet;
  const auto whole = sheet.hang(sheet.whole, false);
  const auto sewn = sheet.hang(sheet.slit, true);
  const auto open = sheet.hang(sheet.slit, false);
  ASSERT_EQ(sewn->stitches().size(), static_cast<std::size_t>(SlitSheet::kSlitTop));
  for (long f = 1; f <= 45; ++f)
    for (ClothSolver* s : {whole.get(), sewn.get(), open.get()})
      ASSERT_TRUE(s->stepFrame(f)) << s->instability().describe("sheet", 50);
  const auto bottomGap = [&](const ClothSolver& s) {
    const std::uint32_t left = sheetVertex(sheet.spec, SlitSheet::kColumn, 0);
    const auto right = static_cast<std::uint32_t>(sheet.whole.vertexCount());  // row 0's copy
    return (s.state().position(right) - s.state().position(left)).norm();
  };
  // Unsewn, the tension across the sheet opens the slit at the bottom (the sheet's vertices
  // end up to 56 mm from the uncut sheet's); sewn, it hangs as the uncut one to 2.5 mm, the
  // bending across the slit that the cut took away and the copies' 1 mm start aside.
  EXPECT_GT(bottomGap(*open), 0.02);
  EXPECT_LT(bottomGap(*sewn), 1e-9);
  double farthest = 0.0, farthestOpen = 0.0;
  for (std::uint32_t v = 0; v < sheet.whole.vertexCount(); ++v) {
    farthest = std::max(farthest, (sewn->state().position(v) - whole->state().position(v)).norm());
    farthestOpen = std::max(farthestOpen, (open->state().position(v) - whole->state().position(v)).norm());
  }
  EXPECT_LT(farthest, 0.1 * farthestOpen) << farthest << " against " << farthestOpen;
  RecordProperty("sewn_vs_whole_mm", std::to_string(1e3 * farthest));
  RecordProperty("open_vs_whole_mm", std::to_string(1e3 * farthestOpen));
}

TEST(Stitches, AStitchOutOfRangeOrToItselfIsRefusedNamingTheGarment) {
  const TwoSheets sheets;
  ClothSolver s(sheets.model, testing::settingsWithStep(1e-3));
  const auto refused = [&](Stitch st, const std::string& words) {
    try {
      s.setStitches({st}, "coat");
      ADD_FAILURE() << "accepted " << st.a << " " << st.b;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  refused({0, 1000, 0.0}, "garment 'coat': a stitch joins vertex 0 and 1000, but it has 70 vertices");
  refused({3, 3, 0.0}, "garment 'coat': a stitch joins vertex 3 to itself");
  refused({3, 4, -1.0}, "garment 'coat': the stitch of vertices 3 and 4 is -1 m long");
  EXPECT_TRUE(s.stitches().empty());
}

}  // namespace
}  // namespace drape::cloth
