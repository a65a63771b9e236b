// Keeping the body out of itself (sim/keep_apart): a real walk that swings the forearms
// through the small of the back on the MakeHuman body, corrected, and checked frame by frame
// with the distance reads done here, vertex by vertex; what must not move does not; the
// correction eases in and out; bad names are refused.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "drape/core/error.hpp"
#include "drape/motion/animation.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/sim/body_overlap.hpp"
#include "drape/sim/character_world.hpp"
#include "drape/sim/keep_apart.hpp"
#include "walk_fixture.hpp"

namespace drape::sim {
namespace {

constexpr double kMargin = 0.012;

using fixture::Walk;

/// The walking dress's body, its torso and arm parts' fields, and the walk that puts the
/// left forearm 27 mm into the lower back.
const Walk& delfem2Walk() {
  static const Walk walk = fixture::loadWalk(
      std::string(DRAPE_DATA_DIR) + "/mocap/cmu_walk_delfem2.bvh",
      {"Hips", "LowerBack", "Spine", "Spine1", "LeftArm", "RightArm", "LeftForeArm", "RightForeArm"}, 0.016);
  return walk;
}

const PartField& fieldOf(const Walk& w, const std::string& name) {
  return *std::find_if(w.fields.begin(), w.fields.end(), [&](const PartField& f) { return f.segment == name; });
}

/// Least distance of part a's vertices from part b, read here vertex by vertex.
double clearanceOf(const Walk& w, std::span<const RigidTransform> pose, const std::string& a, const std::string& b) {
  const scene::Segment& s = w.avatar.segments[static_cast<std::size_t>(w.avatar.findSegment(a))];
  const PartField& into = fieldOf(w, b);
  const RigidTransform toB = pose[static_cast<std::size_t>(into.joint)].inverse() * pose[static_cast<std::size_t>(s.joint)];
  double least = 1.0;
  for (const Vec3& v : s.mesh.positions) {
    const Vec3 p = toB.apply(v);
    if (into.field.containsPoint(p)) least = std::min(least, into.field.distanceAt(p));
  }
  return least;
}

std::vector<RigidTransform> restPose(const scene::Avatar& avatar) {
  std::vector<RigidTransform> rest;
  for (const scene::Joint& j : avatar.joints) rest.push_back(j.restWorld());
  return rest;
}

bool below(const scene::Avatar& avatar, int j, const std::string& joint) {
  for (; j >= 0; j = avatar.joints[static_cast<std::size_t>(j)].parent)
    if (avatar.joints[static_cast<std::size_t>(j)].name == joint) return true;
  return false;
}

/// The angle (rad) between a joint's corrected and original world rotation, per frame.
std::vector<double> correctionAngles(const motion::AvatarAnimation& before, const motion::AvatarAnimation& after,
                                     int joint) {
  std::vector<double> out;
  for (std::size_t f = 0; f < before.frameCount(); ++f)
    out.push_back(before.frame(f)[static_cast<std::size_t>(joint)].rotation.angularDistance(
        after.frame(f)[static_cast<std::size_t>(joint)].rotation));
  return out;
}

/// The walk with both forearms kept apart (swung about the shoulders), and the report.
struct Corrected {
  motion::AvatarAnimation animation;
  KeepApartReport report;
};

Corrected forearmsKeptApart(const Walk& w) {
  Corrected c{w.animation, {}};
  KeepApartSettings keep;
  keep.parts = {"LeftForeArm", "RightForeArm"};
  keep.margin_m = kMargin;
  c.report = keepBodyApart(w.avatar, c.animation, w.fields, keep);
  return c;
}

TEST(KeepApart, TheForearmsKeepTheirClearanceFromTheTorsoInEveryFrame) {
  const Walk& w = delfem2Walk();
  const Corrected c = forearmsKeptApart(w);
  const motion::AvatarAnimation& corrected = c.animation;
  const KeepApartReport& report = c.report;

  const std::vector<RigidTransform> rest = restPose(w.avatar);
  double deepestBefore = 0;
  int checked = 0;
  for (const std::string forearm : {"LeftForeArm", "RightForeArm"})
    for (const std::string torso : {"Hips", "LowerBack", "Spine"}) {
      // The clearance kept: the margin, or the pair's own at rest if less (both ways round).
      const double target = std::min({kMargin, clearanceOf(w, rest, forearm, torso), clearanceOf(w, rest, torso, forearm)});
      for (std::size_t f = 0; f < corrected.frameCount(); ++f) {
        deepestBefore = std::max(deepestBefore, -clearanceOf(w, w.animation.frame(f), forearm, torso));
        EXPECT_GE(clearanceOf(w, corrected.frame(f), forearm, torso), target - 2e-4)
            << forearm << " into " << torso << ", frame " << f;
        EXPECT_GE(clearanceOf(w, corrected.frame(f), torso, forearm), target - 2e-4)
            << torso << " into " << forearm << ", frame " << f;
        ++checked;
      }
    }
  EXPECT_GT(checked, 500);  // 86 motion frames
  EXPECT_GT(deepestBefore, 0.02) << "the walk must put a forearm well into the torso";
  ASSERT_FALSE(report.pairs.empty());
  EXPECT_EQ(report.pairs.front().part, "LeftForeArm");
  EXPECT_EQ(report.pairs.front().from, "LowerBack");
  EXPECT_EQ(report.pairs.front().pivot, "LeftArm");  // swung about the shoulder
  for (const KeptApart& k : report.pairs) EXPECT_LT(k.remaining_m, 2e-4) << describe(k);
  EXPECT_GT(report.framesChanged, 30);
  EXPECT_LT(report.largestAngle_deg, 30.0);
}

TEST(KeepApart, OnlyTheArmsBelowTheShouldersMoveAndTheirBonesKeepTheirLengths) {
  const Walk& w = delfem2Walk();
  const motion::AvatarAnimation corrected = forearmsKeptApart(w).animation;
  int moved = 0;
  for (std::size_t f = 0; f < corrected.frameCount(); ++f)
    for (std::size_t j = 0; j < w.avatar.joints.size(); ++j) {
      const RigidTransform& a = w.animation.frame(f)[j];
      const RigidTransform& b = corrected.frame(f)[j];
      const int ji = static_cast<int>(j);
      if (!below(w.avatar, ji, "LeftArm") && !below(w.avatar, ji, "RightArm")) {
        ASSERT_EQ(a.translation, b.translation) << w.avatar.joints[j].name << ", frame " << f;
        ASSERT_EQ(a.rotation.coeffs(), b.rotation.coeffs()) << w.avatar.joints[j].name << ", frame " << f;
        continue;
      }
      moved += a.rotation.angularDistance(b.rotation) > 1e-6;
      // Rigid: each joint keeps its distance from its parent, and the shoulder stays put.
      const int p = w.avatar.joints[j].parent;
      const double boneBefore = (a.translation - w.animation.frame(f)[static_cast<std::size_t>(p)].translation).norm();
      const double boneAfter = (b.translation - corrected.frame(f)[static_cast<std::size_t>(p)].translation).norm();
      EXPECT_NEAR(boneAfter, boneBefore, 1e-9) << w.avatar.joints[j].name << ", frame " << f;
      if (w.avatar.joints[j].name == "LeftArm" || w.avatar.joints[j].name == "RightArm") {
        EXPECT_NEAR((a.translation - b.translation).norm(), 0.0, 1e-9);
      }
    }
  EXPECT_GT(moved, 100);
}

TEST(KeepApart, TheCorrectionEasesInAndOut) {
  // Frame by frame alone the shoulder turns from nothing to its correction in one frame;
  // smoothed it starts turning before the first frame that needs it and its angular
  // acceleration (second difference) is smaller, while every frame still keeps its clearance.
  const Walk& w = delfem2Walk();
  KeepApartSettings keep;
  keep.parts = {"LeftForeArm"};
  keep.margin_m = kMargin;
  motion::AvatarAnimation smooth = w.animation, sharp = w.animation;
  const KeepApartReport smoothed = keepBodyApart(w.avatar, smooth, w.fields, keep);
  keep.smoothing_s = 0;
  const KeepApartReport unsmoothed = keepBodyApart(w.avatar, sharp, w.fields, keep);
  const int shoulder = w.avatar.findJoint("LeftArm");
  ASSERT_GE(shoulder, 0);
  const std::vector<double> a = correctionAngles(w.animation, smooth, shoulder);
  const std::vector<double> b = correctionAngles(w.animation, sharp, shoulder);
  const auto peakAcceleration = [](const std::vector<double>& x) {
    double most = 0;
    for (std::size_t f = 1; f + 1 < x.size(); ++f) most = std::max(most, std::abs(x[f + 1] - 2 * x[f] + x[f - 1]));
    return most;
  };
  EXPECT_LT(peakAcceleration(a), 0.6 * peakAcceleration(b));
  // Wherever the frame-by-frame correction starts, the smoothed one has started already.
  int onsets = 0;
  for (std::size_t f = 1; f < b.size(); ++f)
    if (b[f - 1] < 1e-6 && b[f] > 1e-6) {
      ++onsets;
      EXPECT_GT(a[f - 1], 1e-4) << "frame " << f - 1 << ": the smoothed correction starts before it is needed";
    }
  EXPECT_GT(onsets, 0);
  EXPECT_GT(smoothed.framesChanged, unsmoothed.framesChanged);
  for (const KeptApart& k : smoothed.pairs) EXPECT_LT(k.remaining_m, 2e-4) << describe(k);
}

TEST(KeepApart, NoJointTurnsFurtherThanTheLimitAndWhatIsLeftShortIsReported) {
  // The forearms need about 20 degrees at the shoulders on this walk; allowed 5, the
  // shoulders stop there in every frame and the report says how far each pair stays short.
  const Walk& w = delfem2Walk();
  motion::AvatarAnimation corrected = w.animation;
  KeepApartSettings keep;
  keep.parts = {"LeftForeArm", "RightForeArm"};
  keep.margin_m = kMargin;
  keep.maxTurn_deg = 5;
  const KeepApartReport report = keepBodyApart(w.avatar, corrected, w.fields, keep);
  EXPECT_LE(report.largestAngle_deg, 5.0 + 1e-6);
  for (const char* shoulder : {"LeftArm", "RightArm"})
    for (const double a : correctionAngles(w.animation, corrected, w.avatar.findJoint(shoulder)))
      ASSERT_LE(a, 5.0 * std::numbers::pi / 180.0 + 1e-9) << shoulder;
  ASSERT_FALSE(report.pairs.empty());
  const KeptApart& deepest = report.pairs.front();
  EXPECT_GT(deepest.remaining_m, 0.005) << describe(deepest);
  EXPECT_LT(deepest.remaining_m, deepest.deepest_m) << describe(deepest);
  EXPECT_GT(deepest.framesRemaining, 0);
}

TEST(KeepApart, APartThatGoesIntoNothingLeavesTheMotionAsItIs) {
  const Walk& w = delfem2Walk();
  motion::AvatarAnimation corrected = w.animation;
  KeepApartSettings keep;
  keep.parts = {"Head"};
  keep.margin_m = kMargin;
  const KeepApartReport report = keepBodyApart(w.avatar, corrected, w.fields, keep);
  EXPECT_TRUE(report.pairs.empty());
  EXPECT_EQ(report.framesChanged, 0);
  for (std::size_t f = 0; f < corrected.frameCount(); ++f)
    for (std::size_t j = 0; j < w.avatar.joints.size(); ++j)
      ASSERT_EQ(corrected.frame(f)[j].rotation.coeffs(), w.animation.frame(f)[j].rotation.coeffs());
}

/// The walk kept apart a frame at a time: each frame pushed, every ready frame taken as it
/// comes (the lag the stream sees recorded), the last ones after finish().
struct LiveCorrected {
  std::vector<std::vector<RigidTransform>> frames;
  std::vector<std::size_t> readyAfterPush;  // per pushed frame: frames out after it
  KeepApartReport report;
  std::size_t delay = 0;
};

LiveCorrected keptApartLive(const Walk& w, const KeepApartSettings& keep) {
  LiveKeepApart live(w.avatar, w.fields, keep, w.animation.rate());
  LiveCorrected out;
  out.delay = live.delay();
  std::vector<RigidTransform> pose(w.avatar.joints.size());
  const auto take = [&] {
    while (live.next(pose)) out.frames.push_back(pose);
  };
  for (std::size_t f = 0; f < w.animation.frameCount(); ++f) {
    live.push(w.animation.frame(f));
    take();
    out.readyAfterPush.push_back(out.frames.size());
  }
  live.finish();
  take();
  out.report = live.report();
  return out;
}

TEST(KeepApart, AMotionKeptApartAFrameAtATimeIsTheWholeMotionsCorrectionToTheBit) {
  // Smoothed (0.1 s: frames wait 2 + 3 sigmas, 15 at 30 Hz), smoothed more than the walk's
  // first frames reach back (the clamping at both ends), and not at all (no wait).
  const Walk& w = delfem2Walk();
  const std::size_t n = w.animation.frameCount();
  for (const double smoothing : {0.1, 0.5, 0.0}) {
    SCOPED_TRACE(::testing::Message() << "smoothing " << smoothing << " s");
    KeepApartSettings keep;
    keep.parts = {"LeftForeArm", "RightForeArm"};
    keep.margin_m = kMargin;
    keep.smoothing_s = smoothing;
    motion::AvatarAnimation whole = w.animation;
    const KeepApartReport report = keepBodyApart(w.avatar, whole, w.fields, keep);
    ASSERT_GT(report.framesChanged, 0);
    const LiveCorrected live = keptApartLive(w, keep);
    const double sigma = smoothing * w.animation.rate();  // frames, as the settings give it
    const std::size_t delay =
        static_cast<std::size_t>(std::ceil(2 * sigma)) + static_cast<std::size_t>(std::ceil(3 * sigma));
    EXPECT_EQ(live.delay, delay);
    ASSERT_EQ(live.frames.size(), n);
    for (std::size_t f = 0; f < n; ++f) {
      // Frame f is out once frame f + delay has come, and not before.
      EXPECT_EQ(live.readyAfterPush[f], f >= delay ? f - delay + 1 : 0) << "after frame " << f;
      for (std::size_t j = 0; j < w.avatar.joints.size(); ++j) {
        const RigidTransform& a = whole.frame(f)[j];
        const RigidTransform& b = live.frames[f][j];
        ASSERT_EQ(a.rotation.coeffs(), b.rotation.coeffs()) << "frame " << f << ", joint " << j;
        ASSERT_EQ(a.translation, b.translation) << "frame " << f << ", joint " << j;
      }
    }
    EXPECT_EQ(live.report.framesChanged, report.framesChanged);
    EXPECT_EQ(live.report.largestAngle_deg, report.largestAngle_deg);
    ASSERT_EQ(live.report.pairs.size(), report.pairs.size());
    for (std::size_t i = 0; i < report.pairs.size(); ++i) EXPECT_EQ(describe(live.report.pairs[i]), describe(report.pairs[i]));
  }
}

TEST(KeepApart, ALiveCorrectionRefusesFramesItCannotHold) {
  const Walk& w = delfem2Walk();
  KeepApartSettings keep;
  keep.parts = {"LeftForeArm"};
  keep.margin_m = kMargin;
  LiveKeepApart live(w.avatar, w.fields, keep, w.animation.rate());
  const std::vector<RigidTransform> wrong(w.avatar.joints.size() - 1);
  EXPECT_THROW(live.push(wrong), Error);
  // Frames pushed and none taken: the window holds delay() + 1 of them, and no more.
  for (std::size_t f = 0; f <= live.delay(); ++f) live.push(w.animation.frame(f));
  EXPECT_THROW(live.push(w.animation.frame(live.delay() + 1)), Error);
  std::vector<RigidTransform> pose(w.avatar.joints.size());
  ASSERT_TRUE(live.next(pose));
  ASSERT_FALSE(live.next(pose));
  live.push(w.animation.frame(live.delay() + 1));
  live.finish();
  EXPECT_THROW(live.push(w.animation.frame(0)), Error);
  std::size_t out = 1;
  while (live.next(pose)) ++out;
  EXPECT_EQ(out, live.delay() + 2);
  EXPECT_EQ(live.framesOut(), out);
}

TEST(KeepApart, RefusesAnUnknownPartAndTheRoot) {
  const Walk& w = delfem2Walk();
  motion::AvatarAnimation corrected = w.animation;
  KeepApartSettings keep;
  keep.parts = {"Tail"};
  try {
    (void)keepBodyApart(w.avatar, corrected, w.fields, keep);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("has no part 'Tail' (it has: "), std::string::npos) << e.what();
  }
  keep.parts = {"Hips"};
  try {
    (void)keepBodyApart(w.avatar, corrected, w.fields, keep);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("part 'Hips' moves with the avatar's root joint"), std::string::npos)
        << e.what();
  }
}

TEST(KeepApart, Describes) {
  KeptApart k{"LeftForeArm", "LowerBack", "LeftArm", 0.012, 0.0391, 66, 41, 0.00004, 0};
  EXPECT_EQ(describe(k),
            "LeftForeArm out of LowerBack about LeftArm: 39.1 mm short of its 12 mm clearance at most, in 41 frames "
            "(most in frame 66); 0.0 mm after");
  k.remaining_m = 0.0154;
  k.framesRemaining = 120;
  EXPECT_EQ(describe(k),
            "LeftForeArm out of LowerBack about LeftArm: 39.1 mm short of its 12 mm clearance at most, in 41 frames "
            "(most in frame 66); 15.4 mm after, in 120 frames");
}

}  // namespace
}  // namespace drape::sim
