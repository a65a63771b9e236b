// Skeletons, clips, interpolation: SLERP properties, exact substep endpoints, hand-computed
// forward kinematics of a tiny BVH, units guesses, the CMU T-pose frame, resampling.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "drape/core/error.hpp"
#include "drape/formats/bvh.hpp"
#include "drape/motion/animation.hpp"
#include "drape/motion/clip_io.hpp"
#include "drape/motion/interpolate.hpp"
#include "drape/motion/jointmap.hpp"

namespace drape::motion {
namespace {

Quat randomRotation(std::mt19937& rng) {
  std::normal_distribution<double> n;
  return Quat(n(rng), n(rng), n(rng), n(rng)).normalized();
}

TEST(Slerp, EndpointsAreExact) {
  std::mt19937 rng(1);
  for (int i = 0; i < 1000; ++i) {
    const Quat a = randomRotation(rng), b = randomRotation(rng);
    const Quat s0 = slerp(a, b, 0.0), s1 = slerp(a, b, 1.0);
    EXPECT_EQ(s0.coeffs(), a.coeffs());
    EXPECT_EQ(s1.coeffs(), b.coeffs());
  }
}

TEST(Slerp, ConstantAngularSpeed) {
  std::mt19937 rng(2);
  for (int i = 0; i < 500; ++i) {
    const Quat a = randomRotation(rng), b = randomRotation(rng);
    const double total = a.angularDistance(b);
    for (double s : {0.1, 0.25, 0.5, 0.7, 0.9}) {
      const Quat q = slerp(a, b, s);
      EXPECT_NEAR(a.angularDistance(q), s * total, 1e-9);
      EXPECT_NEAR(q.angularDistance(b), (1.0 - s) * total, 1e-9);
      EXPECT_NEAR(q.norm(), 1.0, 1e-12);
    }
  }
}

TEST(Slerp, TakesTheShortPathAcrossTheSignFlip) {
  // b and -b are the same rotation: the halfway point must be the same either way, and
  // lie 10 degrees from a, not 170.
  const Quat a(Eigen::AngleAxisd(0.0, Vec3::UnitZ()));
  const Quat b(Eigen::AngleAxisd(20.0 * M_PI / 180.0, Vec3::UnitZ()));
  const Quat minusB(-b.w(), -b.x(), -b.y(), -b.z());
  const Quat h1 = slerp(a, b, 0.5), h2 = slerp(a, minusB, 0.5);
  EXPECT_NEAR(a.angularDistance(h1), 10.0 * M_PI / 180.0, 1e-12);
  EXPECT_NEAR(h1.angularDistance(h2), 0.0, 1e-7);
  const Vec3 x = h2 * Vec3::UnitX();
  EXPECT_NEAR(std::atan2(x.y(), x.x()), 10.0 * M_PI / 180.0, 1e-12);
}

TEST(Interpolate, TranslationIsLinearAndEndsExact) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-5, 5);
  for (int i = 0; i < 200; ++i) {
    const RigidTransform a{randomRotation(rng), Vec3(u(rng), u(rng), u(rng))};
    const RigidTransform b{randomRotation(rng), Vec3(u(rng), u(rng), u(rng))};
    const RigidTransform t0 = interpolate(a, b, 0.0), t1 = interpolate(a, b, 1.0);
    EXPECT_EQ(t0.translation, a.translation);
    EXPECT_EQ(t1.translation, b.translation);
    EXPECT_EQ(t0.rotation.coeffs(), a.rotation.coeffs());
    EXPECT_EQ(t1.rotation.coeffs(), b.rotation.coeffs());
    const RigidTransform m = interpolate(a, b, 0.25);
    EXPECT_NEAR((m.translation - (0.75 * a.translation + 0.25 * b.translation)).norm(), 0.0, 1e-12);
  }
}

// Two joints: root "hips" with a knee 10 units below it and an End Site; every number
// below is worked out by hand (units: cm).
constexpr const char* kTinyBvh = R"(HIERARCHY
ROOT hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT knee
  {
    OFFSET 0 -10 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 10 0 0
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.5
1 2 3 90 0 0 0 0 0
0 0 0 0 0 0 90 90 0
)";

Clip tinyClip() {
  ClipLoadOptions options;
  options.metresPerUnit = 0.01;
  options.rate = 0.0;  // keep the file's 2 Hz
  options.skipReferenceTPose = false;
  return clipFromBvh(formats::parseBvh(kTinyBvh, "tiny.bvh"), options);
}

TEST(ForwardKinematics, TinyBvhByHand) {
  const Clip clip = tinyClip();
  ASSERT_EQ(clip.frameCount(), 2u);
  EXPECT_DOUBLE_EQ(clip.rate, 2.0);
  std::vector<RigidTransform> w(2);
  // Frame 0: root at (1,2,3) cm turned 90 degrees about Z; the knee offset (0,-10,0)
  // turns to (10,0,0); the end site (10,0,0) turns to (0,10,0).
  forwardKinematics(clip.skeleton, clip.frameRotations(0), clip.rootTranslations[0], w);
  EXPECT_NEAR((w[0].translation - Vec3(0.01, 0.02, 0.03)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((w[1].translation - Vec3(0.11, 0.02, 0.03)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((w[1].apply(*clip.skeleton.joints[1].endSite) - Vec3(0.11, 0.12, 0.03)).norm(), 0.0, 1e-12);
  // Frame 1: knee channels Z=90 then X=90 compose as Rz * Rx: Rx leaves (10,0,0), Rz
  // turns it to (0,10,0), so the end site is back at the origin. (Rx * Rz would give
  // (0,0,10) from the knee.)
  forwardKinematics(clip.skeleton, clip.frameRotations(1), clip.rootTranslations[1], w);
  EXPECT_NEAR((w[1].translation - Vec3(0, -0.10, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((w[1].apply(*clip.skeleton.joints[1].endSite) - Vec3(0, 0, 0)).norm(), 0.0, 1e-12);
}

TEST(Units, GuessesFromSkeletonSize) {
  EXPECT_EQ(guessUnits(30.0).name, "CMU units (0.0564 m)");
  EXPECT_DOUBLE_EQ(guessUnits(30.0).metresPerUnit, kCmuMetresPerUnit);
  EXPECT_EQ(guessUnits(170.0).name, "cm");
  EXPECT_EQ(guessUnits(68.0).name, "in");
  EXPECT_EQ(guessUnits(1.75).name, "m");
  EXPECT_EQ(guessUnits(1750.0).name, "mm");
}

TEST(ClipIo, CmuWalkIsCmuUnitsWithATPoseFirstFrame) {
  ClipLoadReport report;
  const Clip clip = loadClip(std::string(DRAPE_DATA_DIR) + "/mocap/cmu_walk_delfem2.bvh", {}, &report);
  EXPECT_EQ(report.units.name, "CMU units (0.0564 m)");
  EXPECT_TRUE(report.referenceTPoseSkipped);
  EXPECT_EQ(report.referenceTPose(), "frame 1 is a reference T-pose, not played");
  EXPECT_EQ(report.sourceFrames, 344u);
  EXPECT_NEAR(report.sourceRate, 120.0, 0.01);
  // 343 frames at 120 Hz span 342/120 s = 2.85 s: 86 frames at 30 Hz.
  EXPECT_DOUBLE_EQ(clip.rate, 30.0);
  EXPECT_EQ(clip.frameCount(), 86u);
  EXPECT_EQ(clip.skeleton.size(), 31u);
  // Hips about 0.94 m above the floor (16.7 units).
  EXPECT_NEAR(clip.rootTranslations[0].y(), 0.94, 0.05);
}

TEST(ClipIo, DazWalkIsCentimetres) {
  ClipLoadReport report;
  const Clip clip = loadClip(std::string(DRAPE_DATA_DIR) + "/mocap/cmu_02_02_walk_dazstyle.bvh", {}, &report);
  EXPECT_EQ(report.units.name, "cm");
  EXPECT_EQ(clip.skeleton.size(), 43u);
  EXPECT_NEAR(clip.rootTranslations[0].y(), 0.78, 0.05);
}

TEST(ClipIo, DazWalksUnfoldingFromTheRestPoseIsNotPlayed) {
  // Frame 1 of the file has the body at rest; frames 2 to 5 swing the arms down and the
  // legs into the walk at up to 3,000 degrees per second (the walk itself: about 300).
  const std::string path = std::string(DRAPE_DATA_DIR) + "/mocap/cmu_02_02_walk_dazstyle.bvh";
  ClipLoadReport report;
  const Clip clip = loadClip(path, {}, &report);
  EXPECT_FALSE(report.referenceTPoseSkipped);
  EXPECT_EQ(report.referenceTPose(), "");
  EXPECT_EQ(report.restUnfoldFramesSkipped, 4u);
  // 295 frames at 120 Hz span 294/120 s = 2.45 s: 74 frames at 30 Hz.
  EXPECT_EQ(clip.frameCount(), 74u);
  ClipLoadOptions keep;
  keep.skipRestUnfold = false;
  ClipLoadReport kept;
  EXPECT_EQ(loadClip(path, keep, &kept).frameCount(), 75u);
  EXPECT_EQ(kept.restUnfoldFramesSkipped, 0u);
  // The CMU clips have none (after their reference T-pose, where they have one).
  for (const char* name : {"cmu_walk_delfem2.bvh", "cmu_12_03_walk.bvh", "cmu_11_01.amc"}) {
    ClipLoadReport r;
    (void)loadClip(std::string(DRAPE_DATA_DIR) + "/mocap/" + name, {}, &r);
    EXPECT_EQ(r.restUnfoldFramesSkipped, 0u) << name;
  }
}

/// Two joints at 120 Hz: the child turns about X from `startDegrees` by the per-frame steps
/// given, then `steadyDegrees` per frame for 100 frames (a steady motion).
Clip turningClip(double startDegrees, const std::vector<double>& stepsDegrees, double steadyDegrees = 1.0) {
  Clip clip;
  clip.rate = 120.0;
  clip.skeleton.joints.push_back({"root", -1, Vec3::Zero(), std::nullopt});
  clip.skeleton.joints.push_back({"arm", 0, Vec3(0.3, 0, 0), std::nullopt});
  std::vector<double> steps = stepsDegrees;
  steps.insert(steps.end(), 100, steadyDegrees);
  double angle = startDegrees;
  for (std::size_t f = 0; f <= steps.size(); ++f) {
    clip.rotations.push_back(Quat::Identity());
    clip.rotations.push_back(Quat(Eigen::AngleAxisd(angle * M_PI / 180.0, Vec3::UnitX())));
    clip.rootTranslations.push_back(Vec3::Zero());
    if (f < steps.size()) angle += steps[f];
  }
  return clip;
}

TEST(ClipIo, RestUnfoldingIsAShortFastRunFromRest) {
  EXPECT_EQ(restUnfoldFrames(turningClip(0.0, {25, 25, 25})), 3u);  // 3,000 deg/s from rest, then 120
  EXPECT_EQ(restUnfoldFrames(turningClip(0.0, {})), 0u);            // no fast run
  EXPECT_EQ(restUnfoldFrames(turningClip(40.0, {25, 25, 25})), 0u); // fast, but not from rest
  EXPECT_EQ(restUnfoldFrames(turningClip(0.0, std::vector<double>(40, 25.0))), 0u);  // a third of a second: the motion
  EXPECT_EQ(restUnfoldFrames(turningClip(0.0, {1.4, 1.4}, 0.05)), 0u);  // 168 deg/s is no unfolding
  EXPECT_EQ(restUnfoldFrames(turningClip(0.0, {1.6, 1.6}, 0.05)), 2u);  // 192 deg/s, from 6 deg/s
}

TEST(ClipIo, ScaleOverrideWins) {
  ClipLoadOptions options;
  options.metresPerUnit = 0.01;
  ClipLoadReport report;
  const Clip clip = loadClip(std::string(DRAPE_DATA_DIR) + "/mocap/cmu_walk_delfem2.bvh", options, &report);
  EXPECT_TRUE(report.unitsOverridden);
  EXPECT_NEAR(clip.rootTranslations[0].y(), 0.167, 0.01);
}

TEST(ClipIo, AsfAmcSoccerKick) {
  ClipLoadReport report;
  const Clip clip = loadClip(std::string(DRAPE_DATA_DIR) + "/mocap/cmu_11_01.amc", {}, &report);
  EXPECT_EQ(report.sourceFrames, 597u);
  EXPECT_EQ(report.units.name, "CMU units (0.0564 m)");
  EXPECT_EQ(clip.skeleton.size(), 31u);  // root + 30 bones
  // 597 frames at 120 Hz span 4.967 s: 150 frames at 30 Hz.
  EXPECT_EQ(clip.frameCount(), 150u);
  // The subject stands: the lowest joint stays near the floor, the head well above.
  std::vector<RigidTransform> w(clip.skeleton.size());
  forwardKinematics(clip.skeleton, clip.frameRotations(0), clip.rootTranslations[0], w);
  double low = 1e9, high = -1e9;
  for (const RigidTransform& t : w) {
    low = std::min(low, t.translation.y());
    high = std::max(high, t.translation.y());
  }
  EXPECT_GT(high - low, 1.3);
  EXPECT_LT(high - low, 2.0);
  EXPECT_NEAR(low, 0.0, 0.15);
}

// Given the skeleton half of an Acclaim pair, or a file of no motion format, the message
// says what to give instead.
TEST(ClipIo, TheWrongFileSaysWhatToGive) {
  const std::string asf = std::string(DRAPE_DATA_DIR) + "/mocap/cmu_11.asf";
  try {
    (void)loadClip(asf, {});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind(asf + ": an ASF file holds a skeleton, not motion; give one of its .amc", 0), 0u)
        << e.what();
  }
  try {
    (void)loadClip("walk.fbx", {});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "walk.fbx: unknown motion format '.fbx' (expected .bvh or .amc, or a glTF avatar's own .glb or "
                           ".gltf)");
  }
}

TEST(ClipIo, ResampleKeepsEndpoints) {
  const Clip clip = tinyClip();
  const Clip r = resample(clip, 8.0);  // 0.5 s at 8 Hz: 5 frames
  ASSERT_EQ(r.frameCount(), 5u);
  EXPECT_EQ(r.rootTranslations.front(), clip.rootTranslations.front());
  EXPECT_EQ(r.rootTranslations.back(), clip.rootTranslations.back());
  EXPECT_NEAR((r.rootTranslations[2] - 0.5 * clip.rootTranslations[0]).norm(), 0.0, 1e-15);
}

TEST(JointMap, UnknownJointsAreErrorsWithTheirLine) {
  const JointMap map = parseJointMap("{\n  \"name\": \"mine\",\n  \"joints\": {\n    \"hips\": \"Hips\",\n"
                                     "    \"ankle\": \"LeftFoot\"\n  }\n}\n", "mine.json");
  const Clip clip = tinyClip();
  scene::Avatar avatar;
  avatar.name = "a";
  avatar.joints.push_back({"Hips", -1, Vec3::Zero(), Quat::Identity()});
  avatar.joints.push_back({"LeftFoot", 0, Vec3(0, -1, 0), Quat::Identity()});
  try {
    checkJointMap(map, clip.skeleton, avatar);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "mine.json:5:5: unknown motion joint 'ankle' (not in the motion's skeleton)");
  }
  try {  // an unknown avatar joint is reported where its name is written, in a chain too
    checkJointMap(parseJointMap("{\"joints\": {\n  \"hips\": [\"Hips\",\n    \"Pelvis\"]}}", "chain.json"), clip.skeleton, avatar);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "chain.json:3:5: unknown avatar joint 'Pelvis' (not in avatar 'a')");
  }
  try {
    (void)parseJointMap("{\n \"joints\": {\n  \"a\": 1\n }\n}", "bad.json");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "bad.json:3:8: the avatar joint for 'a' must be a string or a list of strings");
  }
  try {
    (void)parseJointMap("{\n \"joints\": {\n  \"a\": \n }\n}", "broken.json");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("broken.json:4:", 0), 0u) << e.what();
  }
}

// Entry lines come from one pass over the text: a search per key was quadratic (6,500 keys
// in 64 KB took 5 s under the fuzzer). Nested values and escaped keys keep the count right.
TEST(JointMap, EntryLinesInOnePass) {
  try {
    (void)parseJointMap("{\n \"joints\": {\n  \"z\": {\"k\": \"v\"},\n  \"b\": 2\n }\n}", "nested.json");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "nested.json:4:8: the avatar joint for 'b' must be a string or a list of strings");
  }
  const JointMap escaped = parseJointMap("{\"name\": \"joints\",\n\"joints\": {\n\"\\u0062\": \"B\"}}", "e.json");
  ASSERT_EQ(escaped.entries.size(), 1u);
  EXPECT_EQ(escaped.entries[0].motionJoint, "b");
  EXPECT_EQ(escaped.entries[0].at.line, 3);
  EXPECT_EQ(escaped.entries[0].at.column, 1);
  EXPECT_EQ(escaped.entries[0].avatarAt.column, 11);
  std::string many = "{\"joints\": {";
  for (int i = 0; i < 6500; ++i) many += std::string(i ? "," : "") + "\n\"j" + std::to_string(i) + "\": \"b\"";
  many += "}}";
  const JointMap map = parseJointMap(many, "many.json");
  ASSERT_EQ(map.entries.size(), 6500u);
  EXPECT_EQ(map.entries.back().motionJoint, "j6499");
  EXPECT_EQ(map.entries.back().at.line, 6501);
  try {  // a motion joint written twice: nlohmann would keep the second pairing silently
    (void)parseJointMap("{\"joints\": {\n  \"Hips\": \"hips\",\n  \"Spine\": \"spine\",\n  \"Hips\": \"pelvis\"}}",
                        "twice.json");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "twice.json:4:3: key 'Hips' is written twice in one object (first at line 2, column 3); which one "
                 "counts is left open");
  }
  // The same name as a key of another object is no repeat.
  EXPECT_EQ(parseJointMap("{\"name\": \"n\", \"joints\": {\"name\": \"a\"}}", "other.json").entries.size(), 1u);
}

// A list value is a chain of avatar joints driven by one motion joint, in its order; a rig's
// map composes with a naming style's through drape's names, and only where both pair.
TEST(JointMap, ChainsParseInOrderAndMapsCompose) {
  const JointMap rig = parseJointMap(
      "{\"name\": \"rig\", \"joints\": {\n\"LeftUpLeg\": [\"thigh1\", \"thigh2\"],\n\"LeftLeg\": \"shin\"}}", "rig.json");
  ASSERT_EQ(rig.entries.size(), 3u);
  EXPECT_EQ(rig.entries[0].avatarJoint, "thigh1");
  EXPECT_EQ(rig.entries[1].avatarJoint, "thigh2");
  EXPECT_EQ(rig.entries[1].at.line, 2);
  EXPECT_EQ(rig.entries[1].avatarAt.line, 2);
  EXPECT_EQ(rig.entries[1].avatarAt.column, 25);
  EXPECT_EQ(*rig.avatarJointFor("LeftUpLeg"), "thigh1");  // the chain's head
  const JointMap style =
      parseJointMap("{\"name\": \"style\", \"joints\": {\"lThigh\": \"LeftUpLeg\", \"lShin\": \"LeftLeg\", \"lFoot\": \"LeftFoot\"}}",
                    "style.json");
  const JointMap both = composeJointMaps(style, rig);
  EXPECT_EQ(both.name, "style + rig");
  std::vector<std::string> pairs;  // lFoot drives nothing: the rig has no LeftFoot
  for (const JointMapEntry& e : both.entries) pairs.push_back(e.motionJoint + "->" + e.avatarJoint);
  EXPECT_EQ(pairs, (std::vector<std::string>{"lShin->shin", "lThigh->thigh1", "lThigh->thigh2"}));
  for (const char* bad : {"[]", "[\"a\", 2]", "[[\"a\"]]"}) {
    try {
      (void)parseJointMap(std::string("{\"joints\": {\n\"x\": ") + bad + "}}", "chain.json");
      FAIL() << bad;
    } catch (const Error& e) {
      EXPECT_STREQ(e.what(), "chain.json:2:6: the avatar joint for 'x' must be a string or a list of strings") << bad;
    }
  }
}

// Reversed, a map drives the avatar joints' names from the motion joints': one to one, the
// first written entry kept where two motion joints drove one avatar joint or one drove a
// chain; its places are the same words' places in the file.
TEST(JointMap, ReversedOneToOneTheFirstWrittenKept) {
  const JointMap style = parseJointMap(
      "{\"name\": \"style\", \"joints\": {\n\"lThigh\": \"LeftUpLeg\",\n\"Spine1\": \"Spine1\",\n\"Chest\": \"Spine1\",\n"
      "\"lShin\": [\"LeftLeg\", \"LeftLegTwist\"]}}",
      "style.json");
  const JointMap reversed = reverseJointMap(style);
  EXPECT_EQ(reversed.name, "style (reversed)");
  EXPECT_EQ(reversed.source, "style.json");
  std::vector<std::string> pairs;
  for (const JointMapEntry& e : reversed.entries) pairs.push_back(e.motionJoint + "->" + e.avatarJoint);
  EXPECT_EQ(pairs, (std::vector<std::string>{"LeftUpLeg->lThigh", "Spine1->Spine1", "LeftLeg->lShin"}));
  EXPECT_EQ(reversed.entries[0].at.line, 2);
  EXPECT_EQ(reversed.entries[0].at.column, 11);  // "LeftUpLeg", the value it was
  EXPECT_EQ(reversed.entries[0].avatarAt.column, 1);
  // Twice reversed, a one-to-one map is itself.
  const JointMap back = reverseJointMap(reverseJointMap(parseJointMap(
      "{\"name\": \"m\", \"joints\": {\"a\": \"A\", \"b\": \"B\"}}", "m.json")));
  ASSERT_EQ(back.entries.size(), 2u);
  EXPECT_EQ(back.entries[1].motionJoint, "b");
  EXPECT_EQ(back.entries[1].avatarJoint, "B");
  EXPECT_EQ(back.name, "m (reversed) (reversed)");
}

TEST(JointMap, MalformedCorpus) {
  // A number beyond double range used to be "bad JSON (...)" with no line or column.
  const std::string overflow = std::string(DRAPE_TEST_DATA_DIR) + "/bad/motion/map_number_overflow.json";
  try {
    (void)readJointMap(overflow);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), overflow + ":3:12: expected a finite number, found '-1e999'");
  }
}

TEST(AvatarAnimation, SubstepEndpointsEqualFramesExactly) {
  const Clip clip = tinyClip();
  scene::Avatar avatar;
  avatar.joints.push_back({"hips", -1, Vec3(0, 1, 0), Quat::Identity()});
  avatar.joints.push_back({"knee", 0, Vec3(0, 0.5, 0), Quat::Identity()});
  const AvatarAnimation anim = AvatarAnimation::build(avatar, clip, JointMap::identity(clip.skeleton));
  ASSERT_EQ(anim.frameCount(), 2u);
  std::vector<RigidTransform> out(2), inv(2);
  anim.evaluate(0, 0.0, out);
  for (std::size_t j = 0; j < 2; ++j) {
    EXPECT_EQ(out[j].translation, anim.frame(0)[j].translation);
    EXPECT_EQ(out[j].rotation.coeffs(), anim.frame(0)[j].rotation.coeffs());
  }
  anim.evaluate(0, 1.0, out);
  anim.evaluateInverse(0, 1.0, inv);
  for (std::size_t j = 0; j < 2; ++j) {
    EXPECT_EQ(out[j].translation, anim.frame(1)[j].translation);
    EXPECT_EQ(out[j].rotation.coeffs(), anim.frame(1)[j].rotation.coeffs());
    const RigidTransform id = out[j] * inv[j];
    EXPECT_NEAR(id.translation.norm(), 0.0, 1e-12);
    EXPECT_NEAR(id.rotation.angularDistance(Quat::Identity()), 0.0, 1e-12);
  }
  // Within the frame the separately interpolated inverse is not exactly the inverse (the
  // paper's scheme), but close for small motions; here the knee turns 90 degrees at once.
  anim.evaluate(0, 0.5, out);
  anim.evaluateInverse(0, 0.5, inv);
  EXPECT_NEAR((out[1] * inv[1]).rotation.angularDistance(Quat::Identity()), 0.0, 1e-12);
}

}  // namespace
}  // namespace drape::motion
