// Following takes on a real nats-server: the pose follower grows the sender's animation
// bit for bit through duplicates, gaps, garbage and strangers; the cloth follower gathers a
// frame's garments whatever their order, and seeks to any frame without reading the ones
// before; a publisher restarted in the middle of a take sends only what the stream lacks;
// and the motion a cloth frame waits for is all the frame's substeps read.

#include <gtest/gtest.h>

#include <atomic>
#include <random>
#include <thread>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/motion/animation.hpp"
#include "drape/motion/interpolate.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/sim/character_world.hpp"
#include "drape/studio/cloth_follower.hpp"
#include "drape/studio/pose_follower.hpp"
#include "drape/studio/publisher.hpp"
#include "drape/studio/takes.hpp"
#include "drape/testing/nats_server.hpp"

namespace drape::studio {
namespace {

using namespace std::chrono_literals;

scene::Avatar threeJoints() {
  scene::Avatar a;
  a.name = "tester";
  a.joints = {{"Hips", -1}, {"Spine", 0}, {"Head", 1}};
  return a;
}

PoseStart startOf(const scene::Avatar& a, std::int64_t frames) {
  PoseStart s;
  s.character = a.name;
  for (const scene::Joint& j : a.joints) s.joints.push_back(j.name);
  s.driving = {0, 1, -1};
  s.start = TimeCode{90, 30.0};
  s.frames = frames;
  return s;
}

std::vector<PoseFrame> randomFrames(int count, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<PoseFrame> out;
  for (int f = 0; f < count; ++f) {
    PoseFrame p;
    p.frame = f;
    for (int j = 0; j < 3; ++j)
      p.joints.push_back({Quat(n(rng), n(rng), n(rng), n(rng)).normalized(), Vec3(n(rng), n(rng), n(rng))});
    out.push_back(p);
  }
  return out;
}

void send(Bus& bus, const std::string& source, const std::string& take, const Payload& p, const std::string& id) {
  (void)bus.publish(source, encode(Message{source, take, p}), id);
}

TEST(PoseFollower, GrowsTheSendersAnimationThroughDuplicatesGapsAndGarbage) {
  testing::NatsServer server;
  Bus bus = Bus::connect(server.url(), "test");
  bus.ensureStream("anim");
  const scene::Avatar avatar = threeJoints();
  std::mt19937 rng(1);
  const std::vector<PoseFrame> frames = randomFrames(12, rng);
  send(bus, "anim", "old", startOf(avatar, 2), "old.start");  // an earlier take's, then its frames
  send(bus, "anim", "old", frames[0], "old.0");
  send(bus, "anim", "T", startOf(avatar, 12), "T.start");
  for (int f = 0; f < 12; ++f) {
    if (f == 5 || f == 6) continue;  // never came
    send(bus, "anim", "T", frames[static_cast<std::size_t>(f)], fmt::format("T.{}", f));
    if (f == 3) {
      send(bus, "anim", "T", frames[3], "T.3.again");                                        // sent twice
      (void)bus.publish("anim", std::vector<std::uint8_t>{1, 2, 3, 4, 5, 6, 7, 8, 9}, "junk");  // not a frame
      (void)bus.publish("anim", encode(Message{"stranger", "T", frames[4]}), "T.4.stranger");  // another's message
    }
  }
  send(bus, "anim", "T", End{12, "", "", 0}, "T.end");

  StreamReader stream(bus, "anim", "follower", 200ms, 10s);
  PoseFollower poses(stream);
  poses.followNextTake(avatar, 30.0, "T");
  EXPECT_EQ(poses.take(), "T");
  EXPECT_TRUE(poses.waitForFrames(12));
  EXPECT_FALSE(poses.waitForFrames(13));
  EXPECT_TRUE(poses.ended());
  EXPECT_EQ(poses.filledFrames(), 2);
  EXPECT_GE(poses.skippedMessages(), 2);  // the junk and the stranger's
  const motion::AvatarAnimation& got = poses.animation();
  ASSERT_EQ(got.frameCount(), 12u);
  EXPECT_EQ(got.start().frame, 90);
  for (std::size_t f = 0; f < 12; ++f)
    for (std::size_t j = 0; j < 3; ++j) {
      RigidTransform want = frames[f].joints[j];
      if (f == 5 || f == 6)  // in between frames 4 and 7, as the micro-interpolation would take them
        want = motion::interpolate(frames[4].joints[j], frames[7].joints[j], static_cast<double>(f - 4) / 3.0);
      ASSERT_EQ(got.frame(f)[j].rotation.coeffs(), want.rotation.coeffs()) << f << " " << j;
      ASSERT_EQ(got.frame(f)[j].translation, want.translation) << f << " " << j;
    }
}

TEST(PoseFollower, ANewTakeEndsTheOneFollowedAndIsFollowedNext) {
  testing::NatsServer server;
  Bus bus = Bus::connect(server.url(), "test");
  bus.ensureStream("anim");
  const scene::Avatar avatar = threeJoints();
  std::mt19937 rng(2);
  const std::vector<PoseFrame> frames = randomFrames(4, rng);
  send(bus, "anim", "A", startOf(avatar, 0), "A.start");
  send(bus, "anim", "A", frames[0], "A.0");
  send(bus, "anim", "B", startOf(avatar, 0), "B.start");
  send(bus, "anim", "B", frames[1], "B.0");
  StreamReader stream(bus, "anim", "follower", 200ms, 10s);
  PoseFollower poses(stream);
  poses.followNextTake(avatar, 30.0);
  EXPECT_EQ(poses.take(), "A");
  EXPECT_THROW((void)poses.waitForFrames(2), NewTake);
  poses.followNextTake(avatar, 30.0);
  EXPECT_EQ(poses.take(), "B");
  EXPECT_TRUE(poses.waitForFrames(1));
  EXPECT_EQ(poses.animation().frame(0)[2].translation, frames[1].joints[2].translation);
}

TEST(PoseFollower, RefusesAnotherAvatarAndGivesUpOnSilence) {
  testing::NatsServer server;
  Bus bus = Bus::connect(server.url(), "test");
  bus.ensureStream("anim");
  scene::Avatar other = threeJoints();
  other.joints[2].name = "Neck";
  send(bus, "anim", "T", startOf(other, 0), "T.start");
  StreamReader stream(bus, "anim", "follower", 100ms, 400ms);
  PoseFollower poses(stream);
  try {
    poses.followNextTake(threeJoints(), 30.0);
    FAIL() << "followed another avatar's poses";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("joint 2 'Neck', where avatar 'tester' has 'Head'"), std::string::npos)
        << e.what();
  }
  try {
    poses.followNextTake(threeJoints(), 30.0);
    FAIL() << "a silent stream was waited for without end";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::Unavailable);
    EXPECT_NE(std::string(e.what()).find("for a take's poses from 'anim'; giving up"), std::string::npos) << e.what();
  }
}

ClothFrame clothFrame(std::int64_t frame, std::uint32_t garment, std::size_t vertices) {
  ClothFrame c;
  c.frame = frame;
  c.garment = garment;
  for (std::size_t v = 0; v < vertices; ++v)
    c.positions.emplace_back(static_cast<double>(frame), static_cast<double>(garment), static_cast<double>(v));
  c.states.assign(vertices, static_cast<std::uint8_t>(garment));
  return c;
}

/// A cloth take T of the poses "anim"'s take T on 'tester', from `start`.
ClothStart clothStartOf(TimeCode start, std::vector<GarmentInfo> garments) {
  ClothStart s;
  s.poses = "anim";
  s.poseTake = "T";
  s.character = "tester";
  s.start = start;
  s.garments = std::move(garments);
  return s;
}

TEST(ClothFollower, GathersEachFrameWholeAndReportsTheTakesError) {
  testing::NatsServer server;
  Bus bus = Bus::connect(server.url(), "test");
  bus.ensureStream("cloth");
  ClothStart start = clothStartOf(TimeCode{60, 30.0}, {{"Skirt", 4}, {"Top", 2}});
  start.leadIn_s = 1.0;
  send(bus, "cloth", "T", start, "start");
  // Garments out of order, one frame sent twice, one that fits no garment.
  send(bus, "cloth", "T", clothFrame(0, 1, 2), "0.1");
  send(bus, "cloth", "T", clothFrame(0, 0, 4), "0.0");
  send(bus, "cloth", "T", clothFrame(1, 0, 4), "1.0");
  send(bus, "cloth", "T", clothFrame(1, 0, 3), "1.0.bad");
  send(bus, "cloth", "T", clothFrame(0, 1, 2), "0.1.again");
  send(bus, "cloth", "T", clothFrame(1, 1, 2), "1.1");
  send(bus, "cloth", "T", End{1, "{}", "garment 'Skirt' went unstable in frame 2", 3}, "end");

  StreamReader stream(bus, "cloth", "player", 200ms, 10s);
  ClothFollower cloth(stream);
  EXPECT_EQ(cloth.followNextTake().garments.size(), 2u);
  for (std::int64_t f = 0; f < 2; ++f) {
    ASSERT_TRUE(cloth.waitForFrame(f));
    EXPECT_EQ(cloth.garment(0).positions.size(), 4u);
    EXPECT_EQ(cloth.garment(1).positions.size(), 2u);
    EXPECT_EQ(cloth.garment(1).positions[1], Vec3(static_cast<double>(f), 1.0, 1.0));
  }
  try {
    (void)cloth.waitForFrame(2);
    FAIL() << "the take's error was not reported";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::Unstable);
    EXPECT_NE(std::string(e.what()).find("went unstable in frame 2"), std::string::npos) << e.what();
  }
  EXPECT_EQ(cloth.skippedMessages(), 1);
}

TEST(ClothFollower, TheNextTakePassesOverTheOneFollowedAndAStopEndsAWait) {
  testing::NatsServer server;
  Bus bus = Bus::connect(server.url(), "test");
  bus.ensureStream("cloth");
  const ClothStart start = clothStartOf(TimeCode{0, 30.0}, {{"Skirt", 4}});
  // Take A, then A announced again (a restarted cloth-server), then take B.
  send(bus, "cloth", "A", start, "A.start");
  send(bus, "cloth", "A", clothFrame(0, 0, 4), "A.0");
  send(bus, "cloth", "A", End{1, "{}", "", 0}, "A.end");
  send(bus, "cloth", "A", start, "A.start.again");
  send(bus, "cloth", "B", start, "B.start");
  send(bus, "cloth", "B", clothFrame(0, 0, 4), "B.0");

  // Waiting in slices of a tenth of a second: a stop is seen long before the 30 s give-up.
  std::atomic<bool> stop{false};
  StreamReader stream(bus, "cloth", "player", 5s, 30s);
  stream.stopOn(&stop);
  ClothFollower cloth(stream);
  (void)cloth.followNextTake();
  EXPECT_EQ(cloth.take(), "A");
  ASSERT_TRUE(cloth.waitForFrame(0));
  EXPECT_FALSE(cloth.waitForFrame(1));
  (void)cloth.followNextTake("", "A");
  EXPECT_EQ(cloth.take(), "B");
  ASSERT_TRUE(cloth.waitForFrame(0));

  std::thread stopper([&] {
    std::this_thread::sleep_for(300ms);
    stop = true;
  });
  EXPECT_THROW((void)cloth.waitForFrame(1), Stopped);  // not the give-up's Error
  stopper.join();
}

TEST(ClothFollower, SeeksToAnyFrameAsReadingFromTheStartWould) {
  // A take of 150 frames of two garments, with what a stream can hold between them: the
  // take announced again by a restarted server, a message that is no studio frame, one
  // from a stranger. Seeking to a random frame gathers that frame as reading everything
  // before it does, and reads only a handful of messages to get there.
  testing::NatsServer server;
  Bus bus = Bus::connect(server.url(), "test");
  bus.ensureStream("cloth");
  const ClothStart start = clothStartOf(TimeCode{-30, 30.0}, {{"Skirt", 3}, {"Top", 2}});
  send(bus, "cloth", "T", start, "start");
  constexpr std::int64_t kFrames = 150;
  std::mt19937 rng(11);
  for (std::int64_t f = 0; f < kFrames; ++f) {
    send(bus, "cloth", "T", clothFrame(f, 0, 3), fmt::format("{}.0", f));
    if (rng() % 9 == 0) (void)bus.publish("cloth", std::vector<std::uint8_t>{1, 2, 3}, fmt::format("junk{}", f));
    if (rng() % 13 == 0) send(bus, "cloth", "T", start, fmt::format("restart{}", f));
    if (rng() % 11 == 0) (void)bus.publish("cloth", encode(Message{"other", "T", clothFrame(f + 7, 1, 2)}), fmt::format("x{}", f));
    send(bus, "cloth", "T", clothFrame(f, 1, 2), fmt::format("{}.1", f));
  }
  send(bus, "cloth", "T", End{kFrames - 1, "{}", "", 0}, "end");

  StreamReader all(bus, "cloth", "all", 200ms, 10s);
  ClothFollower reference(all);
  (void)reference.followNextTake();
  std::vector<std::vector<ClothFrame>> expected;
  for (std::int64_t f = 0; f < kFrames; ++f) {
    ASSERT_TRUE(reference.waitForFrame(f));
    expected.push_back({reference.garment(0), reference.garment(1)});
  }
  const ClothFollower::Held held = reference.held();
  EXPECT_EQ(held.newest, kFrames - 1);
  ASSERT_TRUE(held.ended.has_value());
  EXPECT_EQ(*held.ended, kFrames - 1);

  StreamReader stream(bus, "cloth", "seeker", 200ms, 10s);
  ClothFollower cloth(stream);
  (void)cloth.followNextTake();
  std::uniform_int_distribution<std::int64_t> any(0, kFrames - 1);
  for (int trial = 0; trial < 40; ++trial) {
    const std::int64_t target = trial == 0 ? 0 : trial == 1 ? kFrames - 1 : any(rng);
    const std::int64_t before = cloth.messagesRead();
    cloth.seek(target);  // forwards and back, and back again past the End read
    for (std::int64_t f = target; f < std::min(target + 3, kFrames); ++f) {
      ASSERT_TRUE(cloth.waitForFrame(f)) << "seeking to " << target;
      for (std::uint32_t g = 0; g < 2; ++g) {
        EXPECT_EQ(cloth.garment(g).frame, f);
        EXPECT_EQ(cloth.garment(g).positions, expected[static_cast<std::size_t>(f)][g].positions) << f << " " << g;
        EXPECT_EQ(cloth.garment(g).states, expected[static_cast<std::size_t>(f)][g].states);
      }
    }
    // Three frames of two garments and what lay between them: never the frames before.
    EXPECT_LE(cloth.messagesRead() - before, 16) << "seeking to " << target;
    if (target == kFrames - 1) {
      EXPECT_FALSE(cloth.waitForFrame(kFrames));
    }
  }
}

TEST(ClothFollower, HoldsTheNewestWholeFrameOfALiveTake) {
  testing::NatsServer server;
  Bus bus = Bus::connect(server.url(), "test");
  bus.ensureStream("cloth");
  const ClothStart start = clothStartOf(TimeCode{0, 30.0}, {{"Skirt", 3}, {"Top", 2}});
  send(bus, "cloth", "T", start, "start");
  StreamReader stream(bus, "cloth", "player", 200ms, 10s);
  ClothFollower cloth(stream);
  (void)cloth.followNextTake();
  EXPECT_EQ(cloth.held().newest, -1);
  send(bus, "cloth", "T", clothFrame(0, 0, 3), "0.0");
  EXPECT_EQ(cloth.held().newest, -1);  // frame 0 lacks its second garment
  send(bus, "cloth", "T", clothFrame(0, 1, 2), "0.1");
  send(bus, "cloth", "T", clothFrame(1, 0, 3), "1.0");
  EXPECT_EQ(cloth.held().newest, 0);
  send(bus, "cloth", "T", clothFrame(1, 1, 2), "1.1");
  const ClothFollower::Held held = cloth.held();
  EXPECT_EQ(held.newest, 1);
  EXPECT_FALSE(held.ended.has_value());
  cloth.seek(held.newest);
  ASSERT_TRUE(cloth.waitForFrame(1));
  EXPECT_EQ(cloth.garment(1).positions[1], Vec3(1.0, 1.0, 1.0));
  EXPECT_EQ(cloth.messagesRead(), 3);  // its start, then frame 1's two garments
}

TEST(Publisher, ARestartedServerSendsOnlyWhatTheStreamLacks) {
  testing::NatsServer server;
  Bus bus = Bus::connect(server.url(), "test");
  const scene::Avatar avatar = threeJoints();
  std::mt19937 rng(4);
  const std::vector<PoseFrame> frames = randomFrames(10, rng);
  {
    Publisher first(bus, "anim");
    EXPECT_EQ(first.beginTake("T", startOf(avatar, 10)), 0u);
    for (int f = 0; f < 6; ++f) first.send(frames[static_cast<std::size_t>(f)]);
  }  // stops after six frames
  Publisher again(bus, "anim");
  EXPECT_EQ(again.beginTake("T", startOf(avatar, 10)), 7u);
  EXPECT_FALSE(again.complete());
  for (const PoseFrame& f : frames) again.send(f);
  again.send(End{10, "", "", 0});
  EXPECT_EQ(bus.range("anim").messages, 12u) << "start, ten frames and the end, each once";
  for (std::uint64_t seq = 2; seq <= 11; ++seq)
    EXPECT_EQ(std::get<PoseFrame>(decode(bus.get("anim", seq)->data).payload).frame, static_cast<std::int64_t>(seq - 2));
  Publisher third(bus, "anim");
  (void)third.beginTake("T", startOf(avatar, 10));
  EXPECT_TRUE(third.complete());
  // Another take replaces it.
  Publisher next(bus, "anim");
  EXPECT_EQ(next.beginTake("U", startOf(avatar, 10)), 0u);
  EXPECT_EQ(bus.range("anim").messages, 1u);
}

TEST(Takes, ACothFrameWaitsForEveryMotionFrameItsSubstepsRead) {
  // For every cloth frame of the walk, the poses at each of its substeps (also refined
  // twice and four times, as a frame computed again is) from the first
  // motionFramesNeeded(frame) motion frames alone are those of the whole motion, to the bit.
  const scene::Avatar avatar =
      scene::loadAvatarFile(std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_rig_cmu_mb.mhskel");
  motion::MotionOptions mo;
  mo.clip.rate = 30.0;
  mo.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  const motion::AvatarAnimation whole =
      motion::loadAnimation(avatar, std::string(DRAPE_DATA_DIR) + "/mocap/cmu_12_03_walk.bvh", mo);
  const double rate = 30.0, leadIn = 1.0;
  const std::int64_t last = clothFramesOf(static_cast<std::int64_t>(whole.frameCount()), rate, leadIn, rate);
  EXPECT_EQ(last, static_cast<std::int64_t>(std::ceil((leadIn + whole.duration()) * rate)));
  const sim::AvatarPoses all(avatar, &whole, leadIn);
  std::vector<RigidTransform> a(avatar.joints.size()), b(avatar.joints.size());
  for (std::int64_t frame = 1; frame <= last; ++frame) {
    const std::int64_t need = motionFramesNeeded(frame, rate, leadIn, rate);
    ASSERT_GE(need, 1);
    if (need > static_cast<std::int64_t>(whole.frameCount())) {
      EXPECT_GE(frame, last - 1) << "only the take's last frames read past its end";
      continue;
    }
    motion::AvatarAnimation part = motion::AvatarAnimation::streamed(
        avatar.joints.size(), rate, whole.start(), {whole.drivingJoint().begin(), whole.drivingJoint().end()});
    for (std::int64_t f = 0; f < need; ++f) part.appendFrame(whole.frame(static_cast<std::size_t>(f)));
    const sim::AvatarPoses some(avatar, &part, leadIn);
    for (const int n : {33, 66, 132}) {
      const double dt = 1.0 / (rate * n);
      for (int s = 0; s <= n; ++s) {
        const double t = static_cast<double>((frame - 1) * n + s) * dt;
        all.evaluate(t, a);
        some.evaluate(t, b);
        for (std::size_t j = 0; j < a.size(); ++j) {
          ASSERT_EQ(a[j].rotation.coeffs(), b[j].rotation.coeffs()) << "frame " << frame << " substep " << s << "/" << n;
          ASSERT_EQ(a[j].translation, b[j].translation) << "frame " << frame << " substep " << s << "/" << n;
        }
      }
    }
  }
}

}  // namespace
}  // namespace drape::studio
