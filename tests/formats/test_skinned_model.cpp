// The rules the skinned-model readers (Assimp, glTF) share for sampling animations: which
// animation a name picks, how many frames a time span holds, and the cap on what all of a
// file's animations together may hold.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "drape/formats/skinned_model.hpp"
#include "drape/testing/errors.hpp"

namespace drape::formats::detail {
namespace {

using testing::errorOf;

SkinnedJointMotion motionOf(std::size_t frames, std::size_t joints, const std::string& name) {
  SkinnedJointMotion m;
  m.animation = name;
  m.joints.assign(joints, "joint");
  m.frames.assign(frames * joints, RigidTransform{});
  return m;
}

TEST(SkinnedModelRules, AnAnimationIsPickedByNameByIndexOrFirst) {
  const std::vector<std::string> names{"walk", "animation 1", "12"};
  EXPECT_EQ(chooseAnimation(names, "", "f.glb"), 0u);
  EXPECT_EQ(chooseAnimation(names, "walk", "f.glb"), 0u);
  EXPECT_EQ(chooseAnimation(names, "animation 1", "f.glb"), 1u);
  EXPECT_EQ(chooseAnimation(names, "1", "f.glb"), 1u);
  // A name made of digits is a name first: "12" is the third animation, not index 12.
  EXPECT_EQ(chooseAnimation(names, "12", "f.glb"), 2u);
  EXPECT_EQ(errorOf([&] { (void)chooseAnimation(names, "run", "f.glb"); }),
            "f.glb: has no animation 'run' (it has 3: 0 'walk', 1 'animation 1', 2 '12')");
  EXPECT_EQ(errorOf([&] { (void)chooseAnimation(names, "3", "f.glb"); }),
            "f.glb: has no animation '3' (it has 3: 0 'walk', 1 'animation 1', 2 '12')");
  EXPECT_EQ(errorOf([&] { (void)chooseAnimation({}, "", "f.glb"); }), "f.glb: has no animation");
  EXPECT_EQ(animationName("", 4), "animation 4");
  EXPECT_EQ(animationName("idle", 4), "idle");
}

TEST(SkinnedModelRules, ATimeSpanHoldsBothEndsAndASinglePrecisionLastKey) {
  EXPECT_EQ(motionFrameCount(0.0, 0.0, 30.0, 10, "a", "f"), 1u);
  EXPECT_EQ(motionFrameCount(0.0, 1.0, 30.0, 10, "a", "f"), 31u);
  // 140 frames at 30 Hz end at 4.6666665 s in single precision; the last frame is kept.
  EXPECT_EQ(motionFrameCount(0.0, static_cast<double>(4.6666665f), 30.0, 10, "a", "f"), 141u);
  // Starting late counts from the first key.
  EXPECT_EQ(motionFrameCount(2.0, 3.0, 24.0, 10, "a", "f"), 25u);
  EXPECT_EQ(errorOf([] { (void)motionFrameCount(0.0, 1.0, 0.0, 10, "a", "f"); }), "f: a motion rate of 0 frames per second");
  EXPECT_EQ(errorOf([] { (void)motionFrameCount(0.0, 1.0, -30.0, 10, "a", "f"); }),
            "f: a motion rate of -30 frames per second");
  // 10,000 s at 1,000 Hz of 10 joints is 100,010,010 transforms, over the cap.
  EXPECT_EQ(errorOf([] { (void)motionFrameCount(0.0, 10'000.0, 1'000.0, 10, "walk", "f"); }),
            "f: animation 'walk' lasts 10000 s: 1e+07 frames of 10 joints at 1000 Hz are more than drape samples "
            "(10000000)");
}

TEST(SkinnedModelRules, AFilesAnimationsTogetherStayWithinTheCap) {
  std::vector<SkinnedJointMotion> motions;
  appendWithinCap(motions, motionOf(40, 5, "walk"), "f.fbx", 500);  // 200 transforms
  appendWithinCap(motions, motionOf(60, 5, "run"), "f.fbx", 500);   // 500 in all: at the cap, kept
  ASSERT_EQ(motions.size(), 2u);
  EXPECT_EQ(motions[1].animation, "run");
  EXPECT_EQ(motions[1].frameCount(), 60u);
  EXPECT_EQ(errorOf([&] { appendWithinCap(motions, motionOf(1, 5, "idle"), "f.fbx", 500); }),
            "f.fbx: its animations together hold more than the 500 joint transforms drape samples at 30 Hz");
  EXPECT_EQ(motions.size(), 2u) << "a motion over the cap is not appended";
}

}  // namespace
}  // namespace drape::formats::detail
