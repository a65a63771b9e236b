// Frames computed again with more substeps when they go unstable (StepSettings::
// maxRefinement): the refined frame is exactly the frame a solver with that many substeps
// computes from the same start, the failed attempt leaves nothing behind, and a frame
// unstable at every refinement is still reported.

#include <gtest/gtest.h>

#include <fmt/format.h>

#include "cloth_fixture.hpp"
#include "drape/cloth/collider.hpp"
#include "drape/core/error.hpp"

namespace drape::cloth {
namespace {

using testing::makeModel;
using testing::knit;
using testing::row;

/// A sheet hanging from its top row, pushed out of its plane so that it swings into a
/// sphere, undamped, at `substeps` per frame.
struct HangingSheet {
  SheetSpec spec{0.3, 0.3, 12, 12, Vec3(-0.15, 0, 0), Vec3::UnitX(), Vec3(0, -1, 0), "sheet"};
  std::shared_ptr<const ClothModel> model = makeModel(irregularSheet(spec, 0.3, 7), knit());
  StepSettings settings;
  SphereCollider sphere{Vec3(0, -0.25, -0.12), 0.08};

  HangingSheet(int substeps, int maxRefinement) {
    settings.substepsPerFrame = substeps;
    settings.airViscosity_Ns_m3 = 0.0;
    settings.maxRefinement = maxRefinement;
    settings.rescueStrainLimit = 0.0;  // refinement alone (test_strain_limit.cpp has the rescue)
  }
  [[nodiscard]] std::unique_ptr<ClothSolver> solver() {
    auto s = std::make_unique<ClothSolver>(
        model, settings,
        std::vector<PinGroup>{PinGroup::atRest(row(spec, 0), model->restX(), model->restY(), model->restZ())});
    s->addCollider(sphere);
    for (std::size_t i = 0; i < s->state().size(); ++i) s->mutableState().vz[i] = -0.5;
    return s;
  }
};

constexpr long kFrames = 30;

/// The first frame (1-based) at which the solver stops, or 0 if it runs kFrames frames.
long firstUnstableFrame(ClothSolver& solver) { return testing::firstUnstableFrame(solver, kFrames); }

/// The fewest substeps per frame at which the fixed step goes unstable within kFrames while
/// twice as many keep it stable (the case refinement is for), found by trying; 0 if none.
int unstableButNotAtTwice() {
  for (int n = 1; n <= 64; ++n) {
    HangingSheet at(n, 1), twice(2 * n, 1);
    if (firstUnstableFrame(*at.solver()) > 0 && firstUnstableFrame(*twice.solver()) == 0) return n;
  }
  return 0;
}

TEST(Refinement, AFrameUnstableAtItsSubstepsIsComputedAgainWithMore) {
  const int n = unstableButNotAtTwice();
  ASSERT_GT(n, 0) << "no substep count is unstable at once and stable at twice: the test would mean nothing";
  HangingSheet plain(n, 1);
  auto fixed = plain.solver();
  const long bad = firstUnstableFrame(*fixed);
  ASSERT_GT(bad, 0);
  EXPECT_EQ(fixed->instability().refinement, 1);
  EXPECT_EQ(fixed->instability().substepsPerFrame, n);
  EXPECT_EQ(fixed->refinedFrames(), 0);

  HangingSheet refined(n, 2);
  auto solver = refined.solver();
  long f = 1;
  bool sawRefinement = false;
  for (; f <= kFrames; ++f) {
    ASSERT_TRUE(solver->stepFrame(f)) << solver->instability().describe("sheet", 50);
    if (solver->lastRefinement() == 1) continue;
    EXPECT_EQ(solver->lastRefinement(), 2);
    const std::string line = describeRefinedFrame(*solver, "sheet");
    EXPECT_NE(line.find("computed again with 2 times the substeps"), std::string::npos) << line;
    if (!sawRefinement) {
      EXPECT_EQ(solver->refinedBecause().frame, bad) << "first refined where the fixed step failed";
    }
    sawRefinement = true;
  }
  EXPECT_TRUE(sawRefinement);
  EXPECT_GT(solver->refinedFrames(), 0);
}

TEST(Refinement, TheRefinedFrameIsTheFrameComputedWithTwiceTheSubsteps) {
  const int n = unstableButNotAtTwice();
  ASSERT_GT(n, 0);
  HangingSheet plain(n, 1);
  const long bad = firstUnstableFrame(*plain.solver());
  ASSERT_GT(bad, 0);
  // The state before the bad frame, at n substeps.
  HangingSheet before(n, 1);
  auto upTo = before.solver();
  for (long f = 1; f < bad; ++f) ASSERT_TRUE(upTo->stepFrame(f));
  const ColliderCounters countsBefore = before.sphere.counters();

  // The refining solver takes the same frames up to there, bit for bit, then computes the
  // bad one again.
  HangingSheet refining(n, 2);
  auto solver = refining.solver();
  for (long f = 1; f < bad; ++f) ASSERT_TRUE(solver->stepFrame(f));
  ASSERT_EQ(solver->state().hash(), upTo->state().hash());
  ASSERT_TRUE(solver->stepFrame(bad)) << solver->instability().describe("sheet", 50);
  ASSERT_EQ(solver->lastRefinement(), 2);

  // A solver with twice the substeps per frame, from the same state, computes the same frame.
  HangingSheet reference(2 * n, 1);
  auto direct = reference.solver();
  direct->mutableState() = upTo->state();
  ASSERT_TRUE(direct->stepFrame(bad));
  EXPECT_EQ(solver->state().hash(), direct->state().hash());
  // The failed attempt left no count behind.
  EXPECT_EQ(refining.sphere.counters().calls, countsBefore.calls + reference.sphere.counters().calls);
  EXPECT_EQ(refining.sphere.counters().contacts, countsBefore.contacts + reference.sphere.counters().contacts);
}

TEST(Refinement, AFrameUnstableAtEveryRefinementIsReported) {
  // Far beyond the stable step: twice the substeps do not save it.
  HangingSheet sheet(1, 2);
  auto solver = sheet.solver();
  const long bad = firstUnstableFrame(*solver);
  ASSERT_GT(bad, 0);
  const Instability& i = solver->instability();
  EXPECT_EQ(i.refinement, 2);
  EXPECT_EQ(i.substepsPerFrame, 2 * sheet.settings.substepsPerFrame);
  const std::string what = i.describe("sheet", 50);
  EXPECT_NE(what.find("computed again with 2 times the substeps"), std::string::npos) << what;
  EXPECT_NE(what.find(fmt::format("of {}", 2 * sheet.settings.substepsPerFrame)), std::string::npos) << what;
}

TEST(Refinement, MaxRefinementIsValidated) {
  StepSettings s;
  s.maxRefinement = 0;
  EXPECT_THROW(s.validate("--"), Error);
  s.maxRefinement = 65;
  EXPECT_THROW(s.validate("--"), Error);
}

}  // namespace
}  // namespace drape::cloth
