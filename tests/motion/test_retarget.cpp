// CMU walks retargeted onto the MakeHuman body: feet meet the floor once per gait cycle
// without sinking through it, and the hips follow the scaled root path; a body whose rest
// pose faces another way is turned to face as the capture does.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <tuple>

#include "drape/core/error.hpp"
#include "drape/motion/animation.hpp"
#include "drape/motion/clip_io.hpp"
#include "drape/motion/jointmap.hpp"
#include "drape/scene/avatar_makehuman.hpp"
#include "hanim_loa1.hpp"
#include "limb_angles.hpp"

namespace drape::motion {
namespace {

const scene::Avatar& makeHuman() {
  static const scene::Avatar avatar = [] {
    scene::MakeHumanAvatarOptions options;
    options.directory = std::string(DRAPE_DATA_DIR) + "/avatars";
    return scene::buildMakeHumanAvatar(options);
  }();
  return avatar;
}

std::vector<JointMap> shippedMaps() { return readJointMapDirectory(std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps"); }

double floorOf(const scene::Avatar& avatar) {
  double floor = 1e300;
  for (const scene::Segment& s : avatar.segments)
    for (const Vec3& v : s.mesh.positions) floor = std::min(floor, avatar.joints[static_cast<std::size_t>(s.joint)].restWorld().apply(v).y());
  return floor;
}

// Lowest point of both feet (foot and toe segments) per frame, relative to the floor.
std::vector<double> lowestFootHeights(const scene::Avatar& avatar, const AvatarAnimation& anim) {
  const double floor = floorOf(avatar);
  std::vector<double> lowest(anim.frameCount(), 1e300);
  for (std::size_t f = 0; f < anim.frameCount(); ++f) {
    const auto world = anim.frame(f);
    for (const scene::Segment& s : avatar.segments) {
      if (s.name.find("Foot") == std::string::npos && s.name.find("Toe") == std::string::npos) continue;
      for (const Vec3& v : s.mesh.positions)
        lowest[f] = std::min(lowest[f], world[static_cast<std::size_t>(s.joint)].apply(v).y() - floor);
    }
  }
  return lowest;
}

void checkWalk(const std::string& file) {
  const scene::Avatar& avatar = makeHuman();
  const Clip clip = loadClip(std::string(DRAPE_DATA_DIR) + "/mocap/" + file);
  const JointMap map = chooseJointMap(shippedMaps(), clip.skeleton, avatar);
  const AvatarAnimation anim = AvatarAnimation::build(avatar, clip, map);
  ASSERT_GT(anim.frameCount(), 60u);
  const std::vector<double> lowest = lowestFootHeights(avatar, anim);

  // A walking gait cycle lasts about a second; in every one-second window a foot is planted.
  // Windows of one second cover the clip; a short tail joins the window before it.
  const auto window = static_cast<std::size_t>(anim.rate());
  std::vector<std::pair<std::size_t, std::size_t>> windows;
  for (std::size_t start = 0; start < lowest.size(); start += window) windows.emplace_back(start, std::min(start + window, lowest.size()));
  if (windows.size() > 1 && windows.back().second - windows.back().first < window / 2) {
    windows[windows.size() - 2].second = windows.back().second;
    windows.pop_back();
  }
  double highestWindowLow = -1e300;
  for (const auto& [begin, end] : windows) {
    const double low = *std::min_element(lowest.begin() + static_cast<std::ptrdiff_t>(begin), lowest.begin() + static_cast<std::ptrdiff_t>(end));
    highestWindowLow = std::max(highestWindowLow, low);
    EXPECT_LT(std::abs(low), 0.02) << file << ": frames " << begin << ".." << end;
  }
  const double deepest = *std::min_element(lowest.begin(), lowest.end());
  EXPECT_GT(deepest, -0.02) << file;
  std::printf("%s: map %s, root scale %.4f, deepest foot point %.1f mm, highest per-second low %.1f mm\n", file.c_str(),
              map.name.c_str(), anim.rootScale(), deepest * 1000.0, highestWindowLow * 1000.0);

  // The hips follow the BVH root path scaled by the leg-length ratio, from where the
  // avatar stands at rest, less the smooth ground correction (which stays small and slow).
  const auto hips = static_cast<std::size_t>(avatar.findJoint("Hips"));
  const double k = anim.rootScale();
  EXPECT_GT(k, 0.8);
  EXPECT_LT(k, 1.2);
  EXPECT_DOUBLE_EQ(anim.rootHeightOffset(), floorOf(avatar));
  // The ground correction is slow (under 15 cm/s) and bounded; it absorbs the capture
  // floor's tilt and offset (the Daz-style file's floor lies about 10 cm below its y = 0).
  const auto ground = anim.groundCorrection();
  for (std::size_t f = 0; f < ground.size(); ++f) {
    EXPECT_LT(std::abs(ground[f]), 0.25);
    if (f > 0) {
      EXPECT_LT(std::abs(ground[f] - ground[f - 1]), 0.005);
    }
  }
  std::printf("%s: ground correction %.1f .. %.1f mm\n", file.c_str(), *std::min_element(ground.begin(), ground.end()) * 1000.0,
              *std::max_element(ground.begin(), ground.end()) * 1000.0);
  const Vec3 rest = avatar.joints[hips].restCenter;
  const Vec3 r0 = clip.rootTranslations[0];
  for (std::size_t f = 0; f < anim.frameCount(); ++f) {
    const Vec3 r = clip.rootTranslations[f];
    const Vec3 expected(rest.x() + k * (r.x() - r0.x()), anim.rootHeightOffset() + k * r.y() - anim.groundCorrection()[f], rest.z() + k * (r.z() - r0.z()));
    EXPECT_LT((anim.frame(f)[hips].translation - expected).norm(), 0.02) << "frame " << f;
  }
}

// The paper's caveat (section 4.3.1): joints interpolated on their own drift apart within
// a frame. Measured at 33 substeps per 30 Hz frame, the default.
TEST(Retarget, JointSeparationWithinAFrameIsSmall) {
  const scene::Avatar& avatar = makeHuman();
  for (const char* file : {"cmu_walk_delfem2.bvh", "cmu_12_03_walk.bvh"}) {
    const Clip clip = loadClip(std::string(DRAPE_DATA_DIR) + "/mocap/" + file);
    const AvatarAnimation anim = AvatarAnimation::build(avatar, clip, chooseJointMap(shippedMaps(), clip.skeleton, avatar));
    const double separation = maxJointSeparation(anim, avatar, 33);
    std::printf("%s: largest joint separation within a frame %.2f mm\n", file, separation * 1000.0);
    EXPECT_GT(separation, 0.0);    // the effect is real ...
    EXPECT_LT(separation, 0.010);  // ... and small at 30 Hz
  }
}

TEST(Retarget, CmuWalkDelfem2OnMakeHuman) { checkWalk("cmu_walk_delfem2.bvh"); }
TEST(Retarget, CmuWalk12_03OnMakeHuman) { checkWalk("cmu_12_03_walk.bvh"); }
TEST(Retarget, DazStyleWalkOnMakeHuman) { checkWalk("cmu_02_02_walk_dazstyle.bvh"); }

// Where a hip bone and a clavicle sit on the pelvis and chest is the avatar's build: a
// capture whose own hip bones and clavicles never turn (the Daz-style walk: lButtock and
// lCollar are zero in every frame) leaves the avatar's thighs and shoulders where they are
// on its hips and chest. Turned onto the capture's hip bone (2.8 cm, down and back), the
// thighs' joints were carried up to 15 cm on the hips, and the shoulders 5 cm off the
// chest; a dress's yoke tore.
TEST(Retarget, ACapturesStillHipBonesAndClaviclesLeaveTheAvatarsBuildAsItIs) {
  const scene::Avatar& avatar = makeHuman();
  const Clip clip = loadClip(std::string(DRAPE_DATA_DIR) + "/mocap/cmu_02_02_walk_dazstyle.bvh");
  const JointMap map = chooseJointMap(shippedMaps(), clip.skeleton, avatar);
  ASSERT_EQ(map.name, "daz");
  const AvatarAnimation anim = AvatarAnimation::build(avatar, clip, map);
  const auto joint = [&](const char* name) {
    const int j = avatar.findJoint(name);
    EXPECT_GE(j, 0) << name;
    return static_cast<std::size_t>(j);
  };
  double farthest = 0.0;
  for (const auto& [trunk, carried] : {std::pair{"Hips", "LeftUpLeg"}, std::pair{"Hips", "RightUpLeg"},
                                       std::pair{"Spine1", "LeftArm"}, std::pair{"Spine1", "RightArm"}}) {
    const std::size_t t = joint(trunk), c = joint(carried);
    const Vec3 atRest = avatar.joints[t].restWorld().inverse().apply(avatar.joints[c].restCenter);
    for (std::size_t f = 0; f < anim.frameCount(); ++f) {
      const auto world = anim.frame(f);
      const double moved = (world[t].inverse().apply(world[c].translation) - atRest).norm();
      farthest = std::max(farthest, moved);
      ASSERT_LT(moved, 1e-6) << carried << " on " << trunk << ", frame " << f;
    }
  }
  std::printf("thighs and shoulders on the hips and chest: %.2g m from where they rest at most\n", farthest);
}

// The CMU originals (Acclaim ASF/AMC, a soccer kick) drive the MakeHuman body through the
// shipped 'acclaim' map: every bone is paired, and each limb on the avatar points where the
// motion's does on every frame (a wrong pairing, such as left for right or thigh for shin,
// puts them tens of degrees apart in a kick).
TEST(Retarget, AcclaimKickOnMakeHumanFollowsTheMotionsLimbs) {
  const scene::Avatar& avatar = makeHuman();
  const Clip clip = loadClip(std::string(DRAPE_DATA_DIR) + "/mocap/cmu_11_01.amc");
  const JointMap map = chooseJointMap(shippedMaps(), clip.skeleton, avatar);
  EXPECT_EQ(map.name, "acclaim");
  for (const SkeletonJoint& j : clip.skeleton.joints) {
    const std::string* paired = map.avatarJointFor(j.name);
    ASSERT_NE(paired, nullptr) << j.name;
    EXPECT_GE(avatar.findJoint(*paired), 0) << j.name;
  }
  const AvatarAnimation anim = AvatarAnimation::build(avatar, clip, map);
  ASSERT_EQ(anim.frameCount(), clip.frameCount());
  const std::vector<std::pair<std::string, std::string>> limbs = {
      {"lfemur", "ltibia"},   {"ltibia", "lfoot"},   {"rfemur", "rtibia"},   {"rtibia", "rfoot"},
      {"lhumerus", "lradius"}, {"lradius", "lwrist"}, {"rhumerus", "rradius"}, {"rradius", "rwrist"}};
  const double angle = largestLimbAngle_deg(avatar, clip, map, anim, limbs);
  std::printf("cmu_11_01.amc: largest limb angle between motion and avatar %.2f degrees\n", angle);
  EXPECT_LT(angle, 5.0);
  // The check is sharp: the same motion with the legs' maps swapped left for right fails it.
  JointMap swapped = map;
  for (JointMapEntry& e : swapped.entries) {
    if (e.motionJoint == "lfemur" || e.motionJoint == "ltibia" || e.motionJoint == "lfoot") e.motionJoint[0] = 'r';
    else if (e.motionJoint == "rfemur" || e.motionJoint == "rtibia" || e.motionJoint == "rfoot") e.motionJoint[0] = 'l';
  }
  EXPECT_GT(largestLimbAngle_deg(avatar, clip, map, AvatarAnimation::build(avatar, clip, swapped), limbs), 20.0);
}

// MakeHuman's default rig (twist bones: two per thigh, shin, upper arm and forearm) and its
// game-engine rig (a Root on the floor above the pelvis) take every shipped naming style
// through a style's map composed with the rig's. Each limb points where the motion's does:
// a chain of twist bones turns as one bone, measured from its head (measured from the
// twist bone, the default rig's limbs stood up to 23 degrees off). On the game-engine rig
// the pelvis follows the motion's root and the Root stays on the floor below it.
TEST(Retarget, MakeHumanRigsWithTwistBonesOrAFloorRootFollowTheMotionsLimbs) {
  const std::vector<std::pair<std::string, std::string>> rigs = {{"makehuman_rig_default.mhskel", "makehuman_default"},
                                                                 {"makehuman_rig_game_engine.mhskel", "makehuman_game_engine"}};
  const std::vector<std::tuple<std::string, std::string, std::vector<std::pair<std::string, std::string>>>> motions = {
      {"cmu_12_03_walk.bvh", "motionbuilder",
       {{"LeftUpLeg", "LeftLeg"}, {"LeftLeg", "LeftFoot"}, {"RightArm", "RightForeArm"}, {"RightForeArm", "RightHand"}}},
      {"cmu_02_02_walk_dazstyle.bvh", "daz",
       {{"lThigh", "lShin"}, {"lShin", "lFoot"}, {"rShldr", "rForeArm"}, {"rForeArm", "rHand"}}},
      {"cmu_11_01.amc", "acclaim", {{"lfemur", "ltibia"}, {"ltibia", "lfoot"}, {"rhumerus", "rradius"}, {"rradius", "rwrist"}}}};
  for (const auto& [rigFile, rigMap] : rigs) {
    scene::MakeHumanAvatarOptions options;
    options.directory = std::string(DRAPE_DATA_DIR) + "/avatars";
    options.skeletonFile = rigFile;
    const scene::Avatar avatar = scene::buildMakeHumanAvatar(options);
    for (const auto& [file, style, limbs] : motions) {
      const Clip clip = loadClip(std::string(DRAPE_DATA_DIR) + "/mocap/" + file);
      const JointMap map = chooseJointMap(shippedMaps(), clip.skeleton, avatar);
      EXPECT_EQ(map.name, style + " + " + rigMap) << file;
      const AvatarAnimation anim = AvatarAnimation::build(avatar, clip, map);
      const double angle = largestLimbAngle_deg(avatar, clip, map, anim, limbs);
      std::printf("%s on %s: largest limb angle %.2f degrees, root scale %.3f\n", file.c_str(), rigFile.c_str(), angle,
                  anim.rootScale());
      EXPECT_LT(angle, 5.0) << file << " on " << rigFile;
      EXPECT_GT(anim.rootScale(), 0.8);
      EXPECT_LT(anim.rootScale(), 1.2);
      const int root = avatar.findJoint("Root"), pelvis = avatar.findJoint("pelvis");
      if (root < 0) continue;
      const scene::Joint& r = avatar.joints[static_cast<std::size_t>(root)];
      const Vec3 offset = r.restCenter - avatar.joints[static_cast<std::size_t>(pelvis)].restCenter;
      for (std::size_t f = 0; f < anim.frameCount(); ++f) {
        const Vec3 at = anim.frame(f)[static_cast<std::size_t>(root)].translation;
        const Vec3 below = anim.frame(f)[static_cast<std::size_t>(pelvis)].translation + offset;
        EXPECT_NEAR(at.y(), r.restCenter.y() - anim.groundCorrection()[f], 1e-9) << file << " frame " << f;
        // Where it stands from the pelvis at rest, horizontally, whatever the pelvis does.
        EXPECT_NEAR(at.x(), below.x(), 1e-9) << file << " frame " << f;
        EXPECT_NEAR(at.z(), below.z(), 1e-9) << file << " frame " << f;
      }
    }
  }
}

// A humanoid of H-Anim 1.1's first level of articulation as the standard lays it out: its
// 18 Joints near the suggested centres (Annex A, rounded to millimetres), facing +Z with
// the arms down at the sides, a sacroiliac between the root and the hips and the shoulders
// on vt10. A CMU walk drives it through the shipped 'hanim' map reversed, found by itself:
// every Joint but the sacroiliac is paired (MakeHuman names no pelvis joint), and each limb
// points where the capture's does.
TEST(Retarget, AStandardHanimHumanoidFollowsTheCapturesLimbs) {
  const scene::Avatar loa1 = hanimLoa1();
  ASSERT_EQ(loa1.joints.size(), 18u);

  const Clip clip = loadClip(std::string(DRAPE_DATA_DIR) + "/mocap/cmu_12_03_walk.bvh");
  const JointMap map = chooseJointMap(shippedMaps(), clip.skeleton, loa1);
  EXPECT_EQ(map.name, "hanim (reversed)");
  EXPECT_EQ(matchedJointCount(map, clip.skeleton, loa1), 17u);
  const AvatarAnimation anim = AvatarAnimation::build(loa1, clip, map);
  const std::vector<std::pair<std::string, std::string>> limbs = {
      {"LeftUpLeg", "LeftLeg"}, {"LeftLeg", "LeftFoot"},       {"RightUpLeg", "RightLeg"},       {"RightLeg", "RightFoot"},
      {"LeftArm", "LeftForeArm"}, {"LeftForeArm", "LeftHand"}, {"RightArm", "RightForeArm"}, {"RightForeArm", "RightHand"},
      {"LowerBack", "Spine"}};
  // Measured through the pairs as H-Anim defines its Joints, written here apart from the
  // shipped map: a map that paired left with right, or thigh with shin, would put the limbs
  // tens of degrees from the capture's (below).
  JointMap anatomy;
  for (const auto& [motionJoint, hanimJoint] : std::vector<std::pair<std::string, std::string>>{
           {"LeftUpLeg", "l_hip"}, {"LeftLeg", "l_knee"}, {"LeftFoot", "l_ankle"}, {"RightUpLeg", "r_hip"},
           {"RightLeg", "r_knee"}, {"RightFoot", "r_ankle"}, {"LeftArm", "l_shoulder"}, {"LeftForeArm", "l_elbow"},
           {"LeftHand", "l_wrist"}, {"RightArm", "r_shoulder"}, {"RightForeArm", "r_elbow"}, {"RightHand", "r_wrist"},
           {"LowerBack", "vl5"}, {"Spine", "vt10"}})
    anatomy.entries.push_back({motionJoint, hanimJoint, {}, {}});
  const double angle = largestLimbAngle_deg(loa1, clip, anatomy, anim, limbs);
  std::printf("cmu_12_03_walk.bvh on an H-Anim LOA1 humanoid: largest limb angle %.2f degrees, root scale %.3f\n", angle,
              anim.rootScale());
  EXPECT_LT(angle, 5.0);
  EXPECT_GT(anim.rootScale(), 0.8);
  EXPECT_LT(anim.rootScale(), 1.2);
  JointMap swapped = map;
  for (JointMapEntry& e : swapped.entries)
    if (e.avatarJoint.size() > 2 && e.avatarJoint[1] == '_' && (e.avatarJoint[0] == 'l' || e.avatarJoint[0] == 'r'))
      e.avatarJoint[0] = e.avatarJoint[0] == 'l' ? 'r' : 'l';
  EXPECT_GT(largestLimbAngle_deg(loa1, clip, anatomy, AvatarAnimation::build(loa1, clip, swapped), limbs), 20.0);
}

// A map that leaves the avatar's root undriven is refused with how much it pairs and the
// way out, not left to move a body that stands still.
TEST(Retarget, AMapThatMissesTheRootSaysHowMuchItPairs) {
  const Clip clip = loadClip(std::string(DRAPE_DATA_DIR) + "/mocap/cmu_11_01.amc");
  try {
    (void)AvatarAnimation::build(makeHuman(), clip, JointMap::identity(clip.skeleton));
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("drives the avatar's root joint 'Hips' (joint map 'same names' pairs 0 of "
                                         "the motion's 31 joints with the avatar's); give a joint map naming the "
                                         "motion's joints (--joint-map FILE"),
              std::string::npos)
        << e.what();
  }
}

TEST(Retarget, LoadAnimationWithTheShippedMaps) {
  MotionOptions options;
  options.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  ClipLoadReport report;
  JointMap map;
  const AvatarAnimation anim =
      loadAnimation(makeHuman(), std::string(DRAPE_DATA_DIR) + "/mocap/cmu_02_02_walk_dazstyle.bvh", options, &report, &map);
  EXPECT_EQ(map.name, "daz");
  EXPECT_EQ(report.units.name, "cm");
  EXPECT_DOUBLE_EQ(anim.rate(), 30.0);
  EXPECT_EQ(anim.jointCount(), makeHuman().joints.size());
}

TEST(Retarget, UnknownJointInAUserMapIsAnErrorWithItsLine) {
  MotionOptions options;
  options.jointMapPath = std::string(DRAPE_TEST_DATA_DIR) + "/bad/motion/map_unknown_joint.json";
  try {
    (void)loadAnimation(makeHuman(), std::string(DRAPE_DATA_DIR) + "/mocap/cmu_walk_delfem2.bvh", options);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), options.jointMapPath + ":5:5: unknown motion joint 'LeftKnee' (not in the motion's skeleton)");
    EXPECT_EQ(e.code(), ExitCode::BadInput);
  }
}

// The MakeHuman body turned about the vertical at rest (a VRM 0.x character faces -Z, and
// CesiumMan +X, where glTF characters and CMU captures face +Z) walks exactly as the body
// facing +Z does: the retargeting turns it to face as the capture does first. Without that
// turn its spine's correction, which the shoulders' two directions and the neck's cancel
// to one vertical direction, left the shoulders facing backwards: 18 cm from where the
// capture puts them in the half-turned body.
class RetargetFacing : public ::testing::TestWithParam<int> {};

/// The MakeHuman body at rest turned about the vertical through the origin.
scene::Avatar turnedBody(const Quat& turn) {
  scene::Avatar turned = makeHuman();
  for (scene::Joint& j : turned.joints) j.restCenter = turn * j.restCenter;
  for (scene::Segment& s : turned.segments)
    for (Vec3& p : s.mesh.positions) p = turn * p;
  return turned;
}

/// The CMU walk on `avatar` through the map chosen for the MakeHuman body.
AvatarAnimation walkOn(const scene::Avatar& avatar) {
  const Clip clip = loadClip(std::string(DRAPE_DATA_DIR) + "/mocap/cmu_12_03_walk.bvh");
  return AvatarAnimation::build(avatar, clip, chooseJointMap(shippedMaps(), clip.skeleton, makeHuman()));
}

TEST_P(RetargetFacing, ATurnedBodyWalksAsTheBodyFacingTheCapturesWay) {
  const double degrees = GetParam();
  const Quat turn(Eigen::AngleAxisd(degrees * std::numbers::pi / 180.0, Vec3::UnitY()));
  const scene::Avatar turned = turnedBody(turn);
  const AvatarAnimation facing = walkOn(makeHuman());
  const AvatarAnimation other = walkOn(turned);
  ASSERT_EQ(other.frameCount(), facing.frameCount());
  // The root keeps its own place on the floor: the turned body's rest root stands elsewhere.
  Vec3 shift = turned.joints[0].restCenter - makeHuman().joints[0].restCenter;
  shift.y() = 0.0;
  double position = 0.0, angle = 0.0;
  for (std::size_t f = 0; f < facing.frameCount(); ++f)
    for (std::size_t j = 0; j < facing.jointCount(); ++j) {
      position = std::max(position, (other.frame(f)[j].translation - shift - facing.frame(f)[j].translation).norm());
      // Its joints' frames are the facing body's, turned back from its own rest.
      angle = std::max(angle, other.frame(f)[j].rotation.angularDistance(facing.frame(f)[j].rotation * turn.conjugate()));
    }
  EXPECT_LT(position, 1e-9) << "m";
  EXPECT_LT(angle, 1e-9) << "rad";
}

INSTANTIATE_TEST_SUITE_P(QuarterTurns, RetargetFacing, ::testing::Values(90, 180, 270),
                         [](const ::testing::TestParamInfo<int>& p) { return std::to_string(p.param) + "Degrees"; });

// A rest pose a little turned (a scan standing askew) is pose, not a facing convention: the
// body is not turned, and its joints keep the corrections of their own bones.
TEST(Retarget, ABodyALittleTurnedIsNotTurnedAround) {
  const Quat turn(Eigen::AngleAxisd(20.0 * std::numbers::pi / 180.0, Vec3::UnitY()));
  const AvatarAnimation straight = walkOn(makeHuman());
  const AvatarAnimation a = walkOn(turnedBody(turn));
  // The root follows the capture's own turn, whatever the body's rest facing.
  for (std::size_t f = 0; f < a.frameCount(); ++f)
    EXPECT_LT(a.frame(f)[0].rotation.angularDistance(straight.frame(f)[0].rotation), 1e-12) << f;
}

}  // namespace
}  // namespace drape::motion
