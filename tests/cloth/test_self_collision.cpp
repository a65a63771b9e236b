// Self collision (cloth/layer_collider.hpp): the grid and the list kept between tests find
// the pairs brute force finds; a layer dropped on another comes to rest one thickness above
// it, a folded strip does not pass through itself (without the collider both pass through),
// and a layer sliding on another decelerates at mu g.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <tuple>

#include <fmt/format.h>

#include "cloth_fixture.hpp"
#include "drape/cloth/layer_collider.hpp"
#include "layer_fixture.hpp"

namespace drape::cloth {
namespace self_collision_test {

using testing::ContactSet;
using testing::carryAndWander;
using testing::contactSet;
using testing::everyPair;
using testing::joinedMeshes;
using testing::knit;
using testing::makeModel;
using testing::pinAt;
using testing::run;
using testing::settingsWithStep;

/// A sheet of `cells` x `cells` in the xz plane, folded in two across x = 0: the half with
/// u > 0.5 lies back over the other, `gap` above it, each point moved by up to `noise`.
mesh::TriMesh foldedSheet(int cells, double gap, double noise, std::mt19937& random) {
  SheetSpec spec{1.0, 0.5, cells, cells / 2, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), "folded"};
  mesh::TriMesh m = irregularSheet(spec, 0.3, random());
  std::uniform_real_distribution<double> jitter(-noise, noise);
  for (Vec3& p : m.positions) {
    const double u = p.x();
    p = Vec3(u < 0.5 ? u : 1.0 - u, u < 0.5 ? 0.0 : gap, p.z()) + Vec3(jitter(random), jitter(random), jitter(random));
  }
  return m;
}

ClothState statesAt(const mesh::TriMesh& m) { return testing::stateAt(m.positions); }

TEST(SelfCollision, TheGridFindsWhatBruteForceFinds) {
  std::mt19937 random(7);
  std::size_t total = 0, crossed = 0;
  for (int trial = 0; trial < 40; ++trial) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const int cells = 8 + 2 * static_cast<int>(unit(random) * 5);
    const double cell = 1.0 / cells, thickness = cell * (0.1 + 0.5 * unit(random));
    const mesh::TriMesh before = foldedSheet(cells, thickness * 2.0 * unit(random), 0.2 * thickness, random);
    mesh::TriMesh after = before;
    std::uniform_real_distribution<double> move(-0.4 * thickness, 0.4 * thickness);
    for (Vec3& p : after.positions) p += Vec3(move(random), move(random), move(random));
    const auto model = makeModel(before, knit());
    LayerCollider collider(*model, "folded", thickness);
    const ClothState s0 = statesAt(before), s1 = statesAt(after);

    const ContactSet grid = contactSet(collider.findContacts(s0, s1));
    const auto brute = everyPair(collider, before, s0, s1);
    std::string missing, extra;
    for (const auto& c : brute)
      if (!grid.count(c)) missing += fmt::format(" ({}, {})", std::get<0>(c), std::get<1>(c));
    for (const auto& c : grid)
      if (!brute.count(c)) extra += fmt::format(" ({}, {})", std::get<0>(c), std::get<1>(c));
    EXPECT_TRUE(missing.empty() && extra.empty()) << "trial " << trial << ": " << cells << " cells, thickness "
                                                  << thickness << "; missed:" << missing << "; extra:" << extra;
    total += brute.size();
    for (const auto& c : brute) crossed += std::get<3>(c);
  }
  // Enough contacts of both kinds that a wrong grid could not pass.
  EXPECT_GT(total, 1000u);
  EXPECT_GT(crossed, 50u);
}

TEST(SelfCollision, TheListKeptBetweenTestsFindsWhatBruteForceFinds) {
  // A folded sheet carried along (a walk's common motion, which keeps the list) while its
  // points wander, a few jump (which mends it) and, in the first run, all of them scatter
  // every tenth test (which makes it again), test after test.
  for (const bool scatter : {true, false}) {
    SCOPED_TRACE(scatter ? "scattered every tenth test" : "never scattered");
    std::mt19937 random(11);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const int cells = 12;
    const double thickness = 0.3 / cells;
    const mesh::TriMesh rest = foldedSheet(cells, thickness, 0.2 * thickness, random);
    const auto model = makeModel(rest, knit());
    LayerCollider collider(*model, "folded", thickness);
    ClothState before = statesAt(rest), now = before;
    collider.initialise(before);
    std::size_t total = 0;
    for (int test = 0; test < 120; ++test) {
      carryAndWander(now, test, thickness, random, scatter);
      const ContactSet kept = contactSet(collider.nextContacts(now));
      const auto brute = everyPair(collider, rest, before, now);
      EXPECT_EQ(kept, brute) << "test " << test;
      total += brute.size();
      before = now;
    }
    EXPECT_GT(total, 1000u);
    // Made again when the points had scattered, mended when a few had jumped.
    const LayerCounters& counts = collider.layerCounters();
    EXPECT_GE(counts.rebuilds, scatter ? 3u : 1u);
    EXPECT_LE(counts.rebuilds, scatter ? 13u : 1u);
    EXPECT_GE(counts.mends, 100u);
  }
}

TEST(SelfCollision, ExcludesTheTrianglesAroundAVertexAndItsNeighbours) {
  SheetSpec spec{0.8, 0.8, 8, 8, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), "sheet"};
  const auto model = makeModel(gridSheet(spec), knit());
  LayerCollider collider(*model, "sheet", 0.01);
  const std::uint32_t centre = sheetVertex(spec, 4, 4);
  std::size_t kept = 0;
  for (std::uint32_t t = 0; t < model->triangleCount(); ++t) {
    bool near = false;
    for (std::uint32_t c : model->triangles()[t])
      for (int di = -1; di <= 1; ++di)
        for (int dj = -1; dj <= 1; ++dj) near |= c == sheetVertex(spec, 4 + di, 4 + dj);
    // Every triangle with a corner in the centre's 3 x 3 block touches its one-ring, and
    // those are exactly the excluded ones (the grid's diagonals alternate).
    if (!collider.excluded(centre, t)) {
      ++kept;
      for (std::uint32_t c : model->triangles()[t]) EXPECT_NE(c, centre);
    }
    if (!near) {
      EXPECT_FALSE(collider.excluded(centre, t)) << "triangle " << t;
    }
  }
  EXPECT_GT(kept, 0u);
}

TEST(SelfCollision, ANarrowTestSaysWhichSideAndWhetherItCrossed) {
  const std::array<Vec3, 3> tri{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1)};  // normal -y
  const double h = 0.01;
  // Above (on -normal's side), coming within h: a contact on side -1, not crossed.
  auto c = layerContact(Vec3(0.2, 0.05, 0.2), Vec3(0.2, 0.005, 0.2), tri, tri, h);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->side, -1.0);
  EXPECT_FALSE(c->crossed);
  EXPECT_NEAR(c->weights[0], 0.6, 1e-12);
  EXPECT_NEAR(c->weights[1], 0.2, 1e-12);
  EXPECT_NEAR(c->weights[2], 0.2, 1e-12);
  // Through it: crossed, still side -1.
  c = layerContact(Vec3(0.2, 0.005, 0.2), Vec3(0.2, -0.02, 0.2), tri, tri, h);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->side, -1.0);
  EXPECT_TRUE(c->crossed);
  // Farther than h, or beside the triangle: none.
  EXPECT_FALSE(layerContact(Vec3(0.2, 0.05, 0.2), Vec3(0.2, 0.02, 0.2), tri, tri, h));
  EXPECT_FALSE(layerContact(Vec3(0.8, 0.05, 0.8), Vec3(0.8, 0.0, 0.8), tri, tri, h));
  // Staying on the other side, far below: none (another layer, not a crossing).
  EXPECT_FALSE(layerContact(Vec3(0.2, -0.05, 0.2), Vec3(0.2, -0.04, 0.2), tri, tri, h));
  // A triangle that turns over (a corner through the opposite edge) flips its normal, not the
  // side of a point a metre from it all along, although the point projects into it where the
  // linear distance says zero: none.
  const std::array<Vec3, 3> turned{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, -2)};
  EXPECT_FALSE(layerContact(Vec3(0.2, 1.0, -0.1), Vec3(0.2, 1.0, -0.1), tri, turned, h));
}

/// Two squares in one garment: a lower one held flat at y = 0 and a smaller free one `drop`
/// above it, falling for `seconds`. The upper square's lowest and highest vertex heights.
std::pair<double, double> dropLayer(double thickness, double seconds, bool selfCollision) {
  SheetSpec lower{0.4, 0.4, 10, 10, Vec3(-0.2, 0, -0.2), Vec3::UnitX(), Vec3::UnitZ(), "lower"};
  SheetSpec upper{0.3, 0.3, 9, 9, Vec3(-0.15, 0.03, -0.15), Vec3::UnitX(), Vec3::UnitZ(), "upper"};
  const mesh::TriMesh m = joinedMeshes(irregularSheet(lower, 0.3, 3), irregularSheet(upper, 0.3, 4));
  Material mat = knit();
  mat.damping_s = 1e-4;
  const auto model = makeModel(m, mat);
  std::vector<std::uint32_t> held(121);
  for (std::uint32_t v = 0; v < 121; ++v) held[v] = v;
  const StepSettings settings = settingsWithStep(0.5 * model->estimatedStableStep_s(), 0.02);
  ClothSolver solver(model, settings, {pinAt(*model, held)});
  LayerCollider collider(*model, "layers", thickness);
  collider.setFixedVertices(held);
  if (selfCollision) solver.addCollider(collider);
  EXPECT_TRUE(run(solver, static_cast<long>(seconds / settings.substep_s())));
  double lo = 1e9, hi = -1e9;
  for (std::size_t v = 121; v < m.positions.size(); ++v) {
    lo = std::min(lo, solver.state().y[v]);
    hi = std::max(hi, solver.state().y[v]);
  }
  if (selfCollision) {
    EXPECT_GT(collider.layerCounters().contacts, 0u);
  }
  return {lo, hi};
}

TEST(SelfCollision, ALayerDroppedOnAnotherRestsOneThicknessAboveIt) {
  const double h = 0.004;
  const auto [lo, hi] = dropLayer(h, 0.8, true);
  // Resting on the lower layer: every vertex within a tenth of h of h above it (gravity
  // draws it down by g dt^2 between tests, the collider lifts it back to h).
  EXPECT_NEAR(lo, h, 0.1 * h);
  EXPECT_NEAR(hi, h, 0.1 * h);
  // Without the collider the same layer falls through (0.03 m in 0.08 s; 0.8 s: ~3 m).
  const auto [loFree, hiFree] = dropLayer(h, 0.8, false);
  EXPECT_LT(hiFree, -1.0);
}

/// A strip bent in a U: its lower leg (0.4 m) held flat at y = 0, the fold a half circle of
/// radius 15 mm at x = 0.4, the upper leg (0.25 m) free, coming back over the lower. After
/// 0.3 s (it lands at about 0.1 s), the lowest height of the upper leg's vertices 5 cm or
/// more from the fold.
double foldedStripGap(double thickness, bool selfCollision, LayerCounters& counters) {
  const double legs = 0.4, upper = 0.25, radius = 0.015, arc = M_PI * radius, length = legs + arc + upper;
  SheetSpec spec{length, 0.1, 60, 6, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), "strip"};
  mesh::TriMesh m = gridSheet(spec);
  std::vector<std::uint32_t> held;
  for (std::uint32_t v = 0; v < m.positions.size(); ++v) {
    Vec3& p = m.positions[v];
    const double s = p.x();
    if (s <= legs) {
      held.push_back(v);
    } else if (s <= legs + arc) {
      const double a = (s - legs) / radius;
      p = Vec3(legs + radius * std::sin(a), radius * (1 - std::cos(a)), p.z());
    } else {
      p = Vec3(legs - (s - legs - arc), 2 * radius, p.z());
    }
  }
  Material mat = knit();
  mat.damping_s = 1e-4;
  const auto model = makeModel(m, mat);
  const StepSettings settings = settingsWithStep(0.5 * model->estimatedStableStep_s(), 0.02);
  ClothSolver solver(model, settings, {pinAt(*model, held)});
  LayerCollider collider(*model, "strip", thickness);
  collider.setFixedVertices(held);
  if (selfCollision) solver.addCollider(collider);
  EXPECT_TRUE(run(solver, static_cast<long>(0.3 / settings.substep_s())));
  counters = collider.layerCounters();
  double gap = 1e9;
  for (std::size_t v = 0; v < m.positions.size(); ++v)
    if (model->restX()[v] < legs - 0.05 && model->restY()[v] > radius) {
      gap = std::min(gap, solver.state().y[v]);
      if (selfCollision) {
        EXPECT_GT(solver.state().x[v], 0.0);  // still over the lower leg
      }
    }
  return gap;
}

TEST(SelfCollision, AFoldedStripDoesNotPassThroughItself) {
  const double h = 0.004;
  LayerCounters counters;
  // The upper leg sags onto the lower one and rests a thickness above it.
  const double gap = foldedStripGap(h, true, counters);
  EXPECT_GT(gap, 0.9 * h);
  EXPECT_LT(gap, 1.1 * h);
  // A vertex found through the other leg at a test is put back at once: a few in builds of
  // other arithmetic (none in the optimised one), against thousands of contacts.
  EXPECT_GT(counters.contacts, 1000u);
  EXPECT_LT(counters.crossings, counters.contacts / 1000 + 1);
  // Without: the upper leg goes through the lower one.
  EXPECT_LT(foldedStripGap(h, false, counters), -0.05);
}

/// A 0.1 m square resting one thickness above a held 0.4 m one, sliding along x at 0.5 m/s
/// from t = 0: its mean x velocity at `times`.
std::vector<double> slidingSpeeds(const std::vector<double>& times, double mu) {
  const double h = 0.004;
  SheetSpec lower{0.4, 0.4, 10, 10, Vec3(-0.2, 0, -0.2), Vec3::UnitX(), Vec3::UnitZ(), "lower"};
  SheetSpec upper{0.1, 0.1, 3, 3, Vec3(-0.15, h, -0.05), Vec3::UnitX(), Vec3::UnitZ(), "upper"};
  const mesh::TriMesh m = joinedMeshes(irregularSheet(lower, 0.3, 3), gridSheet(upper));
  Material mat = knit();
  mat.staticFriction = 2 * mu;
  mat.dynamicFriction = mu;
  const auto model = makeModel(m, mat);
  std::vector<std::uint32_t> held(121);
  for (std::uint32_t v = 0; v < 121; ++v) held[v] = v;
  const StepSettings settings = settingsWithStep(0.5 * model->estimatedStableStep_s());
  ClothSolver solver(model, settings, {pinAt(*model, held)});
  LayerCollider collider(*model, "layers", h);
  collider.setFixedVertices(held);
  solver.addCollider(collider);
  for (std::size_t v = 121; v < m.positions.size(); ++v) solver.mutableState().vx[v] = 0.5;
  std::vector<double> speeds;
  const double dt = settings.substep_s();
  long k = 0;
  for (const double t : times) {
    for (; static_cast<double>(k) * dt < t; ++k)
      EXPECT_TRUE(solver.substep(static_cast<double>(k) * dt, k / settings.substepsPerFrame + 1,
                                 static_cast<int>(k % settings.substepsPerFrame)));
    double sum = 0;
    for (std::size_t v = 121; v < m.positions.size(); ++v) sum += solver.state().vx[v] * model->mass()[v];
    double mass = 0;
    for (std::size_t v = 121; v < m.positions.size(); ++v) mass += model->mass()[v];
    speeds.push_back(sum / mass);
  }
  return speeds;
}

TEST(SelfCollision, ALayerSlidingOnAnotherDeceleratesAtMuG) {
  for (const double mu : {0.2, 0.4}) {
    const std::vector<double> v = slidingSpeeds({0.02, 0.08}, mu);
    const double deceleration = (v[0] - v[1]) / 0.06;
    EXPECT_NEAR(deceleration, mu * 9.81, 0.05 * mu * 9.81) << "mu " << mu;
  }
}

TEST(SelfCollision, AThicknessMustBeAPositiveLengthOrNone) {
  SheetSpec spec{0.4, 0.4, 2, 2, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), "sheet"};
  const auto model = makeModel(gridSheet(spec), knit());
  try {
    LayerCollider collider(*model, "skirt", -0.001);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("garment 'skirt': self-collision thickness -0.001 m must be 0 (none) or a "
                                         "positive length"),
              std::string::npos)
        << e.what();
  }
  // 0: its own layers are never tested against each other.
  const LayerCollider none(*model, "skirt", 0.0);
  for (std::uint32_t v = 0; v < model->vertexCount(); ++v)
    for (std::uint32_t t = 0; t < model->triangleCount(); ++t) EXPECT_EQ(none.pairThickness(v, t), 0.0);
}

}  // namespace self_collision_test
}  // namespace drape::cloth
