// A garment worn over another (cloth/layer_collider.hpp, addGarmentBelow): the grid and the
// list kept between tests find the pairs brute force finds, with the points of both
// garments; a sheet dropped on a garment below that rises through every frame rides one gap
// above it (it moves linearly over each frame, not in jumps); a sheet on a garment below that
// slides away is dragged along at mu g.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <tuple>

#include <fmt/format.h>

#include "cloth_fixture.hpp"
#include "drape/cloth/layer_collider.hpp"
#include "drape/core/error.hpp"
#include "layer_fixture.hpp"

namespace drape::cloth {
namespace garment_below_test {

using testing::ContactSet;
using testing::carryAndWander;
using testing::contactSet;
using testing::everyPair;
using testing::joinedMeshes;
using testing::knit;
using testing::makeModel;
using testing::pinAt;
using testing::settingsWithStep;
using testing::stateAt;

constexpr double kFrame_s = 1.0 / 30.0;

/// A wavy sheet of `cells` x `cells` over [0, 1]^2 in xz at height `y`, its points moved by up
/// to `noise`.
mesh::TriMesh wavySheet(int cells, double y, double wave, double noise, unsigned seed, std::mt19937& random) {
  SheetSpec spec{1.0, 1.0, cells, cells, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), "sheet"};
  mesh::TriMesh m = irregularSheet(spec, 0.3, seed);
  std::uniform_real_distribution<double> jitter(-noise, noise);
  for (Vec3& p : m.positions)
    p = Vec3(p.x(), y + wave * std::sin(7 * p.x()) * std::cos(5 * p.z()), p.z()) +
        Vec3(jitter(random), jitter(random), jitter(random));
  return m;
}

/// Heights above a sheet that lies along y: where a vertical line through p meets it.
class SurfaceHeight {
 public:
  explicit SurfaceHeight(const mesh::TriMesh& sheet) : sheet_(sheet) {}
  [[nodiscard]] double above(const Vec3& p) const {
    for (const mesh::Triangle& t : sheet_.triangles) {
      const Vec3 &a = sheet_.positions[t[0]], &b = sheet_.positions[t[1]], &c = sheet_.positions[t[2]];
      // Barycentric weights in the xz plane.
      const double det = (b.x() - a.x()) * (c.z() - a.z()) - (c.x() - a.x()) * (b.z() - a.z());
      const double u = ((b.x() - p.x()) * (c.z() - p.z()) - (c.x() - p.x()) * (b.z() - p.z())) / det;
      const double v = ((c.x() - p.x()) * (a.z() - p.z()) - (a.x() - p.x()) * (c.z() - p.z())) / det;
      const double w = 1.0 - u - v;
      if (u >= -1e-12 && v >= -1e-12 && w >= -1e-12) return p.y() - (u * a.y() + v * b.y() + w * c.y());
    }
    return std::numeric_limits<double>::quiet_NaN();
  }

 private:
  const mesh::TriMesh& sheet_;
};

struct Kinds {
  std::size_t overBelow = 0;  ///< its own vertex, a triangle below
  std::size_t belowOver = 0;  ///< a vertex below, its own triangle
  std::size_t crossed = 0;
  void add(const ContactSet& contacts, std::uint32_t ownVertices) {
    for (const auto& [v, t, side, cross] : contacts) {
      (v < ownVertices ? overBelow : belowOver) += 1;
      crossed += cross;
    }
  }
};

TEST(GarmentBelow, TheGridFindsWhatBruteForceFinds) {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Kinds kinds;
  for (int trial = 0; trial < 40; ++trial) {
    // Two garments of different resolutions, the one over it a gap or so above, some of its
    // points held by a fixture; both move, each point its own way.
    const int cellsOver = 6 + static_cast<int>(unit(random) * 8), cellsBelow = 6 + static_cast<int>(unit(random) * 8);
    const double gap = 0.01 + 0.04 * unit(random), self = trial % 2 == 0 ? 0.0 : gap;
    const mesh::TriMesh over = wavySheet(cellsOver, gap * 1.5 * unit(random), 0.02, 0.3 * gap, trial, random);
    const mesh::TriMesh below = wavySheet(cellsBelow, 0.0, 0.02, 0.3 * gap, 100 + trial, random);
    const auto overModel = makeModel(over, knit()), belowModel = makeModel(below, knit());
    const mesh::TriMesh both = joinedMeshes(over, below);
    std::vector<Vec3> after = both.positions;
    std::uniform_real_distribution<double> move(-0.6 * gap, 0.6 * gap);
    for (Vec3& p : after) p += Vec3(move(random), move(random), move(random));
    if (trial % 4 == 3) {
      // An unstable substep flings a point of each a kilometre: their boxes, and their
      // triangles', touch too many cells to be listed cell by cell.
      after[static_cast<std::size_t>(unit(random) * over.positions.size())] += Vec3(1000.0, -300.0, 20.0);
      after[over.positions.size() + static_cast<std::size_t>(unit(random) * below.positions.size())] +=
          Vec3(-5.0, 800.0, 1000.0);
    }
    const ClothState belowState = stateAt(below.positions);
    LayerCollider collider(*overModel, "over", self);
    std::vector<std::uint32_t> held;
    for (std::uint32_t v = 0; v < over.positions.size(); ++v)
      if (unit(random) < 0.15) held.push_back(v);
    collider.setFixedVertices(held);
    collider.addGarmentBelow(*belowModel, "below", belowState, gap, kFrame_s);
    ASSERT_EQ(collider.vertexCount(), both.positions.size());
    ASSERT_EQ(collider.triangleCount(), both.triangles.size());
    const ClothState s0 = stateAt(both.positions), s1 = stateAt(after);

    const ContactSet grid = contactSet(collider.findContacts(s0, s1));
    const ContactSet brute = everyPair(collider, both, s0, s1);
    std::string missing, extra;
    for (const auto& c : brute)
      if (!grid.count(c)) missing += fmt::format(" ({}, {})", std::get<0>(c), std::get<1>(c));
    for (const auto& c : grid)
      if (!brute.count(c)) extra += fmt::format(" ({}, {})", std::get<0>(c), std::get<1>(c));
    EXPECT_TRUE(missing.empty() && extra.empty()) << "trial " << trial << "; missed:" << missing << "; extra:" << extra;
    kinds.add(brute, static_cast<std::uint32_t>(over.positions.size()));
  }
  // Enough of each kind that a wrong grid could not pass.
  EXPECT_GT(kinds.overBelow, 500u);
  EXPECT_GT(kinds.belowOver, 500u);
  EXPECT_GT(kinds.crossed, 50u);
}

TEST(GarmentBelow, TheListKeptBetweenTestsFindsWhatBruteForceFinds) {
  // Both garments carried along together (a walk) while their points wander, a few jump
  // (which mends the list) and, in the first run, all of them scatter every tenth test
  // (which makes it again), test after test.
  for (const bool scatter : {true, false}) {
    SCOPED_TRACE(scatter ? "scattered every tenth test" : "never scattered");
    std::mt19937 random(13);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const double gap = 0.02;
    const mesh::TriMesh over = wavySheet(10, gap, 0.02, 0.2 * gap, 1, random);
    const mesh::TriMesh below = wavySheet(13, 0.0, 0.02, 0.2 * gap, 2, random);
    const auto overModel = makeModel(over, knit()), belowModel = makeModel(below, knit());
    const mesh::TriMesh both = joinedMeshes(over, below);
    const ClothState belowState = stateAt(below.positions);
    LayerCollider collider(*overModel, "over", 0.0);
    collider.addGarmentBelow(*belowModel, "below", belowState, gap, kFrame_s);
    ClothState before = stateAt(both.positions), now = before;
    collider.findContacts(before, before);  // the sides as they start
    Kinds kinds;
    for (int test = 0; test < 120; ++test) {
      carryAndWander(now, test, gap, random, scatter);
      const ContactSet kept = contactSet(collider.nextContacts(now));
      const ContactSet brute = everyPair(collider, both, before, now);
      EXPECT_EQ(kept, brute) << "test " << test;
      kinds.add(brute, static_cast<std::uint32_t>(over.positions.size()));
      before = now;
    }
    EXPECT_GT(kinds.overBelow, 500u);
    EXPECT_GT(kinds.belowOver, 500u);
    const LayerCounters& counts = collider.layerCounters();
    EXPECT_GE(counts.rebuilds, scatter ? 3u : 1u);
    EXPECT_LE(counts.rebuilds, scatter ? 13u : 1u);
    EXPECT_GE(counts.mends, 100u);
  }
}

/// A rigid translation at constant velocity from the origin.
class Gliding final : public FixtureMotion {
 public:
  explicit Gliding(const Vec3& velocity) : velocity_(velocity) {}
  [[nodiscard]] RigidTransform poseAt(double t_s) const override { return {Quat::Identity(), velocity_ * t_s}; }

 private:
  Vec3 velocity_;
};

/// A 0.4 m square held by a fixture gliding at `below`'s velocity, and a free 0.1 m square
/// `height` above it with velocity `start`: the two garments stepped frame by frame, the one
/// below first. Calls look(t, over's solver, below's solver) after each frame.
struct TwoGarments {
  std::shared_ptr<const ClothModel> belowModel, overModel;
  std::unique_ptr<ClothSolver> belowSolver, overSolver;
  std::unique_ptr<LayerCollider> layers;
};

TwoGarments twoGarments(const Vec3& below, double height, double gap, double mu, bool keepApart) {
  SheetSpec lower{0.4, 0.4, 10, 10, Vec3(-0.2, 0, -0.2), Vec3::UnitX(), Vec3::UnitZ(), "lower"};
  SheetSpec upper{0.1, 0.1, 4, 4, Vec3(-0.05, height, -0.05), Vec3::UnitX(), Vec3::UnitZ(), "upper"};
  Material mat = knit();
  mat.damping_s = 1e-4;
  mat.staticFriction = 2 * mu;
  mat.dynamicFriction = mu;
  TwoGarments g;
  g.belowModel = makeModel(irregularSheet(lower, 0.3, 3), mat);
  g.overModel = makeModel(gridSheet(upper), mat);
  std::vector<std::uint32_t> all(g.belowModel->vertexCount());
  for (std::uint32_t v = 0; v < all.size(); ++v) all[v] = v;
  StepSettings settings = settingsWithStep(0.5 * g.overModel->estimatedStableStep_s());
  g.belowSolver = std::make_unique<ClothSolver>(
      g.belowModel, settings,
      std::vector<PinGroup>{PinGroup::atRest(all, g.belowModel->restX(), g.belowModel->restY(), g.belowModel->restZ(),
                                             std::make_shared<Gliding>(below))});
  g.overSolver = std::make_unique<ClothSolver>(g.overModel, settings);
  if (keepApart) {
    g.layers = std::make_unique<LayerCollider>(*g.overModel, "upper", 0.0);
    g.layers->addGarmentBelow(*g.belowModel, "lower", g.belowSolver->state(), gap, 1.0 / settings.frameRate_hz);
    g.layers->initialise(g.overSolver->state());
    g.overSolver->addCollider(*g.layers);
  }
  return g;
}

/// Frames 1..frames of both garments, the one below first; after each, `look(frame)`.
template <typename Look>
void stepBoth(TwoGarments& g, long frames, Look&& look) {
  for (long f = 1; f <= frames; ++f) {
    ASSERT_TRUE(g.belowSolver->stepFrame(f));
    ASSERT_TRUE(g.overSolver->stepFrame(f));
    look(f);
  }
}

TEST(GarmentBelow, ASheetOnARisingGarmentRidesOneGapAboveIt) {
  // The garment below rises 10 mm a frame, two and a half gaps: the sheet over it lands and is
  // carried up one gap above it at every frame, as it would be if the one below moved
  // smoothly (taken where it was at the frame's end, the sheet would ride up to 10 mm higher;
  // where it was at the start, it would sink through).
  const double gap = 0.004, rise = 0.3;
  TwoGarments g = twoGarments(Vec3(0, rise, 0), 0.03, gap, 0.3, true);
  double lowest = 1e9, highest = -1e9;
  stepBoth(g, 30, [&](long f) {
    if (f < 15) return;  // landed by then (it falls 30 mm while the one below rises)
    const double floor = rise * static_cast<double>(f) * kFrame_s;
    for (std::size_t v = 0; v < g.overModel->vertexCount(); ++v) {
      lowest = std::min(lowest, g.overSolver->state().y[v] - floor);
      highest = std::max(highest, g.overSolver->state().y[v] - floor);
    }
  });
  EXPECT_NEAR(lowest, gap, 0.1 * gap);
  EXPECT_NEAR(highest, gap, 0.1 * gap);
  EXPECT_GT(g.layers->layerCounters().contactsBelow, 0u);
  EXPECT_EQ(g.layers->layerCounters().contacts, 0u);  // none of its own layers: none kept

  // Without the collider it falls through.
  TwoGarments free = twoGarments(Vec3(0, rise, 0), 0.03, gap, 0.3, false);
  stepBoth(free, 30, [](long) {});
  for (std::size_t v = 0; v < free.overModel->vertexCount(); ++v) EXPECT_LT(free.overSolver->state().y[v], -0.5);
}

TEST(GarmentBelow, ASheetOnAGarmentSlidingAwayIsDraggedAtMuG) {
  // The garment below slides along x at 1 m/s under a sheet at rest one gap above it:
  // friction accelerates the sheet at mu g (it is still far slower than the one below).
  const double gap = 0.004;
  for (const double mu : {0.2, 0.4}) {
    TwoGarments g = twoGarments(Vec3(1.0, 0, 0), gap, gap, mu, true);
    std::vector<double> speeds;
    stepBoth(g, 6, [&](long f) {
      if (f != 2 && f != 6) return;
      double momentum = 0, mass = 0;
      for (std::size_t v = 0; v < g.overModel->vertexCount(); ++v) {
        momentum += g.overSolver->state().vx[v] * g.overModel->mass()[v];
        mass += g.overModel->mass()[v];
      }
      speeds.push_back(momentum / mass);
    });
    ASSERT_EQ(speeds.size(), 2u);
    const double acceleration = (speeds[1] - speeds[0]) / (4 * kFrame_s);
    EXPECT_NEAR(acceleration, mu * 9.81, 0.05 * mu * 9.81) << "mu " << mu;
  }
}

TEST(GarmentBelow, ACornerOfSmallWeightIsNotFlungOut) {
  // A triangle held at two corners (a waistband bound over another's) and a vertex below
  // pushing up into it near its held edge: only the free corner can move, at a twentieth of
  // the contact point's weight. The exact projection would lift it twenty times the
  // correction (40 mm in one test, and the cloth there explodes); it moves at most
  // LayerCollider::kMostLever times the correction per sweep, three sweeps a test.
  const double gap = 0.004, height = 0.002, weightOfFree = 0.05;
  mesh::TriMesh over;
  over.positions = {Vec3(0, height, 0), Vec3(0.1, height, 0), Vec3(0.05, height, 0.1)};
  over.triangles = {{0, 2, 1}};
  mesh::TriMesh below;
  below.positions = {Vec3(0.05, 0, weightOfFree * 0.1), Vec3(0.5, 0, 0.5), Vec3(0.6, 0, 0.5)};
  below.triangles = {{0, 2, 1}};
  const auto overModel = makeModel(over, knit()), belowModel = makeModel(below, knit());
  const ClothState belowState = stateAt(below.positions);
  LayerCollider collider(*overModel, "over", 0.0);
  collider.setFixedVertices({0, 1});
  collider.addGarmentBelow(*belowModel, "below", belowState, gap, kFrame_s);
  ClothState state = stateAt(over.positions);
  collider.initialise(state);
  collider.beginFrame();
  collider.collide(*overModel, 0.0, 1e-4, state);
  const double correction = gap - height, lift = state.y[2] - height;
  EXPECT_GT(lift, LayerCollider::kMostLever * correction);  // it moves out, over the sweeps
  EXPECT_LE(lift, 3 * LayerCollider::kMostLever * correction);
  EXPECT_EQ(state.y[0], height);  // held
  EXPECT_EQ(state.y[1], height);
  EXPECT_EQ(collider.layerCounters().contactsBelow, 1u);
}

TEST(GarmentBelow, SaysWhichVerticesStartUnderTheGarmentBelow) {
  // A sheet modelled one gap over another, the same waves: every vertex over it. Pushed
  // through it by half a gap, `pushed` of them start under it, which the layers would keep.
  std::mt19937 random(17);
  const double gap = 0.01;
  const mesh::TriMesh below = wavySheet(12, 0.0, 0.02, 0.0, 3, random);
  mesh::TriMesh over = below;
  for (Vec3& p : over.positions) p.y() += gap;
  const std::vector<std::uint32_t> pushed{15, 40, 41, 77, 120};
  for (const std::uint32_t v : pushed) over.positions[v].y() -= 1.5 * gap;
  const auto overModel = makeModel(over, knit()), belowModel = makeModel(below, knit());
  const ClothState belowState = stateAt(below.positions);
  LayerCollider collider(*overModel, "over", 0.0);
  collider.setFixedVertices({0, 1, 2});  // bound: never pushed, not counted
  collider.addGarmentBelow(*belowModel, "below", belowState, 0.004, kFrame_s);
  collider.initialise(stateAt(over.positions));
  const StartUnder& under = collider.startUnder();
  // The sheets' edges are over the other's edges: inside its triangles within the tolerance.
  EXPECT_EQ(under.over, over.positions.size() - 3);
  EXPECT_EQ(under.vertices, pushed.size());
  EXPECT_TRUE(std::find(pushed.begin(), pushed.end(), under.deepestVertex) != pushed.end());
  EXPECT_NEAR(under.deepest_m, 0.5 * gap, 0.25 * gap);  // the wave's slope tilts the faces

  // Modelled over it, none; and turned over as a whole (the garment under the other), the
  // few that poke out are the ones on the other side.
  LayerCollider clean(*overModel, "over", 0.0);
  clean.addGarmentBelow(*belowModel, "below", belowState, 0.004, kFrame_s);
  mesh::TriMesh lifted = below;
  for (Vec3& p : lifted.positions) p.y() += gap;
  clean.initialise(stateAt(lifted.positions));
  EXPECT_EQ(clean.startUnder().vertices, 0u);
  EXPECT_EQ(clean.startUnder().over, lifted.positions.size());
  mesh::TriMesh sunk = below;
  for (Vec3& p : sunk.positions) p.y() -= gap;
  for (const std::uint32_t v : pushed) sunk.positions[v].y() += 1.5 * gap;
  clean.initialise(stateAt(sunk.positions));
  EXPECT_EQ(clean.startUnder().vertices, pushed.size());
}

TEST(GarmentBelow, VerticesThatStartUnderItAreMovedOutOneGapOverIt) {
  std::mt19937 random(19);
  const double gap = 0.004;
  const mesh::TriMesh below = wavySheet(12, 0.0, 0.02, 0.0, 5, random);
  mesh::TriMesh over = below;
  for (Vec3& p : over.positions) p.y() += 2 * gap;
  const std::vector<std::uint32_t> pushed{20, 21, 60, 100};
  for (const std::uint32_t v : pushed) over.positions[v].y() -= 3 * gap;
  const auto overModel = makeModel(over, knit()), belowModel = makeModel(below, knit());
  const ClothState belowState = stateAt(below.positions);
  LayerCollider collider(*overModel, "over", 0.0);
  collider.addGarmentBelow(*belowModel, "below", belowState, gap, kFrame_s);
  ClothState state = stateAt(over.positions);
  state.setVelocity(20, Vec3(0, -1, 0));
  collider.initialise(state);
  ASSERT_TRUE(collider.belowWoundOneWay());
  EXPECT_EQ(collider.liftOver(state), pushed.size());
  EXPECT_EQ(collider.startUnder().vertices, pushed.size());  // what was modelled
  EXPECT_NEAR(collider.liftedOver().largest_m, 2 * gap, 0.5 * gap);
  // Each moved one gap over the garment below, at rest; the others where they were.
  const SurfaceHeight height(below);
  for (std::uint32_t v = 0; v < over.positions.size(); ++v) {
    const bool moved = std::find(pushed.begin(), pushed.end(), v) != pushed.end();
    if (moved) {
      EXPECT_NEAR(height.above(state.position(v)), gap, 0.1 * gap) << "vertex " << v;
      EXPECT_EQ(state.velocity(v), Vec3::Zero()) << "vertex " << v;
    } else {
      EXPECT_EQ(state.position(v), over.positions[v]) << "vertex " << v;
    }
  }
  // Found again from there: none under.
  LayerCollider again(*overModel, "over", 0.0);
  again.addGarmentBelow(*belowModel, "below", belowState, gap, kFrame_s);
  again.initialise(state);
  EXPECT_EQ(again.startUnder().vertices, 0u);

  // A garment below with a face wound the other way: its sides cannot be told; nothing moves.
  mesh::TriMesh mixed = below;
  std::swap(mixed.triangles[30][0], mixed.triangles[30][1]);
  const auto mixedModel = makeModel(mixed, knit());
  LayerCollider unsure(*overModel, "over", 0.0);
  unsure.addGarmentBelow(*mixedModel, "below", belowState, gap, kFrame_s);
  ClothState untouched = stateAt(over.positions);
  unsure.initialise(untouched);
  EXPECT_FALSE(unsure.belowWoundOneWay());
  EXPECT_EQ(unsure.liftOver(untouched), 0u);
  for (std::uint32_t v = 0; v < over.positions.size(); ++v) EXPECT_EQ(untouched.position(v), over.positions[v]);
}

TEST(GarmentBelow, WithTheBodyTheSideAwayFromItIsOver) {
  // A sheet modelled under another, a gap below it, but for three vertices poking out over
  // it; four more sunk six gaps deep. The body lies under both.
  std::mt19937 random(23);
  const double gap = 0.004;
  const mesh::TriMesh below = wavySheet(12, 0.0, 0.02, 0.0, 7, random);
  mesh::TriMesh over = below;
  for (Vec3& p : over.positions) p.y() -= gap;
  const std::vector<std::uint32_t> poking{15, 40, 77}, deep{50, 51, 90, 130};
  for (const std::uint32_t v : poking) over.positions[v].y() += 2 * gap;
  for (const std::uint32_t v : deep) over.positions[v].y() -= 5 * gap;
  std::vector<Vec3> body;
  for (int i = 0; i <= 20; ++i)
    for (int k = 0; k <= 20; ++k) body.emplace_back(0.05 * i, -0.15, 0.05 * k);
  const auto overModel = makeModel(over, knit()), belowModel = makeModel(below, knit());
  const ClothState belowState = stateAt(below.positions);
  const auto collider = [&](const std::shared_ptr<const ClothModel>& model, bool withBody) {
    auto c = std::make_unique<LayerCollider>(*overModel, "over", 0.0);
    c->addGarmentBelow(*model, "below", belowState, gap, kFrame_s);
    if (withBody) c->setBody(body);
    return c;
  };
  const std::size_t sunk = over.positions.size() - poking.size();

  // Without the body, the side most vertices start on is over: the three poking out are under.
  auto most = collider(belowModel, false);
  most->initialise(stateAt(over.positions));
  EXPECT_FALSE(most->sidesFromBody());
  EXPECT_EQ(most->startUnder().vertices, poking.size());

  // With it, all but those three are under; all but the deep four are moved out one gap over it.
  for (const bool wound : {true, false}) {
    SCOPED_TRACE(wound ? "faces below wound one way" : "a face below wound the other way");
    mesh::TriMesh faces = below;
    if (!wound) std::swap(faces.triangles[30][0], faces.triangles[30][1]);
    auto byBody = collider(makeModel(faces, knit()), true);
    ClothState state = stateAt(over.positions);
    byBody->initialise(state);
    EXPECT_TRUE(byBody->sidesFromBody());
    EXPECT_EQ(byBody->startUnder().vertices, sunk);
    EXPECT_TRUE(std::find(deep.begin(), deep.end(), byBody->startUnder().deepestVertex) != deep.end());
    EXPECT_NEAR(byBody->startUnder().deepest_m, 6 * gap, 1.5 * gap);
    EXPECT_EQ(byBody->liftOver(state), sunk - deep.size());
    EXPECT_EQ(byBody->liftedOver().leftUnder, deep.size());
    const SurfaceHeight height(below);
    std::size_t measured = 0;
    for (std::uint32_t v = 0; v < over.positions.size(); ++v) {
      const bool stays = std::find(deep.begin(), deep.end(), v) != deep.end() ||
                         std::find(poking.begin(), poking.end(), v) != poking.end();
      if (stays) {
        EXPECT_EQ(state.position(v), over.positions[v]) << "vertex " << v;
        continue;
      }
      const double h = height.above(state.position(v));
      if (std::isnan(h)) continue;  // moved along the tilted normal past the sheet's edge
      EXPECT_NEAR(h, gap, 0.1 * gap) << "vertex " << v;
      ++measured;
    }
    EXPECT_GT(measured, sunk - 48);  // all but a few on the edge

    // Those left under pass through the garment below: a deep one rising through it meets
    // nothing, where a vertex moved out over it and sinking through it is held.
    std::vector<Vec3> start, end;
    for (std::uint32_t v = 0; v < state.size(); ++v) start.push_back(state.position(v));
    start.insert(start.end(), below.positions.begin(), below.positions.end());
    end = start;
    end[deep[0]].y() += 0.05;
    end[100].y() -= 0.02;
    const ContactSet contacts = contactSet(byBody->findContacts(stateAt(start), stateAt(end)));
    const auto touches = [&](std::uint32_t v) {
      return std::any_of(contacts.begin(), contacts.end(), [&](const auto& c) { return std::get<0>(c) == v; });
    };
    EXPECT_FALSE(touches(deep[0]));
    EXPECT_TRUE(touches(100));
  }
}

TEST(GarmentBelow, AGapMustBeAPositiveLength) {
  SheetSpec spec{0.4, 0.4, 2, 2, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), "sheet"};
  const auto model = makeModel(gridSheet(spec), knit());
  const ClothState state = ClothState::atRest(*model);
  LayerCollider collider(*model, "jacket", 0.0);
  try {
    collider.addGarmentBelow(*model, "shirt", state, 0.0, kFrame_s);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("garment 'jacket': the gap over 'shirt', 0 m, must be a positive length"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace garment_below_test
}  // namespace drape::cloth
