// An avatar's motion written into its own Collada or FBX file and played back from there
// (AvatarAnimation::toJointMotion, formats::writeAssimpSkinnedModel, fromJointMotion): the
// MakeHuman body's retargeted CMU walk comes back joint for joint, exactly through the
// in-memory round trip and within what each file's keys keep through the files.

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "drape/formats/assimp_avatar.hpp"
#include "drape/formats/avatar_motion.hpp"
#include "drape/motion/animation.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/testing/temp_dir.hpp"

namespace drape::motion {
namespace {

const scene::Avatar& makeHuman() {
  static const scene::Avatar avatar =
      scene::loadAvatarFile(std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_rig_cmu_mb.mhskel");
  return avatar;
}

const AvatarAnimation& walk() {
  static const AvatarAnimation animation = [] {
    MotionOptions options;
    options.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
    return loadAnimation(makeHuman(), std::string(DRAPE_SOURCE_DIR) + "/examples/walking_skirt/walk.bvh", options);
  }();
  return animation;
}

struct Worst {
  double angle = 0.0, position = 0.0;
};

Worst difference(const AvatarAnimation& a, const AvatarAnimation& b) {
  Worst w;
  for (std::size_t f = 0; f < a.frameCount(); ++f)
    for (std::size_t j = 0; j < a.jointCount(); ++j) {
      w.angle = std::max(w.angle, a.frame(f)[j].rotation.angularDistance(b.frame(f)[j].rotation));
      w.position = std::max(w.position, (a.frame(f)[j].translation - b.frame(f)[j].translation).norm());
    }
  return w;
}

TEST(AvatarMotionFiles, ToJointMotionIsTheInverseOfFromJointMotion) {
  const formats::SkinnedJointMotion motion = walk().toJointMotion(makeHuman(), "walk");
  EXPECT_EQ(motion.animation, "walk");
  EXPECT_EQ(motion.frameCount(), walk().frameCount());
  EXPECT_NEAR(motion.end_s, walk().duration(), 1e-12);
  const AvatarAnimation back = AvatarAnimation::fromJointMotion(makeHuman(), motion, "memory");
  ASSERT_EQ(back.frameCount(), walk().frameCount());
  const Worst w = difference(back, walk());
  EXPECT_LT(w.angle, 1e-9);
  EXPECT_LT(w.position, 1e-12);
}

class AvatarMotionFile : public ::testing::TestWithParam<std::string> {};

TEST_P(AvatarMotionFile, TheRetargetedWalkPlaysBackFromTheAvatarsFile) {
  const std::string path = (drape::testing::processTempDir("avatar-motion") / ("walker" + GetParam())).string();
  formats::writeAssimpSkinnedModel(path, scene::skinnedModelOf(makeHuman()), {walk().toJointMotion(makeHuman(), "walk")});
  const AvatarAnimation back =
      AvatarAnimation::fromJointMotion(makeHuman(), formats::readAvatarMotion(path, walk().rate()), path);
  ASSERT_EQ(back.frameCount(), walk().frameCount());
  const Worst w = difference(back, walk());
  // Single-precision Collada matrices; FBX's six digits (centimetres, Euler degrees).
  // Measured: 2e-6 rad and 1e-6 m for Collada, 3e-6 rad and 7e-6 m for FBX.
  const bool fbx = GetParam() == ".fbx";
  EXPECT_LT(w.angle, fbx ? 5e-5 : 2e-5);
  EXPECT_LT(w.position, fbx ? 5e-5 : 1e-5);
}

INSTANTIATE_TEST_SUITE_P(Formats, AvatarMotionFile, ::testing::Values(".dae", ".fbx"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param == ".dae" ? "Collada" : "Fbx"; });

}  // namespace
}  // namespace drape::motion
