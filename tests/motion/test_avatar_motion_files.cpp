// An avatar's motion written into its own Collada or FBX file and played back from there
// (AvatarAnimation::toJointMotion, formats::writeAssimpSkinnedModel, fromJointMotion): the
// MakeHuman body's retargeted CMU walk comes back joint for joint, exactly through the
// in-memory round trip and within what each file's keys keep through the files. And the
// body with its joints named in another style (Mixamo's, H-Anim's): a file in that style
// drives it through the style's shipped map, and the CMU capture drives the renamed body
// through that map reversed.

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "drape/formats/assimp_avatar.hpp"
#include "drape/formats/avatar_motion.hpp"
#include "drape/motion/animation.hpp"
#include "drape/motion/clip_io.hpp"
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

// Mixamo's names for the MakeHuman body's joints (drape's name -> Mixamo's, without the
// "mixamorig:" prefix); Mixamo's rig has no hip joints between the pelvis and the thighs
// (MakeHuman's LHipJoint, RHipJoint), no second neck joint and no finger base.
const std::map<std::string, std::string>& mixamoNames() {
  static const std::map<std::string, std::string> names = {
      {"Hips", "Hips"},           {"LowerBack", "Spine"},       {"Spine", "Spine1"},          {"Spine1", "Spine2"},
      {"Neck", "Neck"},           {"Head", "Head"},             {"LeftUpLeg", "LeftUpLeg"},   {"LeftLeg", "LeftLeg"},
      {"LeftFoot", "LeftFoot"},   {"LeftToeBase", "LeftToeBase"}, {"RightUpLeg", "RightUpLeg"}, {"RightLeg", "RightLeg"},
      {"RightFoot", "RightFoot"}, {"RightToeBase", "RightToeBase"}, {"LeftShoulder", "LeftShoulder"},
      {"LeftArm", "LeftArm"},     {"LeftForeArm", "LeftForeArm"}, {"LeftHand", "LeftHand"},
      {"RightShoulder", "RightShoulder"}, {"RightArm", "RightArm"}, {"RightForeArm", "RightForeArm"},
      {"RightHand", "RightHand"}};
  return names;
}

// The H-Anim 1.1 Joints of a humanoid at the third level of articulation that match the
// MakeHuman body's (drape's name -> H-Anim's): H-Anim's pelvis (sacroiliac) is one joint
// where MakeHuman has one per hip, which stay out.
const std::map<std::string, std::string>& hanimNames() {
  static const std::map<std::string, std::string> names = {
      {"Hips", "HumanoidRoot"},    {"LeftUpLeg", "l_hip"},        {"LeftLeg", "l_knee"},         {"LeftFoot", "l_ankle"},
      {"LeftToeBase", "l_metatarsal"}, {"RightUpLeg", "r_hip"},   {"RightLeg", "r_knee"},        {"RightFoot", "r_ankle"},
      {"RightToeBase", "r_metatarsal"}, {"LowerBack", "vl5"},     {"Spine", "vt10"},             {"Spine1", "vt1"},
      {"Neck", "vc4"},             {"Neck1", "vc2"},              {"Head", "skullbase"},         {"LeftShoulder", "l_sternoclavicular"},
      {"LeftArm", "l_shoulder"},   {"LeftForeArm", "l_elbow"},    {"LeftHand", "l_wrist"},       {"LeftFingerBase", "l_index0"},
      {"LeftHandFinger1", "l_index1"}, {"LThumb", "l_thumb1"},   {"RightShoulder", "r_sternoclavicular"},
      {"RightArm", "r_shoulder"},  {"RightForeArm", "r_elbow"},   {"RightHand", "r_wrist"},      {"RightFingerBase", "r_index0"},
      {"RightHandFinger1", "r_index1"}, {"RThumb", "r_thumb1"}};
  return names;
}

// VRoid Studio's names for the MakeHuman body's joints (drape's name -> VRoid's): its spine
// runs Spine, Chest, UpperChest, Neck with the shoulders on UpperChest; like Mixamo's, no
// hip joints, no second neck joint, no finger base.
const std::map<std::string, std::string>& vroidNames() {
  static const std::map<std::string, std::string> names = {
      {"Hips", "J_Bip_C_Hips"},         {"LowerBack", "J_Bip_C_Spine"},      {"Spine", "J_Bip_C_Chest"},
      {"Spine1", "J_Bip_C_UpperChest"}, {"Neck", "J_Bip_C_Neck"},            {"Head", "J_Bip_C_Head"},
      {"LeftUpLeg", "J_Bip_L_UpperLeg"}, {"LeftLeg", "J_Bip_L_LowerLeg"},    {"LeftFoot", "J_Bip_L_Foot"},
      {"LeftToeBase", "J_Bip_L_ToeBase"}, {"RightUpLeg", "J_Bip_R_UpperLeg"}, {"RightLeg", "J_Bip_R_LowerLeg"},
      {"RightFoot", "J_Bip_R_Foot"},    {"RightToeBase", "J_Bip_R_ToeBase"}, {"LeftShoulder", "J_Bip_L_Shoulder"},
      {"LeftArm", "J_Bip_L_UpperArm"},  {"LeftForeArm", "J_Bip_L_LowerArm"}, {"LeftHand", "J_Bip_L_Hand"},
      {"LeftHandFinger1", "J_Bip_L_Index1"}, {"LThumb", "J_Bip_L_Thumb1"},  {"RightShoulder", "J_Bip_R_Shoulder"},
      {"RightArm", "J_Bip_R_UpperArm"}, {"RightForeArm", "J_Bip_R_LowerArm"}, {"RightHand", "J_Bip_R_Hand"},
      {"RightHandFinger1", "J_Bip_R_Index1"}, {"RThumb", "J_Bip_R_Thumb1"}};
  return names;
}

// A joint's name in a style: its own there, or, where the style has none, a name of its own
// that no map knows.
std::string renamed(const std::map<std::string, std::string>& names, const std::string& prefix, const std::string& name) {
  const auto it = names.find(name);
  return prefix + (it == names.end() ? "drape" + name : it->second);
}

// How far `animation`, of the MakeHuman body or of that body with its joints renamed (same
// order), strays from walk(): the joints that the style names and whose ancestors it all
// names are where the walk puts them; below a joint it does not name (the hip joints,
// following their parents), a joint hangs a few centimetres from where the capture swung
// it, but turned as the walk turns it.
struct Strays {
  double position = 0.0;    ///< m, of the joints the style names all the way up
  double hangingTurn = 0.0; ///< rad, of the joints below one it does not name
};

Strays straysFromTheWalk(const AvatarAnimation& animation, const std::map<std::string, std::string>& names) {
  Strays s;
  for (const auto& [avatarJoint, unused] : names) {
    const auto j = static_cast<std::size_t>(makeHuman().findJoint(avatarJoint));
    bool hangs = false;
    for (int p = makeHuman().joints[j].parent; p >= 0; p = makeHuman().joints[static_cast<std::size_t>(p)].parent)
      hangs = hangs || names.count(makeHuman().joints[static_cast<std::size_t>(p)].name) == 0;
    for (std::size_t f = 0; f < walk().frameCount(); ++f) {
      const RigidTransform& a = animation.frame(f)[j];
      const RigidTransform& b = walk().frame(f)[j];
      if (hangs) s.hangingTurn = std::max(s.hangingTurn, a.rotation.angularDistance(b.rotation));
      else s.position = std::max(s.position, (a.translation - b.translation).norm());
    }
  }
  return s;
}

TEST(AvatarMotionFiles, AMixamoRiggedFileIsRetargetedThroughTheShippedMap) {
  // The MakeHuman body and its walk with the joints named as Mixamo names them (the joints
  // Mixamo's rig lacks keep a prefixed name of their own), as FBX: played on the MakeHuman
  // avatar, whose joint names it does not share, it is retargeted through the shipped
  // 'mixamo' map, found by itself, and walks as the walk it was made of.
  const auto rename = [](const std::string& name) { return renamed(mixamoNames(), "mixamorig:", name); };
  formats::SkinnedModel model = scene::skinnedModelOf(makeHuman());
  for (formats::SkinnedJoint& j : model.joints) j.name = rename(j.name);
  formats::SkinnedJointMotion motion = walk().toJointMotion(makeHuman(), "mixamo.com");
  for (std::string& j : motion.joints) j = rename(j);
  const std::string path = (drape::testing::processTempDir("avatar-motion") / "mixamo_walk.fbx").string();
  formats::writeAssimpSkinnedModel(path, model, {motion});

  MotionOptions options;
  options.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  // The walk in the file is grounded already; grounded again, the legs that hang otherwise
  // would move the whole body by their few centimetres.
  options.retarget.groundFeet = false;
  JointMap chosen;
  const AvatarAnimation retargeted = loadAnimation(makeHuman(), path, options, nullptr, &chosen);
  EXPECT_EQ(chosen.name, "mixamo");
  ASSERT_EQ(retargeted.frameCount(), walk().frameCount());
  // The same skeleton on both sides, the root's path scaled by a leg-length ratio of 1 and
  // the file's floor taken as the body's. Measured: 6e-6 m and 3e-6 rad (FBX's six digits).
  const Strays s = straysFromTheWalk(retargeted, mixamoNames());
  EXPECT_LT(s.position, 1e-4);
  EXPECT_LT(s.hangingTurn, 1e-4);
}

struct Style {
  const char* name;
  const std::map<std::string, std::string>& (*names)();
  const char* prefix;
  const char* map;  ///< the map drape chooses to drive the style's avatar from the capture
};

void PrintTo(const Style& style, std::ostream* os) { *os << style.name; }

class CaptureOnAStyledAvatar : public ::testing::TestWithParam<Style> {};

// The bundled CMU capture (MotionBuilder names, drape's own but for the index finger) onto
// the MakeHuman body with its joints named in another style: no shipped map goes from
// drape's names to that style's, so drape takes the style's map reversed (after the
// MotionBuilder map where that brings the finger to drape's name). The body then moves
// exactly as the MakeHuman body under drape's names does through a map that pairs the same
// joints: the same rest corrections, the same stride (the legs found by the capture's
// names) and the same floor. The joints the style lacks (MakeHuman's hip joints, which
// CMU captures swing by a few centimetres) follow their parents in both.
TEST_P(CaptureOnAStyledAvatar, MovesAsTheBodyDoesThroughTheSamePairs) {
  const Style style = GetParam();
  scene::Avatar avatar = makeHuman();
  for (scene::Joint& j : avatar.joints) j.name = renamed(style.names(), style.prefix, j.name);
  const std::string capture = std::string(DRAPE_SOURCE_DIR) + "/examples/walking_skirt/walk.bvh";
  MotionOptions options;
  options.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  JointMap chosen;
  const AvatarAnimation styled = loadAnimation(avatar, capture, options, nullptr, &chosen);
  EXPECT_EQ(chosen.name, style.map);

  // The same pairs under drape's names: the MotionBuilder map, but only onto joints the
  // style names.
  nlohmann::json same = {{"name", "same pairs"}, {"joints", nlohmann::json::object()}};
  for (const JointMapEntry& e : readJointMap(options.jointMapDirectory + "/motionbuilder.json").entries)
    if (style.names().count(e.avatarJoint) != 0) same["joints"][e.motionJoint] = e.avatarJoint;
  EXPECT_EQ(same["joints"].size(), matchedJointCount(chosen, loadClip(capture).skeleton, avatar));
  options.jointMapPath = (drape::testing::processTempDir("avatar-motion") / (std::string(style.name) + "_pairs.json")).string();
  std::ofstream(options.jointMapPath) << same.dump(2);
  const AvatarAnimation plain = loadAnimation(makeHuman(), capture, options);
  ASSERT_EQ(styled.frameCount(), plain.frameCount());
  const Worst w = difference(styled, plain);
  EXPECT_LT(w.angle, 1e-12);
  EXPECT_LT(w.position, 1e-12);
}

INSTANTIATE_TEST_SUITE_P(Styles, CaptureOnAStyledAvatar,
                         ::testing::Values(Style{"Mixamo", &mixamoNames, "mixamorig:", "mixamo (reversed)"},
                                           Style{"HAnim", &hanimNames, "", "motionbuilder + hanim (reversed)"},
                                           Style{"VRoid", &vroidNames, "", "motionbuilder + vroid (reversed)"}),
                         [](const auto& info) { return std::string(info.param.name); });

INSTANTIATE_TEST_SUITE_P(Formats, AvatarMotionFile, ::testing::Values(".dae", ".fbx"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param == ".dae" ? "Collada" : "Fbx"; });

}  // namespace
}  // namespace drape::motion
