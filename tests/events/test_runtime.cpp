// The scheduler: when random graphs of control events end, against their durations worked
// out by hand; Plays against the motions they play, to the bit; anchoring, blending,
// conditions, state machines, wind, paths against their speed profile and turns worked out
// by hand, graphs started while others run, and a cast of several characters.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <fmt/format.h>

#include "drape/events/runtime.hpp"
#include "drape/motion/interpolate.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/testing/errors.hpp"

namespace drape::events {
namespace {

constexpr double kRate = 30.0;

scene::Avatar oneJoint() {
  scene::Avatar a;
  a.name = "stick";
  a.joints = {{"Hips", -1, Vec3(0, 1, 0)}};
  return a;
}

Event wait(double d) {
  Event e;
  e.kind = Kind::Wait;
  e.duration_s = d;
  return e;
}

Event control(Kind kind, std::vector<Event> children, double speed = 1.0, double duration = -1.0, int count = 0) {
  Event e;
  e.kind = kind;
  e.children = std::move(children);
  e.speed = speed;
  e.duration_s = duration;
  e.count = count;
  return e;
}

Graph graphOf(Event root) {
  Graph g;
  g.root = control(Kind::Parallel, {std::move(root)});
  return g;
}

/// How long an event of waits and control events lasts, by its definition.
double lasts(const Event& e) {
  double d = 0.0;
  switch (e.kind) {
    case Kind::Wait: return e.duration_s;
    case Kind::Sequence:
      for (const Event& c : e.children) d += lasts(c);
      break;
    case Kind::Loop:
      for (const Event& c : e.children) d += lasts(c);
      d *= e.count;
      break;
    case Kind::Parallel:
      for (const Event& c : e.children) d = std::max(d, lasts(c));
      break;
    default: ADD_FAILURE() << "not a timing event";
  }
  d /= e.speed;
  return e.duration_s >= 0.0 ? std::min(d, e.duration_s) : d;
}

std::string describe(const Event& e, int depth) {
  std::string out(static_cast<std::size_t>(2 * depth), ' ');
  out += fmt::format("{} speed {} duration {} count {}\n", kindName(e.kind), e.speed, e.duration_s, e.count);
  for (const Event& c : e.children) out += describe(c, depth + 1);
  return out;
}

Event randomEvent(std::mt19937& rng, int depth) {
  std::uniform_int_distribution<int> pick(0, depth > 3 ? 0 : 3), sixtieths(0, 90), few(1, 3), speeds(0, 2);
  const int kind = pick(rng);
  if (kind == 0) return wait(sixtieths(rng) / 60.0);
  std::vector<Event> children;
  for (int k = few(rng); k > 0; --k) children.push_back(randomEvent(rng, depth + 1));
  const double speed = std::array<double, 3>{0.5, 1.0, 2.0}[static_cast<std::size_t>(speeds(rng))];
  const double cut = std::uniform_int_distribution<int>(0, 3)(rng) == 0 ? sixtieths(rng) / 60.0 : -1.0;
  const Kind k = kind == 1 ? Kind::Sequence : kind == 2 ? Kind::Parallel : Kind::Loop;
  return control(k, std::move(children), speed, cut, k == Kind::Loop ? few(rng) : 0);
}

TEST(Scheduler, RandomGraphsEndWhenTheirDurationsSay) {
  const scene::Avatar avatar = oneJoint();
  const Motions none;
  std::mt19937 rng(17);
  for (int round = 0; round < 400; ++round) {
    const Graph g = graphOf(randomEvent(rng, 0));
    const double d = lasts(g.root);
    const Rendered r = render(g, none, avatar, {}, kRate, 0, {}, {});
    ASSERT_TRUE(r.ended);
    // The tick at which it ends: the first at or past its end.
    const long ticks = static_cast<long>(std::ceil(d * kRate - 1e-6));
    ASSERT_EQ(r.frames, ticks + 1) << "round " << round << ": lasts " << d << " s\n" << describe(g.root, 0);
  }
}

struct Walk {
  scene::Avatar avatar = scene::loadAvatarFile(std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_rig_cmu_mb.mhskel");
  motion::MotionOptions options = [] {
    motion::MotionOptions o;
    o.clip.rate = kRate;
    o.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
    return o;
  }();
  std::string path = std::string(DRAPE_DATA_DIR) + "/mocap/cmu_12_03_walk.bvh";
  motion::AvatarAnimation alone = motion::loadAnimation(avatar, path, options);

  Event play(double from = 0.0, double to = -1.0, double speed = 1.0, double blend = 0.0, bool anchor = false) const {
    Event e;
    e.kind = Kind::Play;
    e.motion = path;
    e.from_s = from;
    e.to_s = to;
    e.speed = speed;
    e.blend_s = blend;
    e.anchor = anchor;
    return e;
  }
  Rendered render(const Graph& g, long frames = 0, const std::vector<TimedEvent>& events = {},
                  const std::vector<std::pair<std::string, std::string>>& parameters = {}) {
    motions.load(g, avatar, options);
    return events::render(g, motions, avatar, {}, kRate, frames, events, parameters);
  }
  Motions motions;
};

void expectSameJoints(std::span<const RigidTransform> a, std::span<const RigidTransform> b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t j = 0; j < a.size(); ++j) {
    ASSERT_EQ(a[j].rotation.coeffs(), b[j].rotation.coeffs()) << what << ", joint " << j;
    ASSERT_EQ(a[j].translation, b[j].translation) << what << ", joint " << j;
  }
}

TEST(Scheduler, APlayIsItsMotionToTheBit) {
  Walk w;
  const Rendered whole = w.render(graphOf(w.play()));
  ASSERT_EQ(static_cast<std::size_t>(whole.frames), w.alone.frameCount());
  for (std::size_t f = 0; f < w.alone.frameCount(); ++f)
    expectSameJoints(whole.animation.frame(f), w.alone.frame(f), "frame " + std::to_string(f));
  // From 1 s to 2 s at twice the speed: every other frame, 0.5 s.
  const Rendered part = w.render(graphOf(w.play(1.0, 2.0, 2.0)));
  ASSERT_EQ(part.frames, 16);
  for (long f = 0; f < part.frames; ++f)
    expectSameJoints(part.animation.frame(static_cast<std::size_t>(f)), w.alone.frame(static_cast<std::size_t>(30 + 2 * f)),
                     "frame " + std::to_string(f));
}

TEST(Scheduler, AnAnchoredPlayGoesOnFromWhereTheCharacterStands) {
  Walk w;
  // The walk twice over, each anchored: the second starts where the first ended.
  const Rendered twice = w.render(graphOf(control(Kind::Sequence, {w.play(0, -1, 1, 0, true), w.play(0, -1, 1, 0, true)})));
  const long n = static_cast<long>(w.alone.frameCount());
  ASSERT_EQ(twice.frames, 2 * n - 1);
  const auto root = [&](long f) { return twice.animation.frame(static_cast<std::size_t>(f))[0].translation; };
  const auto floorStep = [](const Vec3& a, const Vec3& b) { return Vec3(a.x() - b.x(), 0, a.z() - b.z()).norm(); };
  double largest = 0.0;
  for (std::size_t f = 1; f < w.alone.frameCount(); ++f)
    largest = std::max(largest, floorStep(w.alone.frame(f)[0].translation, w.alone.frame(f - 1)[0].translation));
  for (long f = 1; f < twice.frames; ++f)
    EXPECT_LE(floorStep(root(f), root(f - 1)), 1.5 * largest) << "frame " << f << ": the root jumps";
  // It walks on: twice as far from the start as one walk goes.
  const double one = floorStep(w.alone.frame(w.alone.frameCount() - 1)[0].translation, w.alone.frame(0)[0].translation);
  EXPECT_NEAR(floorStep(root(twice.frames - 1), root(0)), 2 * one, 0.1 * one);
  // And heights are the motion's own.
  EXPECT_EQ(root(n + 10).y(), w.alone.frame(11)[0].translation.y());
}

TEST(Scheduler, APlayBlendsInFromWhatTheCharacterDid) {
  Walk w;
  // The first second of the walk, then the walk from 3 s blending in over 0.5 s.
  const Rendered r = w.render(graphOf(control(Kind::Sequence, {w.play(0, 1), w.play(3, -1, 1, 0.5)})));
  const std::span<const RigidTransform> held = w.alone.frame(30);  // the first Play's last pose
  for (long k = 0; k <= 15; ++k) {
    const double weight = std::min(1.0, (k / kRate + 1e-9) / 0.5);
    const std::span<const RigidTransform> got = r.animation.frame(static_cast<std::size_t>(30 + k));
    const std::span<const RigidTransform> second = w.alone.frame(static_cast<std::size_t>(90 + k));
    for (std::size_t j = 0; j < got.size(); ++j) {
      const RigidTransform want = weight >= 1.0 ? second[j] : motion::interpolate(held[j], second[j], weight);
      ASSERT_TRUE(got[j].translation.isApprox(want.translation, 1e-12)) << "tick " << k << " joint " << j;
      ASSERT_TRUE(got[j].rotation.isApprox(want.rotation, 1e-12)) << "tick " << k << " joint " << j;
    }
  }
}

Event windEvent(const Vec3& v, double duration) {
  Event e;
  e.kind = Kind::Wind;
  e.velocity = v;
  e.duration_s = duration;
  return e;
}

TEST(Scheduler, TheWindBlowsForItsDurationOrFromThenOn) {
  const scene::Avatar avatar = oneJoint();
  const Motions none;
  const Graph g = graphOf(control(Kind::Sequence, {wait(0.5), windEvent(Vec3(2, 0, 0), 1.0), windEvent(Vec3(0, 0, 4), -1),
                                                   wait(1.0)}));
  const Rendered r = render(g, none, avatar, {}, kRate, 0, {}, {});
  ASSERT_EQ(r.frames, 76);  // 2.5 s
  for (long f = 0; f < r.frames; ++f) {
    const auto& wind = r.wind[static_cast<std::size_t>(f)];
    if (f < 15) EXPECT_FALSE(wind) << f;
    else if (f < 45) EXPECT_EQ(wind, Vec3(2, 0, 0)) << f;
    else EXPECT_EQ(wind, Vec3(0, 0, 4)) << f;
  }
}

Event stateOf(const std::string& name, std::vector<Event> children, long next, std::vector<std::string> on = {},
              std::vector<std::size_t> to = {}) {
  Event s = control(Kind::Parallel, std::move(children));
  s.name = name;
  s.next = next;
  s.on = std::move(on);
  s.to = std::move(to);
  return s;
}

TEST(Scheduler, AStateMachineMovesOnTheEventsSentToIt) {
  // Idle blows from x and loops; a 'kick' moves it to Kick, which blows from z for a second
  // and goes back to Idle; 'stop' ends it.
  const scene::Avatar avatar = oneJoint();
  const Motions none;
  Event machine;
  machine.kind = Kind::StateMachine;
  machine.children = {stateOf("Idle", {windEvent(Vec3(1, 0, 0), -1), wait(0.5)}, 0, {"kick", "stop"}, {1, 2}),
                      stateOf("Kick", {windEvent(Vec3(0, 0, 5), -1), wait(1.0)}, 0),
                      stateOf("Done", {}, -1)};
  const Rendered r = render(graphOf(machine), none, avatar, {}, kRate, 0, {{"kick", 2.0}, {"stop", 4.0}}, {});
  ASSERT_TRUE(r.ended);
  EXPECT_EQ(r.frames, 121);  // ends at the tick 'stop' arrives
  for (long f = 0; f < r.frames; ++f) {
    const Vec3 want = f >= 60 && f < 90 ? Vec3(0, 0, 5) : Vec3(1, 0, 0);
    EXPECT_EQ(r.wind[static_cast<std::size_t>(f)], want) << "frame " << f;
  }
}

TEST(Scheduler, AConditionChoosesByTheParameterItInherits) {
  const scene::Avatar avatar = oneJoint();
  const Motions none;
  Event cond;
  cond.kind = Kind::Condition;
  cond.parameter = "mood";
  cond.equals = {"calm"};
  cond.children = {wait(2.0), wait(0.5)};
  Event params = control(Kind::Parameters, {cond});
  params.parameters = {{"mood", "calm"}};
  EXPECT_EQ(render(graphOf(params), none, avatar, {}, kRate, 0, {}, {}).frames, 61);
  EXPECT_EQ(render(graphOf(cond), none, avatar, {}, kRate, 0, {}, {{"mood", "calm"}}).frames, 61);
  EXPECT_EQ(render(graphOf(cond), none, avatar, {}, kRate, 0, {}, {{"mood", "storm"}}).frames, 16);
  EXPECT_EQ(render(graphOf(cond), none, avatar, {}, kRate, 0, {}, {}).frames, 16);  // not set: otherwise
}

TEST(Scheduler, AGraphStartedWhileAnotherRunsTakesTheCharacterOver) {
  Walk w;
  Graph first = graphOf(w.play());
  Graph second = graphOf(w.play(2.0, 3.0, 1.0, 0.0));
  w.motions.load(first, w.avatar, w.options);
  Scheduler s(w.avatar, {}, kRate);
  s.start(first, w.motions);
  Tick tick;
  for (int k = 0; k < 20; ++k) ASSERT_TRUE(s.tick(tick));
  s.start(second, w.motions);  // at once: the next tick shows it
  ASSERT_TRUE(s.tick(tick));
  expectSameJoints(tick.poses[0], w.alone.frame(60), "the injected graph's first frame");
  for (int k = 1; k <= 30; ++k) ASSERT_TRUE(s.tick(tick));
  expectSameJoints(tick.poses[0], w.alone.frame(90), "its last frame");
  // It ended and holds its pose over the first, which runs on to its end.
  ASSERT_TRUE(s.tick(tick));
  expectSameJoints(tick.poses[0], w.alone.frame(90), "held");
  long more = 0;
  while (s.tick(tick)) ++more;
  EXPECT_EQ(more, static_cast<long>(w.alone.frameCount()) - 1 - 52);
}

Event pathEvent(std::vector<Vec3> points, double speed, double ease = 0.5, double corner = 0.0, bool turn = true) {
  Event e;
  e.kind = Kind::Path;
  e.points = std::move(points);
  e.pathSpeed_mps = speed;
  e.ease_s = ease;
  e.corner_m = corner;
  e.turn = turn;
  return e;
}

/// Where a path carried at `v` with ease `te` is after t seconds, from the constant
/// acceleration v / te over the ease: v t^2 / (2 te), then v te / 2 + v (t - te), then the
/// same backwards from its end.
double trapezoid(double t, double length, double v, double te) {
  const double total = length / v + te;
  if (t <= te) return v * t * t / (2 * te);
  if (t >= total) return length;
  if (t >= total - te) return length - v * (total - t) * (total - t) / (2 * te);
  return v * te / 2 + v * (t - te);
}

double yawOfRoot(const RigidTransform& r) {
  const Vec3 f = r.rotation * Vec3::UnitZ();
  return std::atan2(f.x(), f.z());
}

scene::Avatar twoJoints() {
  scene::Avatar a = oneJoint();
  a.joints.push_back({"Head", 0, Vec3(0, 1.6, 0.2)});
  return a;
}

TEST(Scheduler, APathCarriesTheCharacterAtItsSpeedEasingInAndOut) {
  // 2 m along x, then 2 m along z (a turn of 90 degrees to the right), at 1 m/s with half a
  // second of ease; then a second's wait, where the character stays where it was carried.
  const scene::Avatar avatar = twoJoints();
  const Motions none;
  const Graph g = graphOf(
      control(Kind::Sequence, {pathEvent({Vec3(5, 0, 5), Vec3(7, 0, 5), Vec3(7, 0, 7)}, 1.0, 0.5), wait(1.0)}));
  const Rendered r = render(g, none, avatar, {}, kRate, 0, {}, {});
  ASSERT_EQ(r.frames, 166);  // 4.5 s of path, 1 s of waiting
  for (long f = 0; f < r.frames; ++f) {
    const double s = trapezoid(static_cast<double>(f) / kRate, 4.0, 1.0, 0.5);
    const Vec3 want = s < 2 ? Vec3(s, 1, 0) : Vec3(2, 1, s - 2);
    const double turn = s >= 2 ? -M_PI / 2 : 0.0;
    const std::span<const RigidTransform> joints = r.animation.frame(static_cast<std::size_t>(f));
    ASSERT_TRUE(joints[0].translation.isApprox(want, 1e-9)) << "frame " << f << ": " << joints[0].translation.transpose();
    ASSERT_NEAR(yawOfRoot(joints[0]), turn, 1e-9) << "frame " << f;
    // The body turns as one about the vertical through the root.
    const Vec3 head = want + Quat(Eigen::AngleAxisd(turn, Vec3::UnitY())) * Vec3(0, 0.6, 0.2);
    ASSERT_TRUE(joints[1].translation.isApprox(head, 1e-9)) << "frame " << f;
  }
  // Too short to reach its speed (0.2 m at 1 m/s with 0.5 s of ease): up and down in a second.
  const Rendered shortPath = render(graphOf(pathEvent({Vec3(0, 0, 0), Vec3(0, 0, 0.2)}, 1.0, 0.5)), none, avatar, {},
                                    kRate, 0, {}, {});
  EXPECT_EQ(shortPath.frames, 31);
  EXPECT_NEAR(shortPath.animation.frame(15)[0].translation.z(), 0.1, 1e-9);
  EXPECT_NEAR(shortPath.animation.frame(30)[0].translation.z(), 0.2, 1e-9);
}

TEST(Scheduler, APathTurnsOverItsCornerAndNotAtAllWhenToldNot) {
  const scene::Avatar avatar = oneJoint();
  const Motions none;
  // At 1 m/s without ease, a left turn of 90 degrees at 2 m, spread over a metre.
  const std::vector<Vec3> points{Vec3(0, 0, 0), Vec3(0, 0, 2), Vec3(2, 0, 2)};
  const Rendered r = render(graphOf(pathEvent(points, 1.0, 0.0, 1.0)), none, avatar, {}, kRate, 0, {}, {});
  ASSERT_EQ(r.frames, 121);
  for (long f = 0; f < r.frames; ++f) {
    const double s = static_cast<double>(f) / kRate;
    const double want = M_PI / 2 * std::clamp(s - 1.5, 0.0, 1.0);
    ASSERT_NEAR(yawOfRoot(r.animation.frame(static_cast<std::size_t>(f))[0]), want, 1e-9) << "frame " << f;
  }
  const Rendered straight = render(graphOf(pathEvent(points, 1.0, 0.0, 1.0, false)), none, avatar, {}, kRate, 0, {}, {});
  for (long f = 0; f < straight.frames; ++f)
    ASSERT_NEAR(yawOfRoot(straight.animation.frame(static_cast<std::size_t>(f))[0]), 0.0, 1e-12) << "frame " << f;
  EXPECT_TRUE(straight.animation.frame(120)[0].translation.isApprox(Vec3(2, 1, 2), 1e-9));
}

TEST(Scheduler, APathCutShortLeavesTheCharacterWhereItWasAndALaterOneTakesOver) {
  const scene::Avatar avatar = oneJoint();
  const Motions none;
  const Event cut = control(Kind::Parallel, {pathEvent({Vec3(0, 0, 0), Vec3(5, 0, 0)}, 1.0, 0.0)}, 1.0, 1.0);
  const Rendered r = render(graphOf(control(Kind::Sequence, {cut, wait(1.0)})), none, avatar, {}, kRate, 0, {}, {});
  ASSERT_EQ(r.frames, 61);
  for (long f = 30; f < r.frames; ++f)
    ASSERT_TRUE(r.animation.frame(static_cast<std::size_t>(f))[0].translation.isApprox(Vec3(1, 1, 0), 1e-9)) << f;
  // A second path starts after half a second, along z: the first stops where it was.
  const Event second = control(Kind::Sequence, {wait(0.5), pathEvent({Vec3(0, 0, 0), Vec3(0, 0, 1)}, 1.0, 0.0)});
  const Rendered both = render(graphOf(control(Kind::Parallel, {pathEvent({Vec3(0, 0, 0), Vec3(5, 0, 0)}, 1.0, 0.0), second})),
                               none, avatar, {}, kRate, 0, {}, {});
  EXPECT_EQ(both.frames, 46);
  EXPECT_TRUE(both.animation.frame(45)[0].translation.isApprox(Vec3(0.5, 1, 1), 1e-9))
      << both.animation.frame(45)[0].translation.transpose();
}

TEST(Scheduler, APathSteersAWalkAlongItsTurns) {
  // The walk, steered along 1.5 m ahead and then 1.5 m to the right of where it heads; the
  // wind that follows the path marks the tick it ends.
  Walk w;
  const Graph plain = graphOf(w.play());
  const Event path = pathEvent({Vec3(0, 0, 0), Vec3(0, 0, 1.5), Vec3(-1.5, 0, 1.5)}, 0.0, 0.5, 0.5);
  const Graph steered = graphOf(
      control(Kind::Parallel, {w.play(), control(Kind::Sequence, {path, windEvent(Vec3(1, 0, 0), -1)})}));
  const Rendered a = w.render(plain), b = w.render(steered);
  ASSERT_EQ(a.frames, b.frames);
  const auto root = [](const Rendered& r, long f) { return r.animation.frame(static_cast<std::size_t>(f))[0]; };
  long ended = -1;
  for (long f = 0; f < b.frames && ended < 0; ++f)
    if (b.wind[static_cast<std::size_t>(f)]) ended = f;
  ASSERT_GT(ended, 30) << "the path never ended";
  const Vec3 travel = root(a, ended).translation - root(a, 0).translation;
  // It ends when the walk has gone the path's 3 m forwards (its sway aside).
  EXPECT_NEAR(Vec3(travel.x(), 0, travel.z()).norm(), 3.0, 0.15);
  for (long f = 1; f < b.frames; ++f) {
    // Each step is the walk's own, turned: as long, as high.
    const Vec3 da = root(a, f).translation - root(a, f - 1).translation;
    const Vec3 db = root(b, f).translation - root(b, f - 1).translation;
    ASSERT_NEAR(da.norm(), db.norm(), 1e-9) << "frame " << f;
    ASSERT_NEAR(root(a, f).translation.y(), root(b, f).translation.y(), 1e-9) << "frame " << f;
  }
  // It went 1.5 m the way it headed and 1.5 m to its right, and heads right from then on.
  const double heading = std::atan2(travel.x(), travel.z());
  const Vec3 want = Quat(Eigen::AngleAxisd(heading, Vec3::UnitY())) * Vec3(-1.5, 0, 1.5);
  const Vec3 went = root(b, ended).translation - root(b, 0).translation;
  EXPECT_LT((Vec3(went.x(), 0, went.z()) - want).norm(), 0.25) << went.transpose() << " against " << want.transpose();
  for (long f = ended; f < b.frames; f += 10)
    ASSERT_NEAR(std::remainder(yawOfRoot(root(b, f)) - yawOfRoot(root(a, f)) + M_PI / 2, 2 * M_PI), 0.0, 1e-9) << f;
}

TEST(Scheduler, EachCharacterOfACastPlaysWhatNamesItAsItWouldAlone) {
  // Ada walks two seconds; Bea, a metre to her side, waits half a second, walks a second and
  // a half, then is carried along a path; a gust blows on both. Each comes out of the cast,
  // frame for frame and to the bit, as the part that names it comes out for her alone (then
  // holding where it ended while the other goes on), and the wind is the graph's.
  Walk w;
  scene::Avatar bea = w.avatar;
  for (scene::Joint& j : bea.joints) j.restCenter += Vec3(1, 0, 0);
  const std::vector<Actor> cast{{&w.avatar, {"Ada"}}, {&bea, {"Bea"}}};
  Event ada = control(Kind::Sequence, {w.play(0.0, 2.0)});
  ada.character = "Ada";
  Event beas = control(Kind::Sequence, {wait(0.5), w.play(0.0, 1.5, 1.0, 0.0, true),
                                        pathEvent({Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(2, 0, 1)}, 1.0, 0.3, 0.4)});
  beas.character = "Bea";
  const Graph g = graphOf(control(Kind::Parallel, {ada, beas, control(Kind::Sequence, {wait(1.0), [] {
                                                                    Event gust;
                                                                    gust.kind = Kind::Wind;
                                                                    gust.velocity = Vec3(3, 0, 0);
                                                                    gust.duration_s = 0.5;
                                                                    return gust;
                                                                  }()})}));
  Motions motions;
  motions.load(g, cast, w.options);
  const RenderedCast both = render(g, motions, cast, kRate, 0, {}, {});
  ASSERT_EQ(both.animations.size(), 2u);
  for (std::size_t a = 0; a < 2; ++a) {
    SCOPED_TRACE(a == 0 ? "Ada" : "Bea");
    const Graph part = graphOf(a == 0 ? ada : beas);
    Motions own;
    own.load(part, *cast[a].avatar, w.options);
    const Rendered alone = render(part, own, *cast[a].avatar, cast[a].names, kRate, 0, {}, {});
    ASSERT_LE(alone.frames, both.frames);
    for (long f = 0; f < both.frames; ++f)
      expectSameJoints(both.animations[a].frame(static_cast<std::size_t>(f)),
                       alone.animation.frame(static_cast<std::size_t>(std::min(f, alone.frames - 1))),
                       fmt::format("frame {}", f));
  }
  EXPECT_FALSE(both.wind[29].has_value());
  ASSERT_TRUE(both.wind[30].has_value());
  EXPECT_EQ(*both.wind[30], Vec3(3, 0, 0));
  EXPECT_FALSE(both.wind[46].has_value());

  // Among several, a Play that names none, or another, is refused where it is.
  Event unnamed = w.play();
  unnamed.where = {"cast.egml", 5, 0};
  EXPECT_EQ(testing::errorOf([&] { (void)render(graphOf(unnamed), motions, cast, kRate, 0, {}, {}); }),
            "cast.egml:5: Play: the scene has 2 characters (Ada, Bea): say which it moves (character \"NAME\", here or "
            "on an event above it)");
  Event carl = w.play();
  carl.character = "Carl";
  carl.where = {"cast.egml", 9, 0};
  EXPECT_EQ(testing::errorOf([&] { (void)render(graphOf(carl), motions, cast, kRate, 0, {}, {}); }),
            "cast.egml:9: Play: character 'Carl' is not in the scene (its characters: Ada, Bea)");
}

TEST(Scheduler, WhatCannotRunIsSaid) {
  const scene::Avatar avatar = oneJoint();
  const Motions none;
  const Graph endless = graphOf(control(Kind::Loop, {wait(1.0)}));
  EXPECT_NE(testing::errorOf([&] { (void)render(endless, none, avatar, {}, kRate, 0, {}, {}); })
                .find("runs on past an hour"),
            std::string::npos);
  EXPECT_EQ(render(endless, none, avatar, {}, kRate, 90, {}, {}).frames, 90);
  Event idle = control(Kind::Loop, {wait(0.0)});
  idle.where = {"idle.egml", 7, 0};
  EXPECT_EQ(testing::errorOf([&] { (void)render(graphOf(idle), none, avatar, {}, kRate, 10, {}, {}); }),
            "idle.egml:7: Loop: repeats events that take no time, for ever");
  Walk w;
  Event elsewhere = w.play();
  elsewhere.character = "Alice";
  elsewhere.where = {"cast.egml", 3, 0};
  const Graph g = graphOf(elsewhere);
  w.motions.load(g, w.avatar, w.options);
  EXPECT_NE(testing::errorOf([&] { (void)render(g, w.motions, w.avatar, {"Body"}, kRate, 0, {}, {}); })
                .find("cast.egml:3: Play: character 'Alice' is not in the scene (its character answers to: Body, "),
            std::string::npos);
}

}  // namespace
}  // namespace drape::events
