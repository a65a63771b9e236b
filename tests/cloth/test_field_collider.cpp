// Distance-field collision (paper section 4.3.3): the response at T2, the last-resort
// projection, friction, the backward entry trace and all nine state transitions.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <random>

#include <tbb/global_control.h>

#include "drape/cloth/field_collider.hpp"
#include "drape/cloth/model.hpp"
#include "drape/core/error.hpp"
#include "drape/field/shapes.hpp"
#include "drape/mesh/topology.hpp"

namespace drape::cloth {
namespace {

/// A body part moving with constant velocity from a start position.
class LinearMotion final : public FixtureMotion {
 public:
  LinearMotion(const Vec3& start, const Vec3& velocity) : start_(start), velocity_(velocity) {}
  [[nodiscard]] RigidTransform poseAt(double t) const override { return {Quat::Identity(), start_ + velocity_ * t}; }

 private:
  Vec3 start_, velocity_;
};

constexpr double kVoxel = 0.005;

field::DistanceField buildField(const mesh::TriMesh& m) {
  field::FieldSettings s;
  s.voxelSize_m = kVoxel;
  s.shell_m = 6 * kVoxel;
  return field::DistanceField::build(m, s);
}

/// A tiny garment (one triangle) whose vertex 0 the tests drive; the others sit far away.
struct Point {
  std::shared_ptr<const ClothModel> model;
  ClothState state;
  explicit Point(const Vec3& p0) {
    mesh::TriMesh m;
    m.positions = {p0, Vec3(50, 50, 50), Vec3(50.1, 50, 50)};
    m.triangles = {{0, 1, 2}};
    model = ClothModel::build(m, mesh::Topology::build(m), Material{});
    state = ClothState::atRest(*model);
  }
};

struct BodySetup {
  field::DistanceField field;
  std::vector<CollisionPart> parts;
  BodySetup(const mesh::TriMesh& body, std::shared_ptr<const FixtureMotion> motion) : field(buildField(body)) {
    parts.push_back({"body", &field, std::move(motion)});
  }
};

const OffsetSurfaces kOffsets = OffsetSurfaces::fromVoxelSize(kVoxel);

/// Initialises the collider with the point far from every part, then puts it at `at`: the
/// first test meets it there as a point that has just arrived (its contacts registered
/// there), not as one the garment starts in below T2 (which is eased out).
void initialiseArriving(FieldCollider& c, Point& p, const Vec3& at) {
  p.state.setPosition(0, Vec3(40, 40, 40));
  c.initialise(p.state, 0.0);
  p.state.setPosition(0, at);
}

TEST(FieldCollider, StopsOnT2AndNeverEndsBelowT0StaticField) {
  BodySetup s(field::makeSphere(0.1, Vec3::Zero(), 64, 32), std::make_shared<StaticMotion>());
  Point p(Vec3(0.3, 0.01, 0.0));
  FieldCollider c("test", s.parts, kOffsets, 0.0, 0.0);
  c.initialise(p.state, 0.0);
  const double dt = 1e-3;
  p.state.setVelocity(0, Vec3(-2.0, 0, 0));  // 2 mm per step towards the centre
  bool touched = false;
  for (int step = 0; step < 200; ++step) {
    p.state.setPosition(0, p.state.position(0) + p.state.velocity(0) * dt);
    c.collide(*p.model, step * dt, (step + 1) * dt, p.state);
    const double d = s.field.distanceAt(p.state.position(0));
    ASSERT_GE(d, kOffsets.t0_m) << "step " << step;
    if (c.state(0, 0) == PointState::OnSurf) {
      if (!touched) {
        EXPECT_NEAR(d, kOffsets.t2_m, 0.3 * kVoxel) << "stops on T2";
        const Vec3 n = s.field.normalAt(p.state.position(0));
        EXPECT_GE(p.state.velocity(0).dot(n), -1e-9) << "no inward normal velocity left";
      }
      touched = true;
    }
  }
  EXPECT_TRUE(touched);
  EXPECT_EQ(c.fieldCounters().vertexSubstepsInsideBody, 0u);
}

TEST(FieldCollider, StopsOnT2AndNeverEndsBelowT0MovingField) {
  // The sphere flies at a resting point at 3 m/s: both move in the world; the trace runs in
  // the sphere's frame.
  auto motion = std::make_shared<LinearMotion>(Vec3(-0.4, 0, 0), Vec3(3.0, 0, 0));
  BodySetup s(field::makeSphere(0.1, Vec3::Zero(), 64, 32), motion);
  Point p(Vec3(0.0, 0.02, 0.0));
  FieldCollider c("test", s.parts, kOffsets, 0.0, 0.0);
  c.initialise(p.state, 0.0);
  const double dt = 1e-3;
  bool touched = false;
  for (int step = 0; step < 150; ++step) {
    p.state.setPosition(0, p.state.position(0) + p.state.velocity(0) * dt);
    c.collide(*p.model, step * dt, (step + 1) * dt, p.state);
    const Vec3 local = motion->poseAt((step + 1) * dt).inverse().apply(p.state.position(0));
    const double d = s.field.distanceAt(local);
    ASSERT_GE(d, kOffsets.t0_m) << "step " << step;
    if (!touched && c.state(0, 0) == PointState::OnSurf) {
      touched = true;
      EXPECT_NEAR(d, kOffsets.t2_m, 0.3 * kVoxel);
      // Relative to the sphere, no inward normal velocity: the point is carried along.
      const Vec3 n = s.field.normalAt(local);
      EXPECT_GE((p.state.velocity(0) - Vec3(3.0, 0, 0)).dot(n), -1e-9);
    }
  }
  EXPECT_TRUE(touched);
}

/// `steps` symplectic Euler steps of `dt` from t0 of point 0 under gravity alone, the
/// collider answering each.
void slideUnderGravity(FieldCollider& c, Point& p, double t0, double dt, int steps) {
  for (int k = 0; k < steps; ++k) {
    const Vec3 v = p.state.velocity(0) + Vec3(0, -9.81, 0) * dt;
    p.state.setVelocity(0, v);
    p.state.setPosition(0, p.state.position(0) + v * dt);
    c.collide(*p.model, t0 + k * dt, t0 + (k + 1) * dt, p.state);
  }
}

TEST(FieldCollider, SlidingFrictionDeceleratesAtMuG) {
  // A large box whose top face is y = 0; the point slides on T2 at 1 m/s under gravity.
  BodySetup s(field::makeBox(Vec3(-0.5, -0.1, -0.5), Vec3(0.5, 0.0, 0.5)), std::make_shared<StaticMotion>());
  const double mu = 0.4, g = 9.81, dt = 1e-4;
  Point p(Vec3::Zero());
  FieldCollider c("test", s.parts, kOffsets, mu, mu);
  initialiseArriving(c, p, Vec3(-0.3, kOffsets.t2_m, 0.0));
  const double v0 = 1.0;
  p.state.setVelocity(0, Vec3(v0, 0, 0));
  const int steps = 1000;  // 0.1 s: expected speed loss mu g t = 0.392 m/s
  slideUnderGravity(c, p, 0.0, dt, steps);
  const double deceleration = (v0 - p.state.velocity(0).x()) / (steps * dt);
  EXPECT_NEAR(deceleration, mu * g, 0.05 * mu * g);
  EXPECT_NEAR(p.state.position(0).y(), kOffsets.t2_m, 0.5 * kVoxel);
}

TEST(FieldCollider, AFrameComputedAgainForgetsItsAttemptAndKeepsSliding) {
  // The solver computes an unstable frame again with more substeps (ClothSolver::stepFrame):
  // the collider goes back to the frame's start. A point sliding on a box's top at 1 m/s
  // keeps sliding with friction from the first test of the new attempt (not eased out nor
  // thrown onto T2), and the counters hold nothing of the attempt.
  BodySetup s(field::makeBox(Vec3(-0.5, -0.1, -0.5), Vec3(0.5, 0.0, 0.5)), std::make_shared<StaticMotion>());
  const double mu = 0.4, g = 9.81, dt = 1e-4;
  Point p(Vec3::Zero());
  FieldCollider c("test", s.parts, kOffsets, mu, mu);
  initialiseArriving(c, p, Vec3(-0.3, kOffsets.t2_m, 0.0));
  p.state.setVelocity(0, Vec3(1.0, 0, 0));
  const auto slide = [&](double t0, double step, int steps) { slideUnderGravity(c, p, t0, step, steps); };
  slide(0.0, dt, 300);
  const double t = 300 * dt;
  const ClothState start = p.state;
  c.beginFrame();
  const FieldCollisionCounters before = c.fieldCounters();
  const std::uint64_t callsBefore = c.counters().calls;
  slide(t, dt, 200);  // the attempt
  ASSERT_GT(c.fieldCounters().tests, before.tests);

  c.restartFrame(start, t);
  p.state = start;
  EXPECT_EQ(c.fieldCounters().tests, before.tests);
  EXPECT_EQ(c.fieldCounters().collisions, before.collisions);
  EXPECT_EQ(c.fieldCounters().transitions, before.transitions);
  EXPECT_EQ(c.counters().calls, callsBefore);
  EXPECT_EQ(c.state(0, 0), PointState::OnSurf);

  const int steps = 400;  // the frame again at half the substep: 0.02 s
  const double v0 = p.state.velocity(0).x();
  slide(t, dt / 2, steps);
  const double deceleration = (v0 - p.state.velocity(0).x()) / (steps * dt / 2);
  EXPECT_NEAR(deceleration, mu * g, 0.05 * mu * g);
  EXPECT_NEAR(p.state.position(0).y(), kOffsets.t2_m, 0.5 * kVoxel);
  const std::uint64_t testsPerCall = before.tests / 300;
  EXPECT_EQ(c.fieldCounters().tests, before.tests + static_cast<std::uint64_t>(steps) * testsPerCall);
  EXPECT_EQ(c.fieldCounters().embeddedAtStart, before.embeddedAtStart);
}

TEST(FieldCollider, APointPressedOntoT2GathersNoInwardVelocity) {
  // A point pressed into a sphere at 1,000 m/s^2 (a tight sleeve's tension on its vertex) at
  // a 35 us substep (945 per frame) from 40 directions. Each collision step puts it back on
  // T2, where the distance read may say it is a little above T2; it is in contact all the
  // same, and its inward velocity goes. (Before, it kept that velocity, which grew by a dt
  // every substep: 50 m/s in two frames of the walking dress at 945 substeps per frame.)
  BodySetup s(field::makeSphere(0.1, Vec3::Zero(), 64, 32), std::make_shared<StaticMotion>());
  const double dt = 1.0 / (30.0 * 945), press = 1000.0;
  std::mt19937 rng(5);
  std::normal_distribution<double> normal;
  double worst = 0.0;
  for (int trial = 0; trial < 40; ++trial) {
    const Vec3 dir = Vec3(normal(rng), normal(rng), normal(rng)).normalized();
    Point p(dir * (0.1 + kOffsets.t2_m));
    FieldCollider c("test", s.parts, kOffsets, 0.0, 0.0);
    c.initialise(p.state, 0.0);
    for (int step = 0; step < 2000; ++step) {
      const Vec3 in = -p.state.position(0).normalized();
      const Vec3 v = p.state.velocity(0) + press * dt * in;
      p.state.setVelocity(0, v);
      p.state.setPosition(0, p.state.position(0) + v * dt);
      c.collide(*p.model, step * dt, (step + 1) * dt, p.state);
      worst = std::max(worst, p.state.velocity(0).dot(in));
    }
    EXPECT_GE(s.field.distanceAt(p.state.position(0)), kOffsets.t1_m) << "direction " << trial;
  }
  // What one substep of pressing adds, and no more.
  // Where the distance read leaves the point above T2 it falls freely to T2 again: at most
  // through half a voxel (the contact plane's reach), sqrt(2 a h / 2) = 2.2 m/s, measured
  // 1.3 m/s; the inward velocity left to grow reached 18 m/s in these 2,000 substeps.
  EXPECT_LE(worst, std::sqrt(press * kVoxel));
}

TEST(FieldCollider, ContactPlanesFollowTheFieldWithinTheirReach) {
  // Wherever a point can slide (between T1 and T3 of a sphere and of a rounded tube), the
  // plane of a read answers for the trilinear field within its reach to a fraction of the
  // T1..T2 gap (measured: 0.15 to 0.17 of it, 5 mm voxels); the error is the cell-to-cell
  // change of the trilinear gradient and the offset surface's curvature. The offset-surface
  // normal in place of the gradient would miss by about half the gap.
  std::mt19937 rng(17);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const mesh::TriMesh& body : {field::makeSphere(0.06, Vec3::Zero(), 48, 24), field::makeRoundedTube(0.04, 0.03, 0.15, 24)}) {
    const field::DistanceField f = buildField(body);
    double largest = 0;
    int samples = 0;
    for (int k = 0; k < 20000 && samples < 2000; ++k) {
      const Vec3 c = Vec3(unit(rng) * (f.dims().nx - 1), unit(rng) * (f.dims().ny - 1), unit(rng) * (f.dims().nz - 1));
      const double d = f.distanceAtVoxel(c);
      if (d < kOffsets.t1_m || d > kOffsets.t3_m || !walkable(f, Vec3i(int(c.x() + 0.5), int(c.y() + 0.5), int(c.z() + 0.5))))
        continue;
      ++samples;
      const field::FieldJet jet = f.jetAtVoxel(c);
      const ContactPlane plane{c, jet.gradient, jet.sample.normal, jet.sample.distance_m};
      EXPECT_EQ(plane.distanceAt(c), d);
      for (int j = 0; j < 8; ++j) {
        const Vec3 direction = Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized();
        const Vec3 there = c + unit(rng) * ContactPlane::kReach_voxels * direction;
        ASSERT_TRUE(plane.reaches(there));
        largest = std::max(largest, std::abs(plane.distanceAt(there) - f.distanceAtVoxel(there)));
      }
    }
    EXPECT_EQ(samples, 2000);
    EXPECT_LT(largest, 0.25 * (kOffsets.t2_m - kOffsets.t1_m)) << "largest error " << largest << " m";
    EXPECT_FALSE(ContactPlane{}.reaches(Vec3::Zero()));  // no read yet: no plane
  }
}

TEST(FieldCollider, SlidingOnContactPlanesRespondsAsReadingTheField) {
  // A point pressed onto a sphere (gravity towards its centre) slides round it, tested by a
  // collider on contact planes; on every substep a second collider that reads the field on
  // every test gets the same input. Its answers differ by the planes' error only, most tests
  // need no read, and the point keeps to the sliding zone.
  BodySetup s(field::makeSphere(0.06, Vec3::Zero(), 48, 24), std::make_shared<StaticMotion>());
  FieldCollider planes("test", s.parts, kOffsets, 0.3, 0.2);
  FieldCollider reads("test", s.parts, kOffsets, 0.3, 0.2);
  reads.setContactPlanes(false);
  Point p(Vec3(0.0, 0.06 + kOffsets.t2_m + 0.001, 0.0));
  planes.initialise(p.state, 0.0);
  reads.initialise(p.state, 0.0);
  p.state.setVelocity(0, Vec3(0.6, 0.0, 0.2));
  const double dt = 5e-4;
  double apart = 0, lowest = 1e9, travelled = 0;
  for (int step = 0; step < 2000; ++step) {
    const Vec3 x = p.state.position(0);
    const Vec3 v = p.state.velocity(0) - 9.81 * dt * x.normalized();
    p.state.setVelocity(0, v);
    p.state.setPosition(0, x + v * dt);
    ClothState shadow = p.state;
    planes.collide(*p.model, step * dt, (step + 1) * dt, p.state);
    reads.collide(*p.model, step * dt, (step + 1) * dt, shadow);
    apart = std::max(apart, (p.state.position(0) - shadow.position(0)).norm());
    lowest = std::min(lowest, s.field.distanceAt(p.state.position(0)));
    travelled += (p.state.position(0) - x).norm();
  }
  EXPECT_GT(travelled, 0.1) << "the point must slide round the sphere";
  EXPECT_LT(apart, 0.25 * (kOffsets.t2_m - kOffsets.t1_m)) << "apart " << apart;
  EXPECT_GT(lowest, kOffsets.t1_m);
  const FieldCollisionCounters& c = planes.fieldCounters();
  EXPECT_EQ(reads.fieldCounters().planeEstimates, 0u);
  EXPECT_GT(reads.fieldCounters().planeReads, 1000u);
  // Over 0.1 m or more of sliding, a read every half voxel (2.5 mm) or so, not on every test.
  EXPECT_GT(c.planeEstimates, 5 * c.planeReads);
  EXPECT_GT(c.planeReads, static_cast<std::uint64_t>(0.5 * travelled / (ContactPlane::kReach_voxels * kVoxel)));
}

TEST(FieldCollider, BackwardTraceFindsTheFirstCrossing) {
  const field::DistanceField f = buildField(field::makeSphere(0.05, Vec3::Zero(), 32, 16));
  std::mt19937 rng(7);
  const auto& d = f.dims();
  std::uniform_int_distribution<int> ix(1, d.nx - 2), iy(1, d.ny - 2), iz(1, d.nz - 2);
  std::uniform_int_distribution<int> far(-40, 40);
  int checked = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Vec3i inside(ix(rng), iy(rng), iz(rng));
    const Vec3i outside(inside.x() + far(rng) * 3, inside.y() + far(rng) * 3, inside.z() + far(rng) * 3);
    if (walkable(f, outside) || !walkable(f, inside)) continue;
    // Brute force: every voxel of the same discrete line, scanned from the outside end.
    std::vector<Vec3i> line;
    walkVoxels(inside, outside, [&](const Vec3i& p) {
      line.push_back(p);
      return true;
    });
    Vec3i first(-1, -1, -1);
    for (auto it = line.rbegin(); it != line.rend(); ++it) {
      if (walkable(f, *it)) {
        first = *it;
        break;
      }
    }
    EXPECT_EQ(entryVoxel(f, inside, outside), first);
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

TEST(FieldCollider, WalkableIsExactlyNotBorder) {
  // walkable() is a range test standing in for the border flag: they must agree everywhere.
  const field::DistanceField f = buildField(field::makeBox(Vec3(-0.03, -0.05, -0.02), Vec3(0.03, 0.05, 0.02)));
  const auto& d = f.dims();
  for (int z = -1; z <= d.nz; ++z)
    for (int y = -1; y <= d.ny; ++y)
      for (int x = -1; x <= d.nx; ++x) {
        const bool inGrid = d.contains(x, y, z);
        ASSERT_EQ(walkable(f, Vec3i(x, y, z)), inGrid && !f.isBorder(f.index(x, y, z))) << x << " " << y << " " << z;
      }
}

TEST(FieldCollider, WalksBetweenWalkableVoxelsStayWalkable) {
  // What lets a sliding pair count its walk instead of walking it: between two walkable
  // voxels the walk visits one walkable voxel per step of its longest axis, never leaving.
  const field::DistanceField f = buildField(field::makeBox(Vec3(-0.03, -0.05, -0.02), Vec3(0.03, 0.05, 0.02)));
  const auto& d = f.dims();
  std::mt19937 rng(21);
  std::uniform_int_distribution<int> x(1, d.nx - 2), y(1, d.ny - 2), z(1, d.nz - 2), near(-5, 5);
  for (int k = 0; k < 5000; ++k) {
    const Vec3i a(x(rng), y(rng), z(rng));
    // Mostly short walks, as sliding points make, and some across the whole box.
    const Vec3i b = k % 4 ? (a + Vec3i(near(rng), near(rng), near(rng))).cwiseMax(1).cwiseMin(Vec3i(d.nx - 2, d.ny - 2, d.nz - 2))
                          : Vec3i(x(rng), y(rng), z(rng));
    ASSERT_TRUE(walkable(f, a) && walkable(f, b));
    int visited = 0;
    const int walked = walkVoxelsByTable(a, b, [&](const Vec3i& p) {
      ++visited;
      return walkable(f, p);
    });
    ASSERT_EQ(walked, (b - a).cwiseAbs().maxCoeff() + 1) << a.transpose() << " -> " << b.transpose();
    ASSERT_EQ(visited, walked);
  }
}

TEST(FieldCollider, BresenhamLinesAreConnectedAndEndWhereAsked) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> c(-20, 20);
  for (int trial = 0; trial < 500; ++trial) {
    const Vec3i a(c(rng), c(rng), c(rng)), b(c(rng), c(rng), c(rng));
    Vec3i prev = a, last = a;
    int count = 0;
    const int visited = walkVoxels(a, b, [&](const Vec3i& p) {
      if (count++ > 0) {
        EXPECT_LE((p - prev).cwiseAbs().maxCoeff(), 1);
      }
      prev = p;
      last = p;
      return true;
    });
    EXPECT_EQ(last, b);
    EXPECT_EQ(visited, (b - a).cwiseAbs().maxCoeff() + 1);
  }
}

// The lookup-table walk (the paper's alternative to Bresenham, used by the collider) visits
// exactly the Bresenham voxels: every offset within the table's reach and beyond it, from
// several starts, whole and stopped early at every voxel.
TEST(FieldCollider, TableWalkVisitsTheBresenhamVoxels) {
  const auto voxels = [](auto&& walk, const Vec3i& a, const Vec3i& b, int stopAfter) {
    std::vector<Vec3i> seen;
    const int visited = walk(a, b, [&](const Vec3i& p) {
      seen.push_back(p);
      return static_cast<int>(seen.size()) != stopAfter;
    });
    EXPECT_EQ(visited, static_cast<int>(seen.size()));
    return seen;
  };
  const auto bresenham = [](const Vec3i& a, const Vec3i& b, auto&& v) { return walkVoxels(a, b, v); };
  const auto table = [](const Vec3i& a, const Vec3i& b, auto&& v) { return walkVoxelsByTable(a, b, v); };
  const int r = kWalkTableReach + 2;  // beyond the table too
  int compared = 0;
  for (const Vec3i& a : {Vec3i(0, 0, 0), Vec3i(10, -3, 7), Vec3i(-5, 12, 40)})
    for (int z = -r; z <= r; ++z)
      for (int y = -r; y <= r; ++y)
        for (int x = -r; x <= r; ++x) {
          const Vec3i b = a + Vec3i(x, y, z);
          const std::vector<Vec3i> whole = voxels(bresenham, a, b, 0);
          ASSERT_EQ(voxels(table, a, b, 0), whole) << "offset " << x << " " << y << " " << z;
          for (int stop = 1; stop <= static_cast<int>(whole.size()); ++stop)
            ASSERT_EQ(voxels(table, a, b, stop), voxels(bresenham, a, b, stop));
          ++compared;
        }
  EXPECT_EQ(compared, 3 * (2 * r + 1) * (2 * r + 1) * (2 * r + 1));
}

TEST(FieldCollider, ExercisesAllNineTransitions) {
  BodySetup s(field::makeSphere(0.1, Vec3::Zero(), 48, 24), std::make_shared<StaticMotion>());
  const double dt = 1e-3;
  const double edge = s.field.bounds().max.x();  // the volume's edge along +x
  // Scripted end positions along +x, one substep each; the names say what each should do.
  struct Move {
    double x;
    PointState expected;
  };
  const std::vector<Move> moves = {
      {edge + 0.10, PointState::OutsideVol},  // O -> O
      {edge - 0.02, PointState::InsideVol},   // O -> I
      {edge - 0.01, PointState::InsideVol},   // I -> I
      {edge + 0.05, PointState::OutsideVol},  // I -> O
      {0.05, PointState::OnSurf},             // O -> S (enters and hits T2)
      {0.1 + kOffsets.t2_m, PointState::OnSurf},  // S -> S
      {0.1 + kOffsets.t3_m + 0.003, PointState::InsideVol},  // S -> I (beyond T3, inside the grid)
      {0.1 + kOffsets.t2_m - 0.002, PointState::OnSurf},    // I -> S
      {edge + 0.10, PointState::OutsideVol},  // S -> O
  };
  Point p(Vec3(edge + 0.2, 0.003, 0.001));
  FieldCollider c("test", s.parts, kOffsets, 0.0, 0.0);
  c.initialise(p.state, 0.0);
  for (std::size_t i = 0; i < moves.size(); ++i) {
    const Vec3 target(moves[i].x, 0.003, 0.001);
    p.state.setVelocity(0, (target - p.state.position(0)) / dt);
    p.state.setPosition(0, target);
    c.collide(*p.model, i * dt, (i + 1) * dt, p.state);
    EXPECT_EQ(c.state(0, 0), moves[i].expected) << "move " << i;
    p.state.setVelocity(0, Vec3::Zero());
  }
  const auto& t = c.fieldCounters().transitions;
  for (int from = 0; from < 3; ++from)
    for (int to = 0; to < 3; ++to) EXPECT_GT(t[from][to], 0u) << "transition " << from << " -> " << to;
}

/// A part that turns about an axis through a moving centre: rotation and translation both
/// change every substep, so the cull's transforms are exercised in full.
class TumblingMotion final : public FixtureMotion {
 public:
  TumblingMotion(const Vec3& start, const Vec3& velocity, const Vec3& axis, double rate)
      : start_(start), velocity_(velocity), axis_(axis.normalized()), rate_(rate) {}
  [[nodiscard]] RigidTransform poseAt(double t) const override {
    return {Quat(Eigen::AngleAxisd(rate_ * t, axis_)), start_ + velocity_ * t};
  }

 private:
  Vec3 start_, velocity_, axis_;
  double rate_;
};

/// A cloud of free points (no triangle uses them) for driving the collider directly.
ClothState cloudState(std::size_t n, std::mt19937& rng) {
  std::uniform_real_distribution<double> coord(-0.25, 0.25);
  ClothState s;
  for (std::size_t i = 0; i < n; ++i) {
    s.x.push_back(coord(rng));
    s.y.push_back(coord(rng));
    s.z.push_back(coord(rng));
  }
  for (auto* v : {&s.vx, &s.vy, &s.vz, &s.fx, &s.fy, &s.fz}) v->assign(n, 0.0);
  return s;
}

/// Runs two colliders over the same random points against three tumbling parts, the second
/// with `reference` applied (a shortcut switched off); every state, counter, position and
/// velocity must agree exactly after every substep. Returns the first's counters.
/// `sameWalks`: the voxels walked agree too (not so with resting balls, whose pairs are not
/// walked). `both`: applied to both colliders first.
template <typename Configure, typename ConfigureBoth = void (*)(FieldCollider&)>
FieldCollisionCounters expectSameAsReference(Configure&& reference, bool measure = true, bool sameWalks = true,
                                             ConfigureBoth both = [](FieldCollider&) {}) {
  const field::DistanceField sphere = buildField(field::makeSphere(0.06, Vec3::Zero(), 32, 16));
  const field::DistanceField box = buildField(field::makeBox(Vec3(-0.04, -0.1, -0.03), Vec3(0.04, 0.1, 0.03)));
  const field::DistanceField tube = buildField(field::makeRoundedTube(0.04, 0.03, 0.15, 24));
  // The last two come from afar: one into the cloud at the end, one never (out of the
  // points' reach, left out of tests while it is: FieldCollider::outOfReach).
  const std::vector<CollisionPart> parts = {
      {"sphere", &sphere, std::make_shared<TumblingMotion>(Vec3(-0.1, 0, 0), Vec3(0.8, 0.1, 0), Vec3(0, 1, 0), 3.0)},
      {"box", &box, std::make_shared<TumblingMotion>(Vec3(0.1, 0.05, 0), Vec3(-0.5, 0, 0.3), Vec3(1, 1, 0), -4.0)},
      {"tube", &tube, std::make_shared<TumblingMotion>(Vec3(0, -0.05, 0.1), Vec3(0, 0.4, -0.6), Vec3(0, 0, 1), 2.0)},
      {"visitor", &sphere, std::make_shared<TumblingMotion>(Vec3(-0.7, 0, 0), Vec3(1.8, 0, 0), Vec3(0, 0, 1), 1.0)},
      {"stranger", &box, std::make_shared<TumblingMotion>(Vec3(3, 0, 0), Vec3(0, 0, 0), Vec3(0, 1, 0), 1.0)}};
  const Point anchor(Vec3::Zero());  // a model for the collide() signature; the collider ignores it
  std::mt19937 rng(11);
  const std::size_t n = 600;
  ClothState fastState = cloudState(n, rng);
  ClothState fullState = fastState;
  FieldCollider fast("test", parts, kOffsets, 0.5, 0.3);
  FieldCollider full("test", parts, kOffsets, 0.5, 0.3);
  both(fast);
  both(full);
  reference(full);
  fast.setMeasurePenetration(measure);
  fast.initialise(fastState, 0.0);
  full.initialise(fullState, 0.0);
  std::normal_distribution<double> kick(0.0, 0.5);
  const double dt = 1e-3;
  for (int step = 0; step < 400; ++step) {
    // The same random velocity change for both clouds, pulled back towards the origin.
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 dv(kick(rng), kick(rng), kick(rng));
      for (ClothState* s : {&fastState, &fullState}) {
        const Vec3 v = s->velocity(i) + dv - 2.0 * s->position(i) * dt * 100;
        s->setVelocity(i, v);
        s->setPosition(i, s->position(i) + v * dt);
      }
    }
    fast.collide(*anchor.model, step * dt, (step + 1) * dt, fastState);
    full.collide(*anchor.model, step * dt, (step + 1) * dt, fullState);
    for (std::size_t k = 0; k < parts.size(); ++k)
      for (std::size_t i = 0; i < n; ++i) {
        EXPECT_EQ(fast.state(k, i), full.state(k, i)) << "step " << step << " part " << k << " vertex " << i;
        // Where the next walk starts (an OutsideVol pair's start follows from its velocity).
        const bool sameStart =
            fast.state(k, i) == PointState::OutsideVol || fast.cachedVoxel(k, i) == full.cachedVoxel(k, i);
        EXPECT_TRUE(sameStart) << "step " << step << " part " << k << " vertex " << i;
        if (fast.state(k, i) != full.state(k, i) || !sameStart) return fast.fieldCounters();
      }
    EXPECT_EQ(fastState.hash(), fullState.hash()) << "step " << step;
    if (fastState.hash() != fullState.hash()) return fast.fieldCounters();
  }
  const FieldCollisionCounters& a = fast.fieldCounters();
  const FieldCollisionCounters& b = full.fieldCounters();
  EXPECT_EQ(a.tests, b.tests);
  EXPECT_EQ(a.traces, b.traces);
  if (sameWalks) {
    EXPECT_EQ(a.traceVoxels, b.traceVoxels);
  }
  EXPECT_EQ(a.collisions, b.collisions);
  EXPECT_EQ(a.projections, b.projections);
  if (measure) {
    EXPECT_EQ(a.vertexSubstepsBelowT1, b.vertexSubstepsBelowT1);
    EXPECT_EQ(a.vertexSubstepsBelowT0, b.vertexSubstepsBelowT0);
    EXPECT_EQ(a.vertexSubstepsInsideBody, b.vertexSubstepsInsideBody);
    EXPECT_EQ(a.maxPenetration_m, b.maxPenetration_m);
  }
  EXPECT_EQ(a.transitions, b.transitions);
  EXPECT_EQ(a.planeEstimates, b.planeEstimates);
  // The scenario must exercise what it compares: entries, collisions, sliding.
  EXPECT_GT(a.transitions[0][1] + a.transitions[0][2], 100u);
  EXPECT_GT(a.collisions, 100u);
  EXPECT_GT(a.transitions[2][2], 100u);
  return a;
}

TEST(FieldCollider, BoxCullingChangesNothing) {
  // Culled pairs, and parts left out: the stranger at every test, the visitor until it came.
  const FieldCollisionCounters c = expectSameAsReference([](FieldCollider& full) { full.setBoxCulling(false); });
  EXPECT_GT(c.transitions[0][0], c.tests / 4);
  EXPECT_GT(c.partsOutOfReach, 400u + 20u);
  EXPECT_LT(c.partsOutOfReach, 2u * 400u);
}

/// At the origin from `arrives` to `leaves` (seconds), 3 m off along -x before and after:
/// a part that comes within the points' reach and goes out of it in one test each.
class VisitingMotion final : public FixtureMotion {
 public:
  VisitingMotion(double arrives, double leaves) : arrives_(arrives), leaves_(leaves) {}
  [[nodiscard]] RigidTransform poseAt(double t) const override {
    return {Quat::Identity(), t >= arrives_ && t < leaves_ ? Vec3(0, 0, 0) : Vec3(-3, 0, 0)};
  }

 private:
  double arrives_, leaves_;
};

TEST(FieldCollider, APartThatLeavesWithPointsInsideItIsTestedOnceMore) {
  // Points inside a sphere's volume between T2 and T3, on its +x side. The sphere comes from
  // 3 m along -x at the 11th test (the points' relative path, along x from far on the +x
  // side, meets no offset surface: nothing collides) and goes back at the 12th. That test
  // finds the sphere clear of the points' box but their pairs InsideVol: it must walk them
  // out (OutsideVol) before the part is left out again, not take the part for as idle as it
  // was before it came.
  const field::DistanceField f = buildField(field::makeSphere(0.06, Vec3::Zero(), 32, 16));
  const double dt = 1e-3;
  const std::vector<CollisionPart> parts = {
      {"visitor", &f, std::make_shared<VisitingMotion>(10.5 * dt, 11.5 * dt)}};
  ClothState s;
  const double r = 0.06 + 0.5 * (kOffsets.t2_m + kOffsets.t3_m);
  for (const double y : {-0.01, 0.0, 0.01})
    for (const double z : {-0.01, 0.0, 0.01}) {
      s.x.push_back(std::sqrt(r * r - y * y - z * z));
      s.y.push_back(y);
      s.z.push_back(z);
    }
  const std::size_t n = s.x.size();
  for (auto* v : {&s.vx, &s.vy, &s.vz, &s.fx, &s.fy, &s.fz}) v->assign(n, 0.0);
  const ClothState start = s;
  FieldCollider c("test", parts, kOffsets, 0.5, 0.3);
  c.initialise(s, 0.0);
  const Point anchor(Vec3::Zero());
  const auto test = [&](int step) { c.collide(*anchor.model, step * dt, (step + 1) * dt, s); };
  for (int step = 0; step < 10; ++step) test(step);
  EXPECT_EQ(c.fieldCounters().partsOutOfReach, 10u);
  test(10);
  for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(c.state(0, i), PointState::InsideVol) << "vertex " << i;
  test(11);
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(c.state(0, i), PointState::OutsideVol) << "vertex " << i;
  EXPECT_EQ(c.fieldCounters().partsOutOfReach, 10u) << "the test the sphere left at walked its pairs";
  for (int step = 12; step < 16; ++step) test(step);
  EXPECT_EQ(c.fieldCounters().partsOutOfReach, 14u);
  EXPECT_EQ(c.fieldCounters().collisions, 0u);
  EXPECT_EQ(s.hash(), start.hash()) << "nothing collided: nothing moved";
}

TEST(FieldCollider, ParallelRangesChangeNothing) {
  // Ranges of 64 of the 600 points (nine), run on two of TBB's threads, against one range.
  const tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
  expectSameAsReference([](FieldCollider& full) { full.setParallelRanges(0); }, true, true,
                        [](FieldCollider& both) { both.setParallelRanges(64, 0); });
}

TEST(FieldCollider, LargeGarmentsSplitIntoRangesOfWholeVectors) {
  const field::DistanceField sphere = buildField(field::makeSphere(0.06, Vec3::Zero(), 32, 16));
  const std::vector<CollisionPart> parts = {{"sphere", &sphere, std::make_shared<StaticMotion>()}};
  std::mt19937 rng(5);
  const auto rangesFor = [&](std::size_t n, std::size_t rangeVertices, std::size_t from) {
    FieldCollider c("test", parts, kOffsets, 0.5, 0.3);
    c.setParallelRanges(rangeVertices, from);
    c.initialise(cloudState(n, rng), 0.0);
    return c.ranges();
  };
  const std::size_t from = FieldCollider::kParallelFrom_vertices, size = FieldCollider::kRange_vertices;
  {
    const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    EXPECT_EQ(rangesFor(600, 64, 0), 1u);  // one thread: one range
  }
  const tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
  EXPECT_EQ(rangesFor(from - 1, size, from), 1u);
  EXPECT_EQ(rangesFor(from, size, from), from / size);
  EXPECT_EQ(rangesFor(2000, 256, from), 8u);   // 256 each, the last 208 (1792 .. 2000)
  EXPECT_EQ(rangesFor(600, 64, 0), 9u);        // the last 88
  EXPECT_EQ(rangesFor(600, 100, 0), 9u);       // rounded down to 64
  EXPECT_EQ(rangesFor(600, 10, 0), 9u);        // at least 64
  EXPECT_EQ(rangesFor(5000, 0, 0), 1u);        // 0: one range
}

TEST(FieldCollider, ClearanceBitsBoundTheTrilinearDistance) {
  // Anywhere in a voxel marked clear, the trilinear distance and the voxel's own are above
  // T2; and the marks reach down to within two voxels of T2 (the 3x3x3 neighbourhood).
  const BodySetup s(field::makeRoundedTube(0.04, 0.03, 0.15, 24), std::make_shared<StaticMotion>());
  const field::DistanceField& f = s.field;
  const FieldCollider c("test", s.parts, kOffsets, 0.5, 0.3);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> within(-0.5, 0.4999);
  const double t2Voxels = kOffsets.t2_m / kVoxel;
  std::size_t clear = 0;
  double lowestClear = 1e9;
  for (std::uint32_t v = 0; v < f.voxelCount(); ++v) {
    if (!c.clearOfT2(0, v)) continue;
    ++clear;
    ASSERT_TRUE(walkable(f, f.coordinates(v)));
    EXPECT_GT(f.distanceVoxels(v), t2Voxels);
    lowestClear = std::min(lowestClear, f.distanceVoxels(v));
    for (int k = 0; k < 4; ++k) {
      const Vec3 p = f.coordinates(v).cast<double>() + Vec3(within(rng), within(rng), within(rng));
      ASSERT_GT(f.distanceAtVoxel(p), kOffsets.t2_m) << "voxel " << v;
    }
  }
  EXPECT_GT(clear, 1000u);
  EXPECT_LT(lowestClear, t2Voxels + 2);
}

TEST(FieldCollider, FixedVerticesAreLeftOut) {
  // Fixtures move some vertices after the collider: it neither moves nor counts them, and
  // the free vertices come out exactly as without any fixed vertex (the collider treats
  // vertices independently).
  const BodySetup s(field::makeSphere(0.06, Vec3::Zero(), 32, 16),
                    std::make_shared<LinearMotion>(Vec3(-0.2, 0, 0), Vec3(2.0, 0, 0)));
  std::mt19937 rng(3);
  const std::size_t n = 400;
  ClothState withFixed = cloudState(n, rng);
  ClothState allFree = withFixed;
  std::vector<std::uint32_t> fixed;
  for (std::uint32_t i = 0; i < n; i += 3) fixed.push_back(i);
  FieldCollider a("test", s.parts, kOffsets, 0.5, 0.3);
  FieldCollider b("test", s.parts, kOffsets, 0.5, 0.3);
  a.setFixedVertices(fixed, n);
  a.initialise(withFixed, 0.0);
  b.initialise(allFree, 0.0);
  const Point anchor(Vec3::Zero());
  const double dt = 1e-3;
  for (int step = 0; step < 200; ++step) {
    const ClothState before = withFixed;
    a.collide(*anchor.model, step * dt, (step + 1) * dt, withFixed);
    b.collide(*anchor.model, step * dt, (step + 1) * dt, allFree);
    for (std::size_t i = 0; i < n; ++i) {
      if (i % 3 == 0) {
        ASSERT_EQ(withFixed.position(i), before.position(i)) << "fixed vertex " << i << " moved";
        ASSERT_EQ(withFixed.velocity(i), before.velocity(i));
        ASSERT_EQ(a.state(0, i), PointState::OutsideVol);
        // Keep the fixed vertices where the free run has them, so that both clouds agree.
        withFixed.setPosition(i, allFree.position(i));
        withFixed.setVelocity(i, allFree.velocity(i));
      } else {
        ASSERT_EQ(withFixed.position(i), allFree.position(i)) << "vertex " << i << " step " << step;
        ASSERT_EQ(a.state(0, i), b.state(0, i));
      }
    }
  }
  EXPECT_GT(b.fieldCounters().collisions, 20u) << "the sphere must sweep through the cloud";
  EXPECT_EQ(a.fieldCounters().vertexSubsteps, 200u * (n - fixed.size()));
  EXPECT_LT(a.fieldCounters().collisions, b.fieldCounters().collisions);
}

TEST(FieldCollider, CountingEverySubstepReadsTheUntestedOnesAndMovesNothing) {
  // With tests every third substep, counting every substep adds, on the two substeps between
  // tests, exactly the points a brute-force location finds inside the body, and changes no
  // point, state or test figure.
  // Fast enough (12 mm per substep) to overrun T2 between two tests.
  const auto motion = std::make_shared<LinearMotion>(Vec3(-0.4, 0, 0), Vec3(12.0, 0, 0));
  const BodySetup s(field::makeSphere(0.06, Vec3::Zero(), 32, 16), motion);
  std::mt19937 rng(5);
  const std::size_t n = 400;
  ClothState counted = cloudState(n, rng);
  ClothState plain = counted;
  FieldCollider a("test", s.parts, kOffsets, 0.5, 0.3, 3);
  FieldCollider b("test", s.parts, kOffsets, 0.5, 0.3, 3);
  a.setCountEverySubstep(true);
  a.initialise(counted, 0.0);
  b.initialise(plain, 0.0);
  const Point anchor(Vec3::Zero());
  const double dt = 1e-3;
  std::uint64_t untestedInside = 0, bruteForceInside = 0;
  for (int step = 0; step < 75; ++step) {
    const std::uint64_t before = a.fieldCounters().vertexSubstepsInsideBody;
    a.collide(*anchor.model, step * dt, (step + 1) * dt, counted);
    b.collide(*anchor.model, step * dt, (step + 1) * dt, plain);
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(counted.position(i), plain.position(i)) << "vertex " << i << " step " << step;
      ASSERT_EQ(counted.velocity(i), plain.velocity(i));
      ASSERT_EQ(a.state(0, i), b.state(0, i));
    }
    if (step % 3 == 0) continue;  // a tested substep: both count it the same way
    untestedInside += a.fieldCounters().vertexSubstepsInsideBody - before;
    const Vec3 centre = motion->poseAt((step + 1) * dt).translation;
    for (std::size_t i = 0; i < n; ++i) {
      const field::PointLocation l = s.field.locate(counted.position(i) - centre);
      bruteForceInside += l.inVolume && l.distance_m < 0;
    }
  }
  const FieldCollisionCounters &ca = a.fieldCounters(), &cb = b.fieldCounters();
  EXPECT_EQ(ca.vertexSubsteps, 75u * n);
  EXPECT_EQ(cb.vertexSubsteps, 25u * n);
  EXPECT_EQ(ca.collisions, cb.collisions);
  EXPECT_EQ(ca.tests, cb.tests);
  EXPECT_GT(bruteForceInside, 10u) << "the sphere must overrun points between the tests";
  EXPECT_EQ(untestedInside, bruteForceInside);
  EXPECT_EQ(ca.vertexSubstepsInsideBody - cb.vertexSubstepsInsideBody, untestedInside);
  EXPECT_GE(ca.maxPenetration_m, cb.maxPenetration_m);
}

TEST(FieldCollider, APointPinchedBetweenTwoPartsSettlesBetweenThem) {
  // Two boxes close on a resting point from either side until their faces are 10 mm apart,
  // closer than twice T2 (15 mm): no place is on both offset surfaces. Each part's correction
  // alone would put the point 5 mm inside the other box; their mean keeps it in the middle,
  // outside both.
  const field::DistanceField boxField = buildField(field::makeBox(Vec3(-0.1, -0.05, -0.05), Vec3(0.0, 0.05, 0.05)));
  const field::DistanceField mirrored = buildField(field::makeBox(Vec3(0.0, -0.05, -0.05), Vec3(0.1, 0.05, 0.05)));
  auto left = std::make_shared<LinearMotion>(Vec3(-0.03, 0, 0), Vec3(0.1, 0, 0));
  auto right = std::make_shared<LinearMotion>(Vec3(0.03, 0, 0), Vec3(-0.1, 0, 0));
  const std::vector<CollisionPart> parts = {{"left", &boxField, left}, {"right", &mirrored, right}};
  Point p(Vec3::Zero());
  FieldCollider c("test", parts, kOffsets, 0.0, 0.0);
  c.initialise(p.state, 0.0);
  EXPECT_TRUE(c.lastPinch(0).parts.empty()) << "30 mm from either box";
  const double dt = 1e-3;
  bool pinched = false;
  for (int step = 0; step < 250; ++step) {
    p.state.setPosition(0, p.state.position(0) + p.state.velocity(0) * dt);
    c.collide(*p.model, step * dt, (step + 1) * dt, p.state);
    const double t = (step + 1) * dt;
    const double x = p.state.position(0).x();
    const double leftFace = -0.03 + 0.1 * t, rightFace = 0.03 - 0.1 * t;
    ASSERT_GT(x, leftFace) << "inside the left box at step " << step;
    ASSERT_LT(x, rightFace) << "inside the right box at step " << step;
    if (rightFace - leftFace < 2 * kOffsets.t2_m) {
      pinched = true;
      EXPECT_NEAR(x, 0.5 * (leftFace + rightFace), 0.25 * (rightFace - leftFace)) << "step " << step;
    }
  }
  EXPECT_TRUE(pinched);
  EXPECT_EQ(c.state(0, 0), PointState::OnSurf);
  EXPECT_EQ(c.state(1, 0), PointState::OnSurf);
  // The middle of faces closer than 2 T1 is below T1 of both: every such substep counts as
  // pinched, and none before the boxes were close enough to press it from both sides.
  const FieldCollisionCounters& f = c.fieldCounters();
  EXPECT_GT(f.vertexSubstepsBelowT1, 10u);
  EXPECT_EQ(f.vertexSubstepsBelowT1Pinched, f.vertexSubstepsBelowT1);
  EXPECT_EQ(f.vertexSubstepsInsideBodyPinched, f.vertexSubstepsInsideBody);
  EXPECT_LT(f.pinchedVertexTests, 250u);
  EXPECT_GE(f.pinchedVertexTests, f.vertexSubstepsBelowT1Pinched);
  // What an instability report names: both parts, at the last test.
  EXPECT_EQ(c.lastPinch(0).parts, (std::vector<std::string>{"left", "right"}));
  EXPECT_EQ(c.lastPinch(0).substepsAgo, 0);
}

/// The projection of 0 onto the intersection of the half-spaces n . x >= d through `a` and
/// `b` (pinchMove's words), by Dykstra's alternating projections: a reference that knows
/// nothing of which half-space bounds the answer.
Vec3 dykstra(const Vec3& a, const Vec3& b) {
  const auto project = [](const Vec3& z, const Vec3& ask) {
    const Vec3 n = ask.normalized();
    return Vec3(z + std::max(0.0, ask.norm() - n.dot(z)) * n);
  };
  Vec3 x = Vec3::Zero(), p = Vec3::Zero(), q = Vec3::Zero();
  for (int k = 0; k < 200000; ++k) {
    const Vec3 y = project(x + p, a);
    p = x + p - y;
    const Vec3 next = project(y + q, b);
    q = y + q - next;
    const bool settled = (next - x).norm() < 1e-16;
    x = next;
    if (settled) break;
  }
  return x;
}

TEST(PinchMove, IsTheNearestPointOutsideBothOrNothingBeyondItsReach) {
  // Random asks of 0.1 to 10 mm in random directions up to 150 degrees apart (where the
  // alternating projections converge fast enough to be the reference): the move is
  // Dykstra's point whenever that lies within kCreaseReach times the longer ask, and
  // nothing otherwise.
  std::mt19937 rng(20261206);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> length(1e-4, 1e-2);
  int creases = 0, beyond = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const Vec3 na = Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized();
    Vec3 nb = Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized();
    if (na.dot(nb) < std::cos(150.0 * std::numbers::pi / 180.0)) nb = -nb;
    const Vec3 a = length(rng) * na, b = length(rng) * nb;
    const Vec3 reference = dykstra(a, b);
    const double longer = std::max(a.norm(), b.norm());
    const std::optional<Vec3> move = pinchMove(a, b);
    if (reference.norm() > kCreaseReach * longer * (1 + 1e-9)) {
      EXPECT_FALSE(move) << "trial " << trial;
      ++beyond;
      continue;
    }
    if (reference.norm() > kCreaseReach * longer * (1 - 1e-9)) continue;  // on the edge of its reach
    ASSERT_TRUE(move) << "trial " << trial;
    EXPECT_LT((*move - reference).norm(), 1e-9 * longer) << "trial " << trial;
    EXPECT_GE(move->dot(na), a.norm() * (1 - 1e-12)) << "trial " << trial;
    EXPECT_GE(move->dot(nb), b.norm() * (1 - 1e-12)) << "trial " << trial;
    creases += (*move - a).norm() > 1e-12 && (*move - b).norm() > 1e-12;  // both planes bound it
  }
  EXPECT_GT(creases, 500);
  EXPECT_GT(beyond, 100);
  // Two parts asking the same way: the longer ask, which satisfies both. Facing each other
  // (the thighs): nothing, the mean is the compromise. At right angles: the sum.
  const Vec3 x = Vec3::UnitX() * 0.004, y = Vec3::UnitY() * 0.003;
  EXPECT_EQ(pinchMove(x, 0.5 * x), x);
  EXPECT_FALSE(pinchMove(x, -0.5 * x));
  EXPECT_LT((*pinchMove(x, y) - (x + y)).norm(), 1e-15);
  EXPECT_FALSE(pinchMove(x, Vec3::Zero()));
}

TEST(FieldCollider, APointPressedIntoACreaseEndsOutsideBothParts) {
  // A wall (x < 0) and a floor (y < 0), two parts meeting at a right angle; something
  // throws the point into the corner at 1 m/s before every test. Each part asks to move it
  // back onto its T2: the crease move puts it on both, where the mean of the two asks left
  // it halfway, below T2 of each (the walking dress's crease of hip and lower back).
  const field::DistanceField wallField = buildField(field::makeBox(Vec3(-0.1, -0.1, -0.05), Vec3(0.0, 0.1, 0.05)));
  const field::DistanceField floorField = buildField(field::makeBox(Vec3(-0.1, -0.1, -0.05), Vec3(0.1, 0.0, 0.05)));
  const std::vector<CollisionPart> parts = {{"wall", &wallField, std::make_shared<StaticMotion>()},
                                            {"floor", &floorField, std::make_shared<StaticMotion>()}};
  const Vec3 into = Vec3(-1, -1, 0).normalized();
  for (const bool crease : {true, false}) {
    Point p(Vec3::Zero());
    FieldCollider c("test", parts, kOffsets, 0.0, 0.0);
    c.setCreaseMoves(crease);
    initialiseArriving(c, p, Vec3(0.03, 0.03, 0));
    const double dt = 1e-3;
    double lowest = 1.0;  // the lower of the two distances after the last 20 tests, m
    for (int step = 0; step < 60; ++step) {
      p.state.setVelocity(0, into);
      p.state.setPosition(0, p.state.position(0) + p.state.velocity(0) * dt);
      c.collide(*p.model, step * dt, (step + 1) * dt, p.state);
      const Vec3 at = p.state.position(0);
      if (step >= 40) lowest = std::min({lowest, wallField.distanceAt(at), floorField.distanceAt(at)});
    }
    ASSERT_EQ(c.state(0, 0), PointState::OnSurf) << crease;
    ASSERT_EQ(c.state(1, 0), PointState::OnSurf) << crease;
    if (crease) {
      EXPECT_NEAR(lowest, kOffsets.t2_m, 1e-6) << "on T2 of both";
      EXPECT_EQ(c.fieldCounters().vertexSubstepsBelowT1, 0u);
      EXPECT_GT(c.fieldCounters().creaseMoves, 40u);
      EXPECT_EQ(c.fieldCounters().creaseMovesRefused, 0u) << "planes: first order is exact";
    } else {
      // Each test moves it back by half of the 0.71 mm per axis it was thrown: it settles
      // that far below T2 of both.
      EXPECT_NEAR(lowest, kOffsets.t2_m - into.x() * -dt, 1e-5) << "halfway: below T2 of each";
    }
  }
}

/// A point 12 mm from each of two boxes that move together (closer than twice T2 apart),
/// tested every fourth substep; between tests something throws it towards
/// the left box at `throw_m_s` (the cloth's forces, in a garment). Returns the deepest it
/// went into either box (m, 0 if never) and checks what a held point must do.
double throwBetweenTests(bool hold, double throw_m_s, std::uint64_t* held = nullptr) {
  const field::DistanceField leftField = buildField(field::makeBox(Vec3(-0.1, -0.05, -0.05), Vec3(0.0, 0.05, 0.05)));
  const field::DistanceField rightField = buildField(field::makeBox(Vec3(0.0, -0.05, -0.05), Vec3(0.1, 0.05, 0.05)));
  const Vec3 velocity(0, 0.3, 0);
  // The boxes' fields put their faces' distance 2.5 mm outside the faces: 12 mm at 14.5 mm.
  const double apart = 0.0145;
  const std::vector<CollisionPart> parts = {
      {"left", &leftField, std::make_shared<LinearMotion>(Vec3(-apart, 0, 0), velocity)},
      {"right", &rightField, std::make_shared<LinearMotion>(Vec3(apart, 0, 0), velocity)}};
  Point p(Vec3::Zero());
  const int every = 4;
  FieldCollider c("test", parts, kOffsets, 0.0, 0.0, every);
  c.setPinchHold(hold);
  initialiseArriving(c, p, Vec3::Zero());
  EXPECT_EQ(c.fieldCounters().embeddedAtStart, 0u);
  const double dt = 1e-3;
  double deepest = 0;
  for (int step = 0; step < 40; ++step) {
    const bool tested = step % every == 0;
    if (!tested) p.state.setVelocity(0, Vec3(-throw_m_s, 0.3, 0));
    const Vec3 before = p.state.position(0);
    p.state.setPosition(0, before + p.state.velocity(0) * dt);
    c.collide(*p.model, step * dt, (step + 1) * dt, p.state);
    const double x = p.state.position(0).x();
    const Vec3 shift = velocity * (step + 1) * dt;
    deepest = std::max({deepest, -leftField.distanceAt(p.state.position(0) - Vec3(-apart, 0, 0) - shift),
                        -rightField.distanceAt(p.state.position(0) - Vec3(apart, 0, 0) - shift)});
    if (hold && !tested) {
      // Held where the test left it, moving with both boxes.
      EXPECT_NEAR(x, 0.0, 1e-9) << "step " << step;
      EXPECT_NEAR((p.state.position(0) - before - velocity * dt).norm(), 0.0, 1e-12) << "step " << step;
      EXPECT_NEAR((p.state.velocity(0) - velocity).norm(), 0.0, 1e-9) << "step " << step;
    }
    if (tested) {
      EXPECT_EQ(c.heldPoints(), hold ? 1u : 0u) << "step " << step;
    }
  }
  if (held) *held = c.fieldCounters().heldVertexSubsteps;
  return deepest;
}

TEST(FieldCollider, APointPinchedAtATestTakesItsPartsMeanVelocity) {
  // Two boxes 12 mm from a point (closer than twice T2), sliding past each other; the cloth
  // throws the point at the left one before every test. Each test moves it back and, with
  // the hold on, gives it the mean of the two boxes' velocities, whatever it came with.
  const field::DistanceField leftField = buildField(field::makeBox(Vec3(-0.1, -0.05, -0.05), Vec3(0.0, 0.05, 0.05)));
  const field::DistanceField rightField = buildField(field::makeBox(Vec3(0.0, -0.05, -0.05), Vec3(0.1, 0.05, 0.05)));
  const double apart = 0.0145;  // the faces' fields read 12 mm at 14.5 mm (see throwBetweenTests)
  const Vec3 leftVelocity(0, 0.3, 0), rightVelocity(0, 0.1, 0.2);
  const std::vector<CollisionPart> parts = {
      {"left", &leftField, std::make_shared<LinearMotion>(Vec3(-apart, 0, 0), leftVelocity)},
      {"right", &rightField, std::make_shared<LinearMotion>(Vec3(apart, 0, 0), rightVelocity)}};
  for (const bool hold : {true, false}) {
    Point p(Vec3::Zero());
    FieldCollider c("test", parts, kOffsets, 0.5, 0.3);
    c.setPinchHold(hold);
    initialiseArriving(c, p, Vec3::Zero());
    const double dt = 1e-3;
    for (int step = 0; step < 20; ++step) {
      p.state.setVelocity(0, p.state.velocity(0) + Vec3(-2.0, 0, 0));
      p.state.setPosition(0, p.state.position(0) + p.state.velocity(0) * dt);
      c.collide(*p.model, step * dt, (step + 1) * dt, p.state);
      const double toMean = (p.state.velocity(0) - 0.5 * (leftVelocity + rightVelocity)).norm();
      if (hold) {
        EXPECT_LT(toMean, 1e-9) << "step " << step;
      } else {
        EXPECT_GT(toMean, 0.1) << "step " << step;  // its own velocity, the parts' responses applied
      }
    }
    EXPECT_EQ(c.fieldCounters().pinchedVertexTests, hold ? 20u : 0u);
  }
}

TEST(FieldCollider, APointPinchedAtATestIsHeldByItsPartsUntilTheNext) {
  std::uint64_t held = 0;
  EXPECT_EQ(throwBetweenTests(true, 5.0, &held), 0.0);
  EXPECT_EQ(held, 30u);  // 10 tests, each followed by 3 untested substeps
  // Free between tests, 5 m/s carries it 15 mm in three substeps: 3 mm into the left box.
  EXPECT_GT(throwBetweenTests(false, 5.0), 0.002);
  EXPECT_LT(throwBetweenTests(false, 5.0), 0.004);
}

/// A frame that turns about an axis that itself turns (rotations at different times do not
/// commute) while it moves.
class WobblingMotion final : public FixtureMotion {
 public:
  [[nodiscard]] RigidTransform poseAt(double t) const override {
    const Quat q = Quat(Eigen::AngleAxisd(4.0 * t, Vec3::UnitZ())) * Quat(Eigen::AngleAxisd(6.0 * t, Vec3::UnitX()));
    return {q, Vec3(0.01 + 0.2 * t, 0.1 * t, 0)};
  }
};

TEST(FieldCollider, AHeldPointTurnsWithItsParts) {
  // Two boxes fixed in one frame that tumbles (turning and moving): a point pinched between
  // them at a test rides the frame's rigid motion exactly until the next, whatever throws
  // it: it stays where the test left it in the boxes' frame.
  const double apart = 0.011;
  const field::DistanceField leftField =
      buildField(field::makeBox(Vec3(-0.1 - apart, -0.05, -0.05), Vec3(-apart, 0.05, 0.05)));
  const field::DistanceField rightField =
      buildField(field::makeBox(Vec3(apart, -0.05, -0.05), Vec3(0.1 + apart, 0.05, 0.05)));
  const auto frame = std::make_shared<WobblingMotion>();
  const std::vector<CollisionPart> parts = {{"left", &leftField, frame}, {"right", &rightField, frame}};
  const Vec3 start(-0.0025, 0, 0);  // where both fields read 11 mm (their grids sit half a voxel apart)
  Point p(Vec3::Zero());
  const int every = 5;
  FieldCollider c("test", parts, kOffsets, 0.0, 0.0, every);
  initialiseArriving(c, p, frame->poseAt(0).apply(start));
  ASSERT_EQ(c.fieldCounters().embeddedAtStart, 0u);
  const double dt = 1e-3;
  Vec3 atTest = Vec3::Zero();  // in the boxes' frame
  for (int step = 0; step < 60; ++step) {
    const bool tested = step % every == 0;
    const Vec3 before = p.state.position(0);
    if (!tested) p.state.setVelocity(0, Vec3(3, -2, 1));
    p.state.setPosition(0, before + p.state.velocity(0) * dt);
    c.collide(*p.model, step * dt, (step + 1) * dt, p.state);
    const Vec3 local = frame->poseAt((step + 1) * dt).inverse().apply(p.state.position(0));
    EXPECT_GT(leftField.distanceAt(local), 0.0) << "step " << step;
    EXPECT_GT(rightField.distanceAt(local), 0.0) << "step " << step;
    if (tested) {
      ASSERT_EQ(c.state(0, 0), PointState::OnSurf) << "step " << step << ": " << leftField.distanceAt(local);
      ASSERT_EQ(c.state(1, 0), PointState::OnSurf) << "step " << step << ": " << rightField.distanceAt(local);
      ASSERT_EQ(c.heldPoints(), 1u) << "step " << step;
      atTest = local;
    } else {
      EXPECT_NEAR((local - atTest).norm(), 0.0, 1e-12) << "step " << step;
      const Vec3 expected = frame->poseAt((step + 1) * dt).apply(frame->poseAt(step * dt).inverse().apply(before));
      EXPECT_NEAR((p.state.velocity(0) - (expected - before) / dt).norm(), 0.0, 1e-9) << "step " << step;
    }
  }
  EXPECT_EQ(c.fieldCounters().heldVertexSubsteps, 48u);  // 12 tests, each followed by 4 untested substeps
}

TEST(FieldCollider, CountersOfTwoGarmentsAddUp) {
  FieldCollisionCounters a;
  std::uint64_t value = 1;
  for (std::uint64_t* f : {&a.tests, &a.traces, &a.traceVoxels, &a.collisions, &a.projections,
                           &a.vertexSubstepsBelowT1, &a.vertexSubstepsBelowT0, &a.vertexSubstepsInsideBody,
                           &a.vertexSubstepsBelowT1Pinched, &a.vertexSubstepsInsideBodyPinched, &a.vertexSubsteps,
                           &a.clearanceSkips, &a.embeddedAtStart, &a.planeEstimates, &a.planeReads,
                           &a.heldVertexSubsteps, &a.embeddedTimedOut, &a.restingSkips,
                           &a.pinchedVertexTests, &a.creaseMoves, &a.creaseMovesRefused, &a.faceTests,
                           &a.faceContacts, &a.facesInsideBody})
    *f = value++;
  for (auto& row : a.transitions)
    for (std::uint64_t& t : row) t = value++;
  a.maxPenetration_m = 0.002;
  FieldCollisionCounters b;
  b.maxPenetration_m = 0.003;
  b += a;
  b += a;
  const FieldCollisionCounters& c = b;
  value = 1;
  for (const std::uint64_t* f : {&c.tests, &c.traces, &c.traceVoxels, &c.collisions, &c.projections,
                                 &c.vertexSubstepsBelowT1, &c.vertexSubstepsBelowT0, &c.vertexSubstepsInsideBody,
                                 &c.vertexSubstepsBelowT1Pinched, &c.vertexSubstepsInsideBodyPinched, &c.vertexSubsteps,
                                 &c.clearanceSkips, &c.embeddedAtStart, &c.planeEstimates,
                                 &c.planeReads, &c.heldVertexSubsteps, &c.embeddedTimedOut, &c.restingSkips,
                                 &c.pinchedVertexTests, &c.creaseMoves, &c.creaseMovesRefused, &c.faceTests,
                                 &c.faceContacts, &c.facesInsideBody})
    EXPECT_EQ(*f, 2 * value++);
  for (const auto& row : c.transitions)
    for (const std::uint64_t t : row) EXPECT_EQ(t, 2 * value++);
  EXPECT_EQ(c.maxPenetration_m, 0.003);  // the deepest, not a sum
  EXPECT_DOUBLE_EQ(c.slidingReadsFromPlanes(), 14.0 / (14.0 + 15.0));
}

TEST(FieldCollider, MeasuringPenetrationMovesNothing) {
  // The same cloud and parts with the penetration figures kept and not kept: the same
  // states, positions and velocities after every substep, and no figure when not kept.
  const FieldCollisionCounters unmeasured = expectSameAsReference([](FieldCollider&) {}, false);
  EXPECT_EQ(unmeasured.vertexSubsteps, 0u);
  EXPECT_EQ(unmeasured.vertexSubstepsBelowT1, 0u);
  EXPECT_EQ(unmeasured.maxPenetration_m, 0.0);
}

TEST(FieldCollider, RestingBallsChangeNothing) {
  const FieldCollisionCounters c =
      expectSameAsReference([](FieldCollider& full) { full.setRestingBalls(false); }, true, false);
  EXPECT_GT(c.restingSkips, c.transitions[1][1] / 4);  // pairs the cull left out as resting
}

TEST(FieldCollider, APairLeavingItsBallWalksFromWhereTheFullTestWould) {
  // A point rests far above a sphere, moves within its ball at the next test, and then
  // dives through T2: the full test walks from where it was at the test before (not from
  // where it came to rest), and the contact point along that walk is where it stops.
  field::FieldSettings settings;
  settings.voxelSize_m = kVoxel;
  settings.shell_m = 6 * kVoxel;
  settings.borderVoxels = 24;  // room far above the sphere
  const field::DistanceField sphere = field::DistanceField::build(field::makeSphere(0.1, Vec3::Zero(), 64, 32), settings);
  const std::vector<CollisionPart> parts = {{"sphere", &sphere, std::make_shared<StaticMotion>()}};
  const Vec3 rest(0, 0.165, 0), within(0.02, 0.165, 0), dive(-0.02, 0.1, 0);
  Point resting(rest), full(rest);
  FieldCollider balls("test", parts, kOffsets, 0.5, 0.3);
  FieldCollider reference("test", parts, kOffsets, 0.5, 0.3);
  reference.setRestingBalls(false);
  balls.initialise(resting.state, 0.0);
  reference.initialise(full.state, 0.0);
  const Vec3 path[] = {rest, within, dive};
  for (int step = 0; step < 3; ++step) {
    for (Point* p : {&resting, &full}) p->state.setPosition(0, path[step]);
    balls.collide(*resting.model, step * 1e-3, (step + 1) * 1e-3, resting.state);
    reference.collide(*full.model, step * 1e-3, (step + 1) * 1e-3, full.state);
  }
  EXPECT_EQ(balls.fieldCounters().restingSkips, 1u);  // the second test
  EXPECT_EQ(balls.fieldCounters().collisions, 1u);
  EXPECT_EQ(balls.state(0, 0), PointState::OnSurf);
  EXPECT_EQ(resting.state.position(0), full.state.position(0));
  EXPECT_GT(resting.state.position(0).x(), -0.02);  // stopped on the way in, on T2
  EXPECT_NEAR(resting.state.position(0).norm(), 0.115, 0.002);
}

TEST(FieldCollider, RestingBallsAreClearOfT2AndInsideTheWalkableBox) {
  // Anywhere in a resting ball: the point's voxel is walkable, the trilinear distance is not
  // below T2, and a walk to it from the ball's centre meets no voxel below T2. On the DVDP
  // fields of three shapes with a wide border (distances beyond the shell, where DVDP is
  // approximate) and on an exact field.
  std::mt19937 rng(17);
  const double t2Voxels = kOffsets.t2_m / kVoxel;
  const auto check = [&](const mesh::TriMesh& body, field::FieldMethod method) {
    field::FieldSettings settings;
    settings.voxelSize_m = kVoxel;
    settings.shell_m = 6 * kVoxel;
    settings.borderVoxels = 24;
    settings.method = method;
    const field::DistanceField f = field::DistanceField::build(body, settings);
    const std::vector<CollisionPart> parts = {{"body", &f, std::make_shared<StaticMotion>()}};
    const FieldCollider c("test", parts, kOffsets, 0.5, 0.3);
    const field::GridDims& d = f.dims();
    std::uniform_real_distribution<double> x(0.5, d.nx - 1.5), y(0.5, d.ny - 1.5), z(0.5, d.nz - 1.5);
    std::normal_distribution<double> gauss(0.0, 1.0);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::size_t balls = 0;
    double largest = 0, tightest = 1e9;
    for (int trial = 0; trial < 4000; ++trial) {
      const Vec3 centre(x(rng), y(rng), z(rng));
      const double r = c.restingRadius(0, centre);
      if (r <= 0) continue;
      ++balls;
      largest = std::max(largest, r);
      // Brute force: every voxel below T2 (the body's inside too) lies beyond the ball by
      // the reach of a trilinear blend, sqrt(3) voxels.
      const int reach = static_cast<int>(std::ceil(r + 2));
      double nearestBelow = 1e9;
      for (int zz = -reach; zz <= reach; ++zz)
        for (int yy = -reach; yy <= reach; ++yy)
          for (int xx = -reach; xx <= reach; ++xx) {
            const Vec3i u = Vec3i(static_cast<int>(std::floor(centre.x())), static_cast<int>(std::floor(centre.y())),
                                  static_cast<int>(std::floor(centre.z()))) +
                            Vec3i(xx, yy, zz);
            if (u.x() < 0 || u.y() < 0 || u.z() < 0 || u.x() >= d.nx || u.y() >= d.ny || u.z() >= d.nz) continue;
            if (f.distanceVoxels(f.index(u.x(), u.y(), u.z())) >= t2Voxels) continue;
            nearestBelow = std::min(nearestBelow, (u.cast<double>() - centre).norm());
          }
      ASSERT_GE(nearestBelow, r + std::sqrt(3.0)) << "centre " << centre.transpose() << " r " << r;
      tightest = std::min(tightest, nearestBelow - r - std::sqrt(3.0));
      for (int k = 0; k < 8; ++k) {
        const Vec3 dir = Vec3(gauss(rng), gauss(rng), gauss(rng)).normalized();
        const Vec3 p = centre + r * std::cbrt(unit(rng)) * 0.999999 * dir;  // uniform in the ball
        const Vec3i end(static_cast<int>(std::floor(p.x() + 0.5)), static_cast<int>(std::floor(p.y() + 0.5)),
                        static_cast<int>(std::floor(p.z() + 0.5)));
        ASSERT_TRUE(walkable(f, end)) << "centre " << centre.transpose() << " r " << r;
        ASSERT_GE(f.distanceAtVoxel(p), kOffsets.t2_m) << "centre " << centre.transpose() << " r " << r;
        const Vec3i start(static_cast<int>(std::floor(centre.x() + 0.5)),
                          static_cast<int>(std::floor(centre.y() + 0.5)),
                          static_cast<int>(std::floor(centre.z() + 0.5)));
        walkVoxelsByTable(start, end, [&](const Vec3i& v) {
          EXPECT_GE(f.distanceVoxels(f.index(v.x(), v.y(), v.z())), t2Voxels) << "voxel " << v.transpose();
          return true;
        });
      }
    }
    // Most of these grids is far from the body: many balls, some of several voxels; and the
    // bound is not loose everywhere.
    EXPECT_GT(balls, 1000u);
    EXPECT_GT(largest, 5.0);
    EXPECT_LT(tightest, 1.5);
  };
  check(field::makeSphere(0.06, Vec3::Zero(), 32, 16), field::FieldMethod::Dvdp);
  check(field::makeBox(Vec3(-0.04, -0.1, -0.03), Vec3(0.04, 0.1, 0.03)), field::FieldMethod::Dvdp);
  check(field::makeRoundedTube(0.04, 0.03, 0.15, 24), field::FieldMethod::Dvdp);
  check(field::makeRoundedTube(0.04, 0.03, 0.15, 24), field::FieldMethod::Exact);
}

TEST(FieldCollider, ClearanceSkipChangesNothing) {
  // Without resting balls in either: the reference, reading every distance, would give balls
  // to the pairs the skip settles in their voxels, and walk less. The skip also sends the
  // sliding pairs their contact planes answer through slideOnPlane instead of the general
  // test, so this compares the two paths too.
  const FieldCollisionCounters c = expectSameAsReference(
      [](FieldCollider& full) { full.setClearanceSkip(false); }, true, true,
      [](FieldCollider& both) { both.setRestingBalls(false); });
  EXPECT_GT(c.clearanceSkips, c.transitions[1][1] / 4);  // pairs that stayed InsideVol unread
}

TEST(FieldCollider, PointsStartingBelowT2AreEasedOutNotThrown) {
  // A garment modelled tight on the body starts below T2: 1 mm from a sphere whose T1 is
  // 10 mm, or 12 mm from it, between T1 and T2 (15 mm). It rises at the easing speed, never
  // in one jump, and then slides on T2.
  BodySetup s(field::makeSphere(0.1, Vec3::Zero(), 64, 32), std::make_shared<StaticMotion>());
  for (const double gap : {0.001, 0.012}) {
    Point p(Vec3(0.1 + gap, 0.0, 0.0));
    FieldCollider c("test", s.parts, kOffsets, 0.0, 0.0);
    c.initialise(p.state, 0.0);
    EXPECT_EQ(c.fieldCounters().embeddedAtStart, 1u);
    const double dt = 1e-3;
    const double easing_m_s = 0.1;
    double previous = s.field.distanceAt(p.state.position(0));
    int steps = 0;
    for (; steps < 1000 && c.state(0, 0) != PointState::OnSurf; ++steps) {
      p.state.setVelocity(0, Vec3(-0.5, 0, 0));  // pressed inwards every substep
      c.collide(*p.model, steps * dt, (steps + 1) * dt, p.state);
      const double d = s.field.distanceAt(p.state.position(0));
      EXPECT_LE(d - previous, easing_m_s * dt * 1.05 + 1e-9) << "gap " << gap << ", step " << steps << ": no jump";
      EXPECT_GE(d, previous - 1e-9) << "gap " << gap << ", step " << steps << ": never deeper";
      EXPECT_GE(p.state.velocity(0).dot(s.field.normalAt(p.state.position(0))), -1e-4) << "no inward velocity";
      previous = d;
    }
    EXPECT_EQ(c.state(0, 0), PointState::OnSurf);
    EXPECT_NEAR(previous, kOffsets.t2_m, 0.2 * kVoxel);
    // 14 mm at 0.1 m/s: about 140 substeps of 1 ms; 3 mm: about 30.
    EXPECT_NEAR(steps, (kOffsets.t2_m - gap) / (easing_m_s * dt), 20) << "gap " << gap;
    EXPECT_EQ(c.fieldCounters().vertexSubstepsInsideBody, 0u);
  }
}

TEST(FieldCollider, APointHeldBelowT2WhileEasedCollidesAsAnyOtherInTime) {
  // A point that starts near a sphere's surface, below T1 (10 mm; T2 = 15 mm), and that the
  // garment puts back where it started on every substep (tied to bound vertices inside the
  // part): eased, it would never reach T2. After twice the time its depth below T2 takes at
  // the easing speed it collides as any other: the next test moves it out.
  BodySetup s(field::makeSphere(0.1, Vec3::Zero(), 64, 32), std::make_shared<StaticMotion>());
  const Vec3 start(0.101, 0.0, 0.0);
  Point p(start);
  FieldCollider c("test", s.parts, kOffsets, 0.0, 0.0);
  c.initialise(p.state, 0.0);
  ASSERT_EQ(c.fieldCounters().embeddedAtStart, 1u);
  const double dt = 1e-3;
  const double d0 = s.field.distanceAt(start);  // the field's reading: 2.7 mm
  ASSERT_LT(d0, kOffsets.t1_m);
  const int deadline = static_cast<int>(std::ceil(2.0 * (kOffsets.t2_m - d0) / 0.1 / dt));  // 246 substeps
  int step = 0;
  for (; step < 400 && c.fieldCounters().embeddedTimedOut == 0; ++step) {
    p.state.setPosition(0, start);
    p.state.setVelocity(0, Vec3::Zero());
    c.collide(*p.model, step * dt, (step + 1) * dt, p.state);
    EXPECT_LT(s.field.distanceAt(p.state.position(0)), d0 + 0.1 * dt * 1.05) << "step " << step << ": eased";
  }
  EXPECT_NEAR(step, deadline, 1);
  EXPECT_EQ(c.fieldCounters().embeddedTimedOut, 1u);
  EXPECT_EQ(c.state(0, 0), PointState::OnSurf);
  p.state.setPosition(0, start);
  c.collide(*p.model, step * dt, (step + 1) * dt, p.state);
  // Below T0, the last resort: projected along the normal towards T2 in one step (a step
  // of the field's normal from 2.7 mm lands at 12 mm), out of the penalty zone.
  EXPECT_EQ(c.fieldCounters().projections, 1u);
  EXPECT_GT(s.field.distanceAt(p.state.position(0)), kOffsets.t1_m);
}

/// An L-shaped prism: the square [0, 2u] x [0, 2u] less its corner [u, 2u] x [u, 2u], from
/// z = -u to u. Its inner edge, the line x = y = u, is concave: the field's normal turns by a
/// right angle around it.
mesh::TriMesh makeLPrism(double u) {
  const std::array<Vec3, 6> outline = {Vec3(0, 0, 0), Vec3(2 * u, 0, 0), Vec3(2 * u, u, 0),
                                       Vec3(u, u, 0),  Vec3(u, 2 * u, 0), Vec3(0, 2 * u, 0)};  // anticlockwise
  mesh::TriMesh m;
  for (const Vec3& p : outline) m.positions.push_back(p - Vec3(0, 0, u));
  for (const Vec3& p : outline) m.positions.push_back(p + Vec3(0, 0, u));
  for (std::uint32_t i = 1; i + 1 < 6; ++i) {  // the caps, fanned from the convex corner 0
    m.triangles.push_back({0, i + 1, i});
    m.triangles.push_back({6, 6 + i, 6 + i + 1});
  }
  for (std::uint32_t i = 0; i < 6; ++i) {  // the sides, facing out
    const std::uint32_t j = (i + 1) % 6;
    m.triangles.push_back({i, j, 6 + j});
    m.triangles.push_back({i, 6 + j, 6 + i});
  }
  return m;
}

TEST(FieldCollider, ALongProjectionReadsTheFieldAgainWhereItLands) {
  // A sliding point found deep inside the body under a concave edge (a garment held below T0
  // by its own pull, then projected as the last resort): the field's normal there points
  // across the edge, diagonally, and one move along it by its depth below T2 lands beside the
  // face it came through, below T1. Read again where it lands and moved again, it ends on T2.
  const double u = 0.05;
  BodySetup s(makeLPrism(u), std::make_shared<StaticMotion>());
  Point p(Vec3::Zero());
  FieldCollider c("test", s.parts, kOffsets, 0.0, 0.0);
  const double dt = 1e-3;
  // First it lands on the top face of the L's lower arm, far from the edge, and slides there.
  initialiseArriving(c, p, Vec3(1.6 * u, u + 0.02, 0));
  p.state.setPosition(0, Vec3(1.6 * u, u + 0.012, 0));
  c.collide(*p.model, 0, dt, p.state);
  ASSERT_EQ(c.state(0, 0), PointState::OnSurf);
  // Then the garment pulls it into the body, 12 mm under the edge.
  const Vec3 inside(u - 0.001, u - 0.012, 0);
  const field::FieldSample at = s.field.sampleAtVoxel(s.field.toVoxel(inside));
  ASSERT_LT(at.distance_m, 0.0);
  const Vec3 oneMove = inside + (kOffsets.t2_m - at.distance_m) * at.normal;
  ASSERT_LT(s.field.distanceAt(oneMove), kOffsets.t1_m) << "the premise: one move lands below T1";
  p.state.setPosition(0, inside);
  p.state.setVelocity(0, Vec3::Zero());
  c.collide(*p.model, dt, 2 * dt, p.state);
  EXPECT_EQ(c.fieldCounters().projections, 1u);
  const Vec3 end = p.state.position(0);
  EXPECT_GT(end.x(), u + kOffsets.t1_m) << "across the edge";
  EXPECT_NEAR(s.field.distanceAt(end), kOffsets.t2_m, 0.2 * kVoxel) << "on T2";
}

TEST(FieldCollider, ACreaseMoveNeverEndsDeeperThanTheMean) {
  // The crease move is first order: each part's surface taken for the plane its ask ends on.
  // Beside a concave edge (the L's) the surface turns away from that plane, and across a
  // channel narrower than 2 T2 the move runs far along it: it can end deeper in a part than
  // the mean of the asks. A box stands on the L's lower arm, 25 mm from its upper arm (a
  // crease with the lower arm's top face, a channel with the upper arm). Random points thrown
  // into the corner, one test each, with crease moves and with the mean alone: with crease
  // moves each ends at least as far out of both parts as with the mean, and further out in
  // many. (Taking every crease move, a third of them ended deeper.)
  const double u = 0.05, gap = 0.025;
  const field::DistanceField lField = buildField(makeLPrism(u));
  const field::DistanceField boxField = buildField(field::makeBox(Vec3(u + gap, u - 0.01, -u), Vec3(2.5 * u, 2.5 * u, u)));
  const std::vector<CollisionPart> parts = {{"L", &lField, std::make_shared<StaticMotion>()},
                                            {"box", &boxField, std::make_shared<StaticMotion>()}};
  const auto clearance = [&](const Vec3& x) { return std::min(lField.distanceAt(x), boxField.distanceAt(x)); };
  std::mt19937 rng(20261207);
  std::uniform_real_distribution<double> where(u - 0.004, u + gap + 0.004), speed(0.5, 4.0);
  std::normal_distribution<double> gauss;
  const double dt = 1e-3;
  int pinched = 0, better = 0;
  std::uint64_t taken = 0, refused = 0;  // crease moves (stats.json's crease_moves, crease_moves_refused)
  for (int trial = 0; trial < 3000; ++trial) {
    const Vec3 from(where(rng), where(rng), 0.01 * gauss(rng));
    const Vec3 v = speed(rng) * Vec3(gauss(rng), gauss(rng), 0.3 * gauss(rng)).normalized();
    std::array<double, 2> ends{};
    for (const bool crease : {true, false}) {
      Point p(Vec3::Zero());
      FieldCollider c("test", parts, kOffsets, 0.0, 0.0);
      c.setCreaseMoves(crease);
      initialiseArriving(c, p, from + v * dt);
      p.state.setVelocity(0, v);
      c.collide(*p.model, 0, dt, p.state);
      ends[crease ? 0 : 1] = clearance(p.state.position(0));
      const FieldCollisionCounters& f = c.fieldCounters();
      if (crease) {
        pinched += f.pinchedVertexTests > 0;
        taken += f.creaseMoves;
        refused += f.creaseMovesRefused;
      } else {
        EXPECT_EQ(f.creaseMoves + f.creaseMovesRefused, 0u);
      }
    }
    EXPECT_GE(ends[0], ends[1] - 1e-12) << "trial " << trial;
    better += ends[0] > ends[1] + 1e-4;
  }
  EXPECT_GT(pinched, 500);
  EXPECT_GT(better, 100) << "of " << pinched << " pinched";
  EXPECT_GE(taken, static_cast<std::uint64_t>(better));
  EXPECT_GT(refused, 100u) << "taken " << taken;
  EXPECT_LE(taken + refused, static_cast<std::uint64_t>(pinched));
}

/// One triangle over the pole of a ball of radius 5 cm, its vertices 30 degrees from the
/// pole: with the vertices on T2 (15 mm), its centroid lies 6 mm from the surface, 9 mm below
/// T2. The ball is still; its parts take face samples.
struct Cap {
  static constexpr double kRadius = 0.05;
  field::DistanceField field = buildField(field::makeSphere(kRadius, Vec3::Zero(), 64, 32));
  std::vector<CollisionPart> parts;
  std::shared_ptr<const ClothModel> model;
  ClothState state;
  std::array<Vec3, 3> directions;

  explicit Cap(int partCount = 1, bool faceSamples = true) {
    for (int k = 0; k < partCount; ++k)
      parts.push_back({"ball" + std::to_string(k), &field, std::make_shared<LinearMotion>(Vec3::Zero(), Vec3::Zero()),
                       faceSamples});
    const double polar = std::numbers::pi / 6.0;
    mesh::TriMesh m;
    for (int i = 0; i < 3; ++i) {
      const double around = 2.0 * std::numbers::pi * i / 3.0;
      directions[i] = Vec3(std::sin(polar) * std::cos(around), std::sin(polar) * std::sin(around), std::cos(polar));
      m.positions.push_back(Vec3(40, 40, 40) + directions[i]);  // far from the ball at first
    }
    m.triangles = {{0, 1, 2}};
    model = ClothModel::build(m, mesh::Topology::build(m), Material{});
    state = ClothState::atRest(*model);
  }
  /// Initialises the collider with the triangle far away, then brings its vertices 2 mm
  /// below T2 moving inwards: the first test registers their collisions on T2.
  void arrive(FieldCollider& c) {
    c.initialise(state, 0.0);
    for (int i = 0; i < 3; ++i) {
      state.setPosition(i, (kRadius + kOffsets.t2_m - 0.002) * directions[i]);
      state.setVelocity(i, -0.5 * directions[i]);
    }
  }
  [[nodiscard]] FieldCollider collider() const { return FieldCollider("test", parts, kOffsets, 0.0, 0.0); }
  /// arrive, then the first test over dt: the vertices land on T2.
  void land(FieldCollider& c, double dt) {
    arrive(c);
    c.collide(*model, 0.0, dt, state);
  }
  [[nodiscard]] Vec3 centroid() const { return (state.position(0) + state.position(1) + state.position(2)) / 3.0; }
  [[nodiscard]] Vec3 centroidVelocity() const {
    return (state.velocity(0) + state.velocity(1) + state.velocity(2)) / 3.0;
  }
};

TEST(FieldCollider, FaceSamplesLiftATriangleUntilItsCentroidIsOnT2) {
  // Beyond the paper, whose vertices alone collide: then the ball reaches 9 mm past T2 into
  // the triangle, between vertices that all rest on T2.
  constexpr double dt = 1e-3;
  for (const bool faces : {false, true}) {
    SCOPED_TRACE(faces ? "face samples" : "vertices alone");
    Cap cap(1, faces);
    FieldCollider c = cap.collider();
    EXPECT_EQ(c.faceSamples(), faces);
    cap.land(c, dt);
    for (int i = 0; i < 3; ++i) {
      ASSERT_EQ(c.state(0, i), PointState::OnSurf);
      if (!faces) {
        EXPECT_NEAR(cap.field.distanceAt(cap.state.position(i)), kOffsets.t2_m, 5e-4) << "vertex " << i;
      }
    }
    // With face samples the first test already lifted the triangle by a quarter of 9 mm.
    EXPECT_NEAR(cap.field.distanceAt(cap.centroid()), faces ? 0.006 + 0.25 * 0.009 : 0.006, 1e-3);
    for (int step = 1; step < 60; ++step) c.collide(*cap.model, step * dt, (step + 1) * dt, cap.state);
    const double centroid = cap.field.distanceAt(cap.centroid());
    if (faces) {
      // A quarter of the depth per test: 0.75^60 of 9 mm is nothing.
      EXPECT_NEAR(centroid, kOffsets.t2_m, 5e-4);
      EXPECT_GT(c.fieldCounters().faceContacts, 10u);
      EXPECT_EQ(c.fieldCounters().facesInsideBody, 0u);
      // Lifted along the ball's normal at the centroid (the same displacement for the
      // three vertices): still about the pole, the vertices between T2 and T3, still sliding.
      for (int i = 0; i < 3; ++i) {
        const double d = cap.field.distanceAt(cap.state.position(i));
        EXPECT_GT(d, kOffsets.t2_m + 0.005) << "vertex " << i;
        EXPECT_LT(d, kOffsets.t3_m) << "vertex " << i;
        EXPECT_EQ(c.state(0, i), PointState::OnSurf);
      }
      EXPECT_LT(std::hypot(cap.centroid().x(), cap.centroid().y()), 5e-4);
    } else {
      EXPECT_NEAR(centroid, 0.006, 1e-3) << "nothing lifts the triangle";
      EXPECT_EQ(c.fieldCounters().faceTests, 0u);
    }
  }
}

TEST(FieldCollider, AFaceSampleBelowT2LosesItsInwardVelocity) {
  // All three vertices fall straight down onto the ball; their own responses (or none, where
  // a read puts a vertex a hair above T2) leave the centroid sinking. A face sample takes that
  // away: the centroid, below T2, keeps no velocity into the ball.
  constexpr double dt = 1e-3;
  for (const bool faces : {false, true}) {
    SCOPED_TRACE(faces ? "face samples" : "vertices alone");
    Cap cap(1, faces);
    FieldCollider c = cap.collider();
    cap.land(c, dt);
    for (int i = 0; i < 3; ++i) cap.state.setVelocity(i, Vec3(0, 0, -0.3));
    c.collide(*cap.model, dt, 2 * dt, cap.state);
    const double down = cap.centroidVelocity().z();
    if (faces) {
      EXPECT_NEAR(down, 0.0, 0.01);
    } else {
      EXPECT_LT(down, -0.05);
    }
  }
}

TEST(FieldCollider, FaceSamplesLeaveAloneWhatTwoPartsPressAndWhatFixturesHold) {
  // Two parts in one place: every vertex slides on both, as where two parts' offset surfaces
  // overlap, and lifting the triangle off one would push it into the other. A bound vertex:
  // the fixtures place it. Either way no centroid is tested and nothing moves but as the
  // vertices alone would move it.
  constexpr double dt = 1e-3;
  const auto run = [&](int partCount, bool faces, bool bound) {
    Cap cap(partCount, faces);
    FieldCollider c = cap.collider();
    if (bound) c.setFixedVertices({0}, 3);
    cap.arrive(c);
    for (int step = 0; step < 20; ++step) c.collide(*cap.model, step * dt, (step + 1) * dt, cap.state);
    return std::pair{cap.state, c.fieldCounters().faceTests};
  };
  for (const bool bound : {false, true}) {
    const int partCount = bound ? 1 : 2;
    const auto [withFaces, faceTests] = run(partCount, true, bound);
    const auto [without, none] = run(partCount, false, bound);
    EXPECT_EQ(faceTests, 0u) << (bound ? "bound vertex" : "two parts");
    EXPECT_EQ(withFaces.x, without.x);
    EXPECT_EQ(withFaces.z, without.z);
  }
  // And the one-part, all-free cap is tested (the two cases above are not vacuous).
  EXPECT_GT(run(1, true, false).second, 0u);
}

TEST(FieldCollider, OnlyTheFirst64PartsTakeFaceSamples) {
  Cap cap(65, false);
  cap.parts.back().faceSamples = true;
  try {
    FieldCollider c("coat", cap.parts, kOffsets, 0.0, 0.0);
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("garment 'coat': body part 'ball64' takes face samples, but only the first 64"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace drape::cloth
