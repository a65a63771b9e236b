// H-Anim motions read from VRML97 files: the writer's interpolators read back frame by frame
// and between keys; interpolated Humanoid fields, Transforms between Joints and sensors of
// different cycles composed as VRML97 composes them; orientations along the shortest arc;
// files without a motion named in the error.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "drape/core/error.hpp"
#include "drape/formats/hanim_motion.hpp"
#include "drape/formats/hanim_writer.hpp"
#include "drape/formats/vrml_read.hpp"
#include "drape/formats/vrml_write.hpp"
#include "drape/testing/errors.hpp"
#include "drape/testing/temp_dir.hpp"
#include "hanim_walker.hpp"

namespace drape::formats {
namespace {

std::string writeText(const std::string& name, const std::string& text) {
  const std::string path = drape::testing::processTempDir("hanim-motion").string() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

// The root walks and turns, its child, the knee, swings (hanim_walker.hpp).
HanimHumanoidData walker(std::size_t frames) { return testing::twoJointWalker(frames, "knee"); }

/// Where the walker's joints are at time t (s) and how far they turned from rest, from the
/// same keys: the root's fields at t (linear translation, rotation about one axis), its
/// child's rotation about its centre under it.
struct WalkerPose {
  Vec3 root, knee;
  Quat rootTurn, kneeTurn;
};
WalkerPose walkerAt(double t) {
  const double f = t * 25.0;
  const Quat turn(Eigen::AngleAxisd(0.05 * f, Vec3::UnitY()));
  const Quat swing(Eigen::AngleAxisd(-0.1 * f, Vec3::UnitX()));
  const Vec3 move(0, 0, 0.04 * f);
  const Vec3 root = Vec3(0, 1, 0) + move;  // T(move) T(c) R T(-c) applied to c
  const Vec3 knee = move + Vec3(0, 1, 0) + turn * (Vec3(0, 0.5, 0) - Vec3(0, 1, 0));
  return {root, knee, turn, turn * swing};
}

void expectPose(const SkinnedJointMotion& m, std::size_t frame, const WalkerPose& p, double tolerance) {
  const RigidTransform& root = m.frames[frame * 2];
  const RigidTransform& knee = m.frames[frame * 2 + 1];
  EXPECT_LT((root.translation - p.root).norm(), tolerance) << "frame " << frame;
  EXPECT_LT((knee.translation - p.knee).norm(), tolerance) << "frame " << frame;
  EXPECT_LT(root.rotation.angularDistance(p.rootTurn), tolerance) << "frame " << frame;
  EXPECT_LT(knee.rotation.angularDistance(p.kneeTurn), tolerance) << "frame " << frame;
}

// The writer's humanoid, read back at its own rate: one frame per key, each joint where the
// keys put it, to Coin's single precision (its quaternions' parts; a few 1e-7).
TEST(HanimMotion, ReadsTheWritersMotionBackFrameByFrame) {
  const std::string path = writeText("walker.wrl", hanimText(walker(9)));
  const std::vector<SkinnedJointMotion> motions = readHanimMotions(path, 25.0);
  ASSERT_EQ(motions.size(), 1u);
  const SkinnedJointMotion& m = motions[0];
  EXPECT_EQ(m.animation, "walker");
  EXPECT_EQ(m.animationNames, std::vector<std::string>{"walker"});
  EXPECT_EQ(m.joints, (std::vector<std::string>{"root", "knee"}));
  EXPECT_EQ(m.parents, (std::vector<int>{-1, 0}));
  ASSERT_EQ(m.frameCount(), 9u);
  EXPECT_NEAR(m.end_s, 0.32, 1e-9);
  EXPECT_LT((m.restCenters[0] - Vec3(0, 1, 0)).norm(), 1e-6);
  EXPECT_LT((m.restCenters[1] - Vec3(0, 0.5, 0)).norm(), 1e-6);
  EXPECT_NEAR(m.floor_m, 0.1, 1e-6) << "the shin's lowest point at rest";
  for (std::size_t f = 0; f < 9; ++f) expectPose(m, f, walkerAt(static_cast<double>(f) / 25.0), 2e-6);
}

// Sampled at twice the key rate, every other frame falls between two keys: positions
// linear, orientations along the arc between them (here about one axis, so the angle
// halfway), as a VRML97 browser plays them.
TEST(HanimMotion, SamplesBetweenTheKeysAsABrowserPlays) {
  const std::string path = writeText("walker50.wrl", hanimText(walker(9)));
  const SkinnedJointMotion m = readHanimMotion(path, 50.0);
  ASSERT_EQ(m.frameCount(), 17u);
  for (std::size_t f = 0; f < 17; ++f) expectPose(m, f, walkerAt(static_cast<double>(f) / 50.0), 2e-6);
}

// A hand-written humanoid: the Humanoid itself moves (its translation, over a 2 s clock), a
// Transform turned a quarter about z sits between the root Joint and the arm, and the arm
// swings about its own x on a 0.5 s clock that loops within the longer one.
constexpr const char* kMover = R"(#VRML V2.0 utf8
DEF H Humanoid {
  name "mover"
  humanoidBody [
    DEF Root Joint {
      name "root"
      center 0 1 0
      children [
        DEF Tilt Transform {
          rotation 0 0 1 1.5707963267948966
          children [
            DEF Arm Joint {
              name "arm"
              center 0.5 1 0
              children [
                Segment {
                  name "arm"
                  children [ Shape { geometry IndexedFaceSet {
                    coord Coordinate { point [ 0.5 1 0, 1 1 0, 0.5 1.1 0 ] } coordIndex [ 0 1 2 -1 ] } } ]
                }
              ]
            }
          ]
        }
      ]
    }
  ]
}
DEF Clock TimeSensor { cycleInterval 2 loop TRUE }
DEF Short TimeSensor { cycleInterval 0.5 loop TRUE }
DEF Move PositionInterpolator { key [ 0 1 ] keyValue [ 0 0 0, 2 0 0 ] }
DEF Swing OrientationInterpolator { key [ 0 1 ] keyValue [ 1 0 0 0, 1 0 0 1 ] }
ROUTE Clock.fraction_changed TO Move.set_fraction
ROUTE Move.value_changed TO H.set_translation
ROUTE Short.fraction_changed TO Swing.set_fraction
ROUTE Swing.value_changed TO Arm.set_rotation
)";

TEST(HanimMotion, ComposesTheHumanoidTheTransformsBetweenJointsAndEachSensorsCycle) {
  const std::string path = writeText("mover.wrl", kMover);
  const SkinnedJointMotion m = readHanimMotion(path, 10.0);
  EXPECT_EQ(m.animation, "mover");
  EXPECT_EQ(m.joints, (std::vector<std::string>{"root", "arm"}));
  EXPECT_EQ(m.parents, (std::vector<int>{-1, 0}));
  ASSERT_EQ(m.frameCount(), 21u) << "the longest clock, 2 s, at 10 Hz";
  // The quarter turn about z takes the arm's centre (0.5 1 0) to (-1 0.5 0).
  EXPECT_LT((m.restCenters[1] - Vec3(-1, 0.5, 0)).norm(), 1e-6);
  EXPECT_NEAR(m.floor_m, 0.5, 1e-6);
  for (std::size_t f = 0; f < 21; ++f) {
    const double t = static_cast<double>(f) / 10.0;
    double fraction = t / 0.5;  // the short clock loops: 1 at its end, then again from 0
    if (fraction > 1.0) fraction -= std::floor(fraction);
    const RigidTransform& root = m.frames[2 * f];
    const RigidTransform& arm = m.frames[2 * f + 1];
    EXPECT_LT((root.translation - Vec3(t, 1, 0)).norm(), 1e-6) << t;  // carried by the Humanoid
    EXPECT_LT(root.rotation.angularDistance(Quat::Identity()), 1e-6) << t;
    EXPECT_LT((arm.translation - Vec3(t - 1, 0.5, 0)).norm(), 1e-6) << t;
    // The arm's swing about its own x is, in the humanoid's axes, a turn about y.
    EXPECT_LT(arm.rotation.angularDistance(Quat(Eigen::AngleAxisd(fraction, Vec3::UnitY()))), 2e-6) << t;
  }
}

// A TimeSensor with `enabled FALSE` sends no fraction: what it would drive keeps its written
// value, and a humanoid that only disabled sensors would move has no motion.
TEST(HanimMotion, ADisabledSensorDrivesNothing) {
  std::string text = kMover;
  const std::string shortClock = "DEF Short TimeSensor { cycleInterval 0.5 loop TRUE }";
  ASSERT_NE(text.find(shortClock), std::string::npos);
  text.replace(text.find(shortClock), shortClock.size(), "DEF Short TimeSensor { cycleInterval 0.5 loop TRUE enabled FALSE }");
  const SkinnedJointMotion m = readHanimMotion(writeText("half-still.wrl", text), 10.0);
  ASSERT_EQ(m.frameCount(), 21u);
  for (std::size_t f = 0; f < 21; ++f) {
    const double t = static_cast<double>(f) / 10.0;
    EXPECT_LT((m.frames[2 * f].translation - Vec3(t, 1, 0)).norm(), 1e-6) << t;  // the enabled clock moves it
    EXPECT_LT(m.frames[2 * f + 1].rotation.angularDistance(Quat::Identity()), 1e-6) << t;  // the arm stays
  }
  const std::string clock = "DEF Clock TimeSensor { cycleInterval 2 loop TRUE }";
  text.replace(text.find(clock), clock.size(), "DEF Clock TimeSensor { cycleInterval 2 loop TRUE enabled FALSE }");
  const std::string still = writeText("all-still.wrl", text);
  EXPECT_NE(drape::testing::errorOf([&] { (void)readHanimMotion(still, 10.0); })
                .find(still + ": Humanoid 'mover' has no motion: no interpolator that an enabled TimeSensor drives is routed "
                              "into its Joints"),
            std::string::npos);
}

// VRML97 interpolates orientations along the shortest arc, not the four numbers linearly:
// halfway from 1 rad about x to 1 rad about y is the quaternions' slerp.
TEST(HanimMotion, OrientationsAreInterpolatedAlongTheShortestArc) {
  const std::string path = writeText("arc.wrl", R"(#VRML V2.0 utf8
DEF T Transform { }
DEF Clock TimeSensor { cycleInterval 1 }
DEF Turn OrientationInterpolator { key [ 0 1 ] keyValue [ 1 0 0 1, 0 1 0 -2 ] }
ROUTE Clock.fraction_changed TO Turn.set_fraction
ROUTE Turn.value_changed TO T.set_rotation
)");
  const vrml::Document d = vrml::readFile(path);
  std::int32_t t = -1;
  for (std::size_t i = 0; i < d.nodes.size(); ++i)
    if (d.nodes[i].def == "T") t = static_cast<std::int32_t>(i);
  ASSERT_GE(t, 0);
  const Quat a(Eigen::AngleAxisd(1.0, Vec3::UnitX())), b(Eigen::AngleAxisd(-2.0, Vec3::UnitY()));
  for (const double w : {0.0, 0.25, 0.5, 0.9, 1.0}) {
    const std::vector<double> r = vrml::sampleAnimatedField(d, t, "rotation", w);
    ASSERT_EQ(r.size(), 4u);
    const Quat got(Eigen::AngleAxisd(r[3], Vec3(r[0], r[1], r[2]).normalized()));
    EXPECT_LT(got.angularDistance(a.slerp(w, b)), 1e-6) << w;
  }
}

TEST(HanimMotion, AFileWithoutAMotionSaysWhatIsMissing) {
  const std::string none = writeText("none.wrl", "#VRML V2.0 utf8\nTransform { }\n");
  EXPECT_NE(drape::testing::errorOf([&] { (void)readHanimMotion(none, 30.0); })
                .find(none + ": has no H-Anim Humanoid to take a motion from"),
            std::string::npos);
  EXPECT_TRUE(readHanimMotions(none, 30.0).empty());

  HanimHumanoidData still = walker(1);
  still.name = "still";
  still.motion.reset();
  const std::string atRest = writeText("still.wrl", hanimText(still));
  EXPECT_NE(drape::testing::errorOf([&] { (void)readHanimMotion(atRest, 30.0); })
                .find(atRest + ": Humanoid 'still' has no motion: no interpolator that an enabled TimeSensor drives is routed "
                               "into its Joints"),
            std::string::npos);
  EXPECT_TRUE(readHanimMotions(atRest, 30.0).empty());

  const std::string mover = writeText("mover2.wrl", kMover);
  EXPECT_EQ(readHanimMotion(mover, 10.0, "0").animation, "mover");
  EXPECT_NE(drape::testing::errorOf([&] { (void)readHanimMotion(mover, 10.0, "dance"); })
                .find(mover + ": has no animation 'dance' (it has 1: 0 'mover')"),
            std::string::npos);
}

}  // namespace
}  // namespace drape::formats
