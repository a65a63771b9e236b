// An avatar's motion written into its own Collada or FBX file and played back from there
// (AvatarAnimation::toJointMotion, formats::writeAssimpSkinnedModel, fromJointMotion): the
// MakeHuman body's retargeted CMU walk comes back joint for joint, exactly through the
// in-memory round trip and within what each file's keys keep through the files.

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <string>

#include "drape/formats/assimp_avatar.hpp"
#include "drape/formats/avatar_motion.hpp"
#include "drape/motion/animation.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "makehuman.hpp"
#include "drape/testing/temp_dir.hpp"

namespace drape::motion {
namespace {

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

TEST(AvatarMotionFiles, AMixamoRiggedFileIsRetargetedThroughTheShippedMap) {
  // The MakeHuman body and its walk with the joints named as Mixamo names them (the joints
  // Mixamo's rig lacks keep a prefixed name of their own), as FBX: played on the MakeHuman
  // avatar, whose joint names it does not share, it is retargeted through the shipped
  // 'mixamo' map, found by itself, and walks as the walk it was made of.
  const std::map<std::string, std::string> mixamo = {
      {"Hips", "Hips"},           {"LowerBack", "Spine"},       {"Spine", "Spine1"},          {"Spine1", "Spine2"},
      {"Neck", "Neck"},           {"Head", "Head"},             {"LeftUpLeg", "LeftUpLeg"},   {"LeftLeg", "LeftLeg"},
      {"LeftFoot", "LeftFoot"},   {"LeftToeBase", "LeftToeBase"}, {"RightUpLeg", "RightUpLeg"}, {"RightLeg", "RightLeg"},
      {"RightFoot", "RightFoot"}, {"RightToeBase", "RightToeBase"}, {"LeftShoulder", "LeftShoulder"},
      {"LeftArm", "LeftArm"},     {"LeftForeArm", "LeftForeArm"}, {"LeftHand", "LeftHand"},
      {"RightShoulder", "RightShoulder"}, {"RightArm", "RightArm"}, {"RightForeArm", "RightForeArm"},
      {"RightHand", "RightHand"}};
  const auto rename = [&](const std::string& name) {
    const auto it = mixamo.find(name);
    return "mixamorig:" + (it == mixamo.end() ? "drape" + name : it->second);
  };
  formats::SkinnedModel model = scene::skinnedModelOf(makeHuman());
  for (formats::SkinnedJoint& j : model.joints) j.name = rename(j.name);
  formats::SkinnedJointMotion motion = walk().toJointMotion(makeHuman(), "mixamo.com");
  for (std::string& j : motion.joints) j = rename(j);
  const std::string path = (drape::testing::processTempDir("avatar-motion") / "mixamo_walk.fbx").string();
  formats::writeAssimpSkinnedModel(path, model, {motion});

  MotionOptions options;
  options.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  // The walk in the file is grounded already; grounded again, the legs that hang otherwise
  // (below) would move the whole body by their few centimetres.
  options.retarget.groundFeet = false;
  JointMap chosen;
  const AvatarAnimation retargeted = loadAnimation(makeHuman(), path, options, nullptr, &chosen);
  EXPECT_EQ(chosen.name, "mixamo");
  ASSERT_EQ(retargeted.frameCount(), walk().frameCount());
  // The same skeleton on both sides, the root's path scaled by a leg-length ratio of 1 and
  // the file's floor taken as the body's. Mixamo's rig has no hip joints between the pelvis
  // and the thighs (MakeHuman's LHipJoint, RHipJoint) nor a second neck joint: those now
  // follow their parents, so the legs and the head hang a few centimetres from where the
  // capture swung them, turned as the walk turns them. Every other joint follows the walk.
  double worstPosition = 0.0, worstHangingTurn = 0.0;
  for (const auto& [avatarJoint, unused] : mixamo) {
    const auto j = static_cast<std::size_t>(makeHuman().findJoint(avatarJoint));
    // Below a joint Mixamo lacks (the hip joints, MakeHuman's second neck joint): turned as
    // the walk turns it, placed where the unmapped joint, following its parent, puts it.
    bool hangs = false;
    for (int p = makeHuman().joints[j].parent; p >= 0; p = makeHuman().joints[static_cast<std::size_t>(p)].parent)
      hangs = hangs || mixamo.count(makeHuman().joints[static_cast<std::size_t>(p)].name) == 0;
    for (std::size_t f = 0; f < walk().frameCount(); ++f) {
      const RigidTransform& a = retargeted.frame(f)[j];
      const RigidTransform& b = walk().frame(f)[j];
      if (hangs) worstHangingTurn = std::max(worstHangingTurn, a.rotation.angularDistance(b.rotation));
      else worstPosition = std::max(worstPosition, (a.translation - b.translation).norm());
    }
  }
  // Measured: 6e-6 m and 3e-6 rad (FBX's six digits).
  EXPECT_LT(worstPosition, 1e-4);
  EXPECT_LT(worstHangingTurn, 1e-4);
}

INSTANTIATE_TEST_SUITE_P(Formats, AvatarMotionFile, ::testing::Values(".dae", ".fbx"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param == ".dae" ? "Collada" : "Fbx"; });

}  // namespace
}  // namespace drape::motion
