// A humanoid found by its skeleton's shape (scene::findHumanoid): on four real rigs, whose
// joints' names say what each is (and the shipped joint maps pair them), the shape alone
// must find the same bones; turned to face any way and moved, the same again; laid along
// any axis, stood up again by scene::findUpright (two real robots stand along +z); and what
// is not a humanoid is refused with a reason.

#include <gtest/gtest.h>

#include <random>

#include "drape/core/error.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/scene/humanoid.hpp"

namespace drape::scene {
namespace {

const std::string kHumanoidAvatars = std::string(DRAPE_DATA_DIR) + "/avatars/";

/// What a rig's names say each bone is: joint names per chain, left side then right.
struct Expected {
  std::string pelvis;
  std::vector<std::string> spine, neck;
  std::array<std::vector<std::vector<std::string>>, 2> legs;  ///< base, upper, lower, end, tip
  std::array<std::vector<std::vector<std::string>>, 2> arms;  ///< base, upper, lower, end
};

std::vector<std::string> namesOf(const Avatar& avatar, const JointChain& chain) {
  std::vector<std::string> names;
  for (int j : chain) names.push_back(avatar.joints[static_cast<std::size_t>(j)].name);
  return names;
}

void expectHumanoid(const Avatar& avatar, const Humanoid& h, const Expected& e) {
  EXPECT_EQ(avatar.joints[static_cast<std::size_t>(h.pelvis)].name, e.pelvis);
  EXPECT_EQ(namesOf(avatar, h.spine), e.spine);
  EXPECT_EQ(namesOf(avatar, h.neck), e.neck);
  for (std::size_t s = 0; s < 2; ++s) {
    const HumanoidLimb& leg = h.legs[s];
    const std::vector<JointChain> legChains{leg.base, leg.upper, leg.lower, leg.end, leg.tip};
    for (std::size_t b = 0; b < e.legs[s].size(); ++b)
      EXPECT_EQ(namesOf(avatar, legChains[b]), e.legs[s][b]) << (s == 0 ? "left" : "right") << " leg, bone " << b;
    const HumanoidLimb& arm = h.arms[s];
    const std::vector<JointChain> armChains{arm.base, arm.upper, arm.lower, arm.end, arm.tip};
    for (std::size_t b = 0; b < e.arms[s].size(); ++b)
      EXPECT_EQ(namesOf(avatar, armChains[b]), e.arms[s][b]) << (s == 0 ? "left" : "right") << " arm, bone " << b;
    EXPECT_TRUE(arm.tip.empty());
  }
}

/// A joint turned by `turn` and moved by `move`, with the tip of its segment.
void moveJoint(JointAt& j, const Quat& turn, const Vec3& move = Vec3::Zero()) {
  j.rest = turn * j.rest + move;
  if (j.tip) j.tip = turn * *j.tip + move;
}

Humanoid humanoidOf(const Avatar& avatar) {
  std::string why;
  const std::optional<Humanoid> h = findHumanoid(jointsAt(avatar), &why);
  if (!h) ADD_FAILURE() << avatar.source << ": " << why;
  return h.value_or(Humanoid{});
}

Expected cmuRig() {
  return {"Hips",
          {"LowerBack", "Spine", "Spine1"},
          {"Neck", "Neck1", "Head"},
          {{{{"LHipJoint"}, {"LeftUpLeg"}, {"LeftLeg"}, {"LeftFoot"}, {"LeftToeBase"}},
            {{"RHipJoint"}, {"RightUpLeg"}, {"RightLeg"}, {"RightFoot"}, {"RightToeBase"}}}},
          {{{{"LeftShoulder"}, {"LeftArm"}, {"LeftForeArm"}, {"LeftHand"}},
            {{"RightShoulder"}, {"RightArm"}, {"RightForeArm"}, {"RightHand"}}}}};
}

TEST(Humanoid, TheMakeHumanCmuRigsBonesAreWhereItsNamesSay) {
  const Avatar avatar = loadAvatarFile(kHumanoidAvatars + "makehuman_rig_cmu_mb.mhskel");
  const Humanoid h = humanoidOf(avatar);
  expectHumanoid(avatar, h, cmuRig());
  EXPECT_TRUE(h.abovePelvis.empty());
  EXPECT_GT(h.forward.z(), 0.99);  // the body faces +z
}

/// The MakeHuman body with a marker joint 0.2 m above its head, as Mixamo's rigs and many
/// exporters end a chain (HeadTop_End): no segment moves with it.
Avatar withTopOfHeadMarker(Avatar avatar) {
  const int head = avatar.findJoint("Head");
  Joint marker = avatar.joints[static_cast<std::size_t>(head)];
  marker.name = "HeadTop_End";
  marker.parent = head;
  marker.restCenter += Vec3(0.0, 0.2, 0.0);
  avatar.joints.push_back(marker);
  return avatar;
}

TEST(Humanoid, AMarkerAtTheTopOfTheHeadIsNoHead) {
  // The way up the neck ends at the marker, but the head is the joint it hangs from: the one
  // the head's segment moves with.
  const Avatar marked = withTopOfHeadMarker(loadAvatarFile(kHumanoidAvatars + "makehuman_rig_cmu_mb.mhskel"));
  Humanoid h = humanoidOf(marked);
  expectHumanoid(marked, h, cmuRig());
  EXPECT_EQ(marked.joints[static_cast<std::size_t>(h.head())].name, "Head");
  // A joint at the top that carries a segment is a bone of its own: the head's last.
  Avatar carrying = marked;
  Segment top = carrying.segments.front();
  top.name = "HeadTop";
  top.joint = carrying.findJoint("HeadTop_End");
  carrying.segments.push_back(top);
  h = humanoidOf(carrying);
  EXPECT_EQ(namesOf(carrying, h.neck), (std::vector<std::string>{"Neck", "Neck1", "Head", "HeadTop_End"}));
  // A skeleton alone (no segments) does not say which joints carry the body: every one does.
  Avatar bare = marked;
  bare.segments.clear();
  h = humanoidOf(bare);
  EXPECT_EQ(namesOf(bare, h.neck), (std::vector<std::string>{"Neck", "Neck1", "Head", "HeadTop_End"}));
}

TEST(Humanoid, TheDefaultRigsTwistBonesGoWithTheirBonesAsItsShippedMapChainsThem) {
  // share/drape/jointmaps/makehuman_default.json chains upperleg01.L and upperleg02.L into
  // one thigh, clavicle.L and shoulder01.L into one shoulder, and so on: the shape finds the
  // same chains (its spine and neck it keeps whole, where the map pairs them with CMU's).
  const Avatar avatar = loadAvatarFile(kHumanoidAvatars + "makehuman_rig_default.mhskel");
  const Humanoid h = humanoidOf(avatar);
  Expected e{"root",
             {"spine05", "spine04", "spine03", "spine02", "spine01"},
             {"neck01", "neck02", "neck03", "head"},
             {},
             {}};
  for (const char* side : {"L", "R"}) {
    const std::size_t s = side[0] == 'L' ? 0 : 1;
    const auto n = [&](const char* bone) { return std::string(bone) + "." + side; };
    e.legs[s] = {{n("pelvis")}, {n("upperleg01"), n("upperleg02")}, {n("lowerleg01"), n("lowerleg02")}, {n("foot")}};
    e.arms[s] = {{n("clavicle"), n("shoulder01")},
                 {n("upperarm01"), n("upperarm02")},
                 {n("lowerarm01"), n("lowerarm02")},
                 {n("wrist")}};
  }
  expectHumanoid(avatar, h, e);
  for (const HumanoidLimb& leg : h.legs) {
    ASSERT_EQ(leg.tip.size(), 1u);
    EXPECT_EQ(avatar.joints[static_cast<std::size_t>(leg.tip[0])].name.substr(0, 3), "toe");
  }
}

TEST(Humanoid, TheGameEngineRigsFloorRootIsAboveThePelvis) {
  const Avatar avatar = loadAvatarFile(kHumanoidAvatars + "makehuman_rig_game_engine.mhskel");
  const Humanoid h = humanoidOf(avatar);
  Expected e{"pelvis", {"spine_01", "spine_02", "spine_03"}, {"neck_01", "head"}, {}, {}};
  for (const char* side : {"l", "r"}) {
    const std::size_t s = side[0] == 'l' ? 0 : 1;
    const auto n = [&](const char* bone) { return std::string(bone) + "_" + side; };
    e.legs[s] = {{}, {n("thigh")}, {n("calf")}, {n("foot")}, {n("ball")}};
    e.arms[s] = {{n("clavicle")}, {n("upperarm")}, {n("lowerarm")}, {n("hand")}};
  }
  expectHumanoid(avatar, h, e);
  EXPECT_EQ(namesOf(avatar, h.abovePelvis), std::vector<std::string>{"Root"});
}

TEST(Humanoid, CesiumMansNumberedJointsFacingX) {
  // joint0 .. joint18: nothing in the names. He faces +x (his toes say so), so his left is -z.
  const Avatar avatar = loadAvatarFile(kHumanoidAvatars + "CesiumMan.glb");
  const Humanoid h = humanoidOf(avatar);
  expectHumanoid(avatar, h,
                 {"joint0",
                  {"joint1", "joint2"},
                  {"joint3", "joint4"},
                  {{{{}, {"joint11"}, {"joint13"}, {"joint15"}, {"joint17"}},
                    {{}, {"joint12"}, {"joint14"}, {"joint16"}, {"joint18"}}}},
                  {{{{}, {"joint5"}, {"joint7"}, {"joint9"}}, {{}, {"joint6"}, {"joint8"}, {"joint10"}}}}});
  EXPECT_GT(h.forward.x(), 0.95);
  EXPECT_LT(avatar.joints[static_cast<std::size_t>(h.legs[0].upper[0])].restCenter.z(), 0.0);
}

TEST(Humanoid, TurnedAndMovedItIsTheSameHumanoid) {
  // Every rig turned about the vertical by random angles and moved: the same joints in
  // every bone, and forward turned with the body.
  std::mt19937 rng(20261205);
  std::uniform_real_distribution<double> angle(-3.14159, 3.14159), shift(-5.0, 5.0);
  for (const char* file : {"makehuman_rig_cmu_mb.mhskel", "makehuman_rig_default.mhskel",
                           "makehuman_rig_game_engine.mhskel", "CesiumMan.glb"}) {
    const Avatar avatar = loadAvatarFile(kHumanoidAvatars + file);
    const std::vector<JointAt> joints = jointsAt(avatar);
    const std::optional<Humanoid> upright = findHumanoid(joints);
    ASSERT_TRUE(upright.has_value()) << file;
    for (int trial = 0; trial < 12; ++trial) {
      const Quat turn(Eigen::AngleAxisd(angle(rng), Vec3::UnitY()));
      const Vec3 move(shift(rng), shift(rng), shift(rng));
      std::vector<JointAt> turned = joints;
      for (JointAt& j : turned) moveJoint(j, turn, move);
      const std::optional<Humanoid> h = findHumanoid(turned);
      ASSERT_TRUE(h.has_value()) << file << ", trial " << trial;
      EXPECT_EQ(h->pelvis, upright->pelvis) << file;
      EXPECT_EQ(h->spine, upright->spine) << file;
      EXPECT_EQ(h->neck, upright->neck) << file;
      for (std::size_t s = 0; s < 2; ++s) {
        for (const auto& [a, b] : {std::pair{&h->legs[s], &upright->legs[s]}, std::pair{&h->arms[s], &upright->arms[s]}}) {
          EXPECT_EQ(a->base, b->base) << file << ", side " << s;
          EXPECT_EQ(a->upper, b->upper) << file << ", side " << s;
          EXPECT_EQ(a->lower, b->lower) << file << ", side " << s;
          EXPECT_EQ(a->end, b->end) << file << ", side " << s;
          EXPECT_EQ(a->tip, b->tip) << file << ", side " << s;
        }
      }
      EXPECT_LT((h->forward - turn * upright->forward).norm(), 1e-9) << file;
    }
  }
}

TEST(Humanoid, WhatIsNotAHumanoidIsRefusedWithAReason) {
  std::string why;
  EXPECT_FALSE(findHumanoid(jointsAt(loadAvatarFile(kHumanoidAvatars + "RiggedSimple.glb")), &why));
  EXPECT_EQ(why, "2 joints are too few for legs, a spine and arms");

  // A CMU body without its arms: legs and a spine, no arms.
  const Avatar cmu = loadAvatarFile(kHumanoidAvatars + "makehuman_rig_cmu_mb.mhskel");
  std::vector<JointAt> noArms;
  std::vector<int> index(cmu.joints.size(), -1);
  for (std::size_t i = 0; i < cmu.joints.size(); ++i) {
    const Joint& j = cmu.joints[i];
    const bool arm = j.name.find("Shoulder") != std::string::npos ||
                     (j.parent >= 0 && index[static_cast<std::size_t>(j.parent)] < 0 && i > 0);
    if (arm) continue;
    index[i] = static_cast<int>(noArms.size());
    noArms.push_back({j.parent < 0 ? -1 : index[static_cast<std::size_t>(j.parent)], j.restCenter});
  }
  EXPECT_FALSE(findHumanoid(noArms, &why));
  EXPECT_EQ(why, "the spine has no two branches reaching out to the sides (the arms)");

  // A chain of 200,000 joints (a glTF skeleton may nest without limit): refused, without
  // recursing down it.
  std::vector<JointAt> chain;
  for (int i = 0; i < 200000; ++i) chain.push_back({i - 1, Vec3(0.001 * (i % 7), -1e-5 * i, 0.0)});
  EXPECT_FALSE(findHumanoid(chain, &why));
  EXPECT_EQ(why, "no joint has two children reaching the floor (the legs)");
  // The CMU body with such a chain hanging from each hand to the floor: still the humanoid,
  // its arms ending at the wrists' chains.
  std::vector<JointAt> braided = jointsAt(cmu);
  for (const char* hand : {"LeftHand", "RightHand"}) {
    int parent = cmu.findJoint(hand);
    const Vec3 from = cmu.joints[static_cast<std::size_t>(parent)].restCenter;
    for (int i = 0; i < 50000; ++i) {
      braided.push_back({parent, from - Vec3(0.0, 1e-5 * (i + 1), 0.0)});
      parent = static_cast<int>(braided.size()) - 1;
    }
  }
  const std::optional<Humanoid> withBraids = findHumanoid(braided, &why);
  ASSERT_TRUE(withBraids.has_value()) << why;
  EXPECT_EQ(cmu.joints[static_cast<std::size_t>(withBraids->pelvis)].name, "Hips");
  EXPECT_EQ(cmu.joints[static_cast<std::size_t>(withBraids->legs[0].upper[0])].name, "LeftUpLeg");

  // Joints not listed parents first (the avatars' and motions' loaders list them so): refused.
  std::vector<JointAt> disordered = jointsAt(cmu);
  disordered[3].parent = 7;
  EXPECT_FALSE(findHumanoid(disordered, &why));
  EXPECT_EQ(why, "joint 3 comes before its parent 7");

  // Lying down: the legs reach the floor (the back lies on it), but nothing rises.
  std::vector<JointAt> lying = jointsAt(cmu);
  const Quat down(Eigen::AngleAxisd(1.5707963, Vec3::UnitX()));
  for (JointAt& j : lying) j.rest = down * j.rest;
  EXPECT_FALSE(findHumanoid(lying, &why));
  EXPECT_EQ(why, "no joint above the legs' parting reaches up (the spine)");
}

TEST(Humanoid, RobotsStandingAlongZAreFoundStoodUp) {
  // Choreonoid's robots stand along +z, as robotics tools stand everything, and face +x;
  // SR1 has no head (its chest carries the arms and nothing above them), and each of its
  // joints is one axis of a shoulder, hip or wrist, so several share a place.
  const Avatar sr1 = loadAvatarFile(std::string(DRAPE_DATA_DIR) + "/vrml/choreonoid_SR1.wrl");
  std::string why;
  EXPECT_FALSE(findHumanoid(jointsAt(sr1), &why));
  EXPECT_EQ(why, "no joint has two children reaching the floor (the legs)");
  std::optional<Upright> u = findUpright(jointsAt(sr1), &why);
  ASSERT_TRUE(u.has_value()) << why;
  EXPECT_EQ(u->axis, "+z");
  EXPECT_EQ(u->rotationText(), "1 0 0 -1.5708");
  EXPECT_LT((u->turn * Vec3::UnitZ() - Vec3::UnitY()).norm(), 1e-12);
  expectHumanoid(sr1, u->humanoid,
                 {"WAIST",
                  {"WAIST_P", "WAIST_R", "CHEST"},
                  {},
                  {{{{}, {"LLEG_HIP_R", "LLEG_HIP_P"}, {"LLEG_HIP_Y", "LLEG_KNEE"}, {"LLEG_ANKLE_P"}, {"LLEG_ANKLE_R"}},
                    {{}, {"RLEG_HIP_R", "RLEG_HIP_P"}, {"RLEG_HIP_Y", "RLEG_KNEE"}, {"RLEG_ANKLE_P"}, {"RLEG_ANKLE_R"}}}},
                  {{{{}, {"LARM_SHOULDER_P", "LARM_SHOULDER_R"}, {"LARM_SHOULDER_Y", "LARM_ELBOW"}, {"LARM_WRIST_Y"}},
                    {{}, {"RARM_SHOULDER_P", "RARM_SHOULDER_R"}, {"RARM_SHOULDER_Y", "RARM_ELBOW"}, {"RARM_WRIST_Y"}}}}});
  EXPECT_EQ(u->humanoid.head(), -1);
  EXPECT_GT(u->humanoid.forward.x(), 0.99);
  // Stood up by the turn, it is the same humanoid along +y.
  Avatar stood = sr1;
  placeAvatar(stood, RigidTransform{u->turn, Vec3::Zero()});
  const std::optional<Humanoid> along = findHumanoid(jointsAt(stood), &why);
  ASSERT_TRUE(along.has_value()) << why;
  EXPECT_EQ(along->spine, u->humanoid.spine);
  EXPECT_EQ(along->legs[0].upper, u->humanoid.legs[0].upper);

  const Avatar gr001 = loadAvatarFile(std::string(DRAPE_DATA_DIR) + "/vrml/choreonoid_GR001/GR001.wrl");
  u = findUpright(jointsAt(gr001), &why);
  ASSERT_TRUE(u.has_value()) << why;
  EXPECT_EQ(u->axis, "+z");
  EXPECT_EQ(namesOf(gr001, u->humanoid.spine), std::vector<std::string>{"CHEST_P"});
  EXPECT_EQ(namesOf(gr001, u->humanoid.neck), std::vector<std::string>{"NECK_Y"});
  EXPECT_EQ(namesOf(gr001, u->humanoid.legs[0].upper), (std::vector<std::string>{"L_HIP_Y", "L_HIP_R", "L_HIP_P"}));
  EXPECT_EQ(namesOf(gr001, u->humanoid.legs[1].lower), std::vector<std::string>{"R_KNEE_P"});
  // GR001's arms end at the elbow, whose segment is the forearm and the gripper: no joint is
  // the wrist, and the shoulder's two joints stand 2.6 cm apart, the first out to the side
  // of the chest as a clavicle is.
  for (std::size_t s = 0; s < 2; ++s) {
    const std::string side = s == 0 ? "L_" : "R_";
    const HumanoidLimb& arm = u->humanoid.arms[s];
    EXPECT_EQ(namesOf(gr001, arm.base), std::vector<std::string>{side + "SHOULDER_P"});
    EXPECT_EQ(namesOf(gr001, arm.upper), std::vector<std::string>{side + "SHOULDER_R"});
    EXPECT_EQ(namesOf(gr001, arm.lower), std::vector<std::string>{side + "ELBOW_P"});
    EXPECT_TRUE(arm.end.empty()) << side;
  }
  Avatar gr001Standing = gr001;
  placeAvatar(gr001Standing, RigidTransform{u->turn, Vec3::Zero()});
  EXPECT_EQ(findForearmsAndHands(gr001Standing), (std::vector<std::string>{"L_ELBOW_P_LINK", "R_ELBOW_P_LINK"}));
}

TEST(Humanoid, AnArmEndingAtItsElbowHasNoHand) {
  // CMU's rig with its arms cut at the elbows, each elbow's segment reaching to where the
  // fingertips were: the forearm is the elbow, the hand no joint. The whole rig with its
  // hands' segments as long as hands: its own arms.
  const Avatar avatar = loadAvatarFile(kHumanoidAvatars + "makehuman_rig_cmu_mb.mhskel");
  const std::vector<JointAt> whole = jointsAt(avatar);
  const std::optional<Humanoid> h = findHumanoid(whole);
  ASSERT_TRUE(h.has_value());
  std::vector<JointAt> cut;
  std::vector<int> index(whole.size(), -1);
  std::vector<bool> dropped(whole.size(), false);
  for (std::size_t s = 0; s < 2; ++s) dropped[static_cast<std::size_t>(h->arms[s].end.front())] = true;
  for (std::size_t j = 0; j < whole.size(); ++j) {
    const int p = whole[j].parent;
    if (dropped[j] || (p >= 0 && dropped[static_cast<std::size_t>(p)])) {
      dropped[j] = true;
      continue;
    }
    index[j] = static_cast<int>(cut.size());
    cut.push_back({p < 0 ? -1 : index[static_cast<std::size_t>(p)], whole[j].rest});
  }
  std::array<Vec3, 2> fingertips{};
  for (std::size_t s = 0; s < 2; ++s) {
    const int wrist = h->arms[s].end.front();
    const Vec3 along = whole[static_cast<std::size_t>(wrist)].rest - whole[static_cast<std::size_t>(h->arms[s].lower.front())].rest;
    fingertips[s] = whole[static_cast<std::size_t>(wrist)].rest + 0.75 * along;  // a hand three quarters of a forearm
  }
  for (std::size_t s = 0; s < 2; ++s)
    cut[static_cast<std::size_t>(index[static_cast<std::size_t>(h->arms[s].lower.front())])].tip = fingertips[s];
  const std::optional<Humanoid> elbowed = findHumanoid(cut);
  ASSERT_TRUE(elbowed.has_value());
  for (std::size_t s = 0; s < 2; ++s) {
    const HumanoidLimb& arm = elbowed->arms[s];
    EXPECT_EQ(arm.lower, JointChain{index[static_cast<std::size_t>(h->arms[s].lower.front())]});
    EXPECT_TRUE(arm.end.empty());
    ASSERT_EQ(arm.upper.size(), 1U);
    EXPECT_EQ(arm.upper.front(), index[static_cast<std::size_t>(h->arms[s].upper.front())]);
    EXPECT_EQ(arm.base, JointChain{index[static_cast<std::size_t>(h->arms[s].base.front())]});
  }
  // The whole rig with a tip on each hand, a hand long: its own arms.
  std::vector<JointAt> tipped = whole;
  for (std::size_t s = 0; s < 2; ++s) tipped[static_cast<std::size_t>(h->arms[s].end.front())].tip = fingertips[s];
  const std::optional<Humanoid> same = findHumanoid(tipped);
  ASSERT_TRUE(same.has_value());
  for (std::size_t s = 0; s < 2; ++s) {
    EXPECT_EQ(same->arms[s].upper, h->arms[s].upper);
    EXPECT_EQ(same->arms[s].lower, h->arms[s].lower);
    EXPECT_EQ(same->arms[s].end, h->arms[s].end);
  }
}

TEST(Humanoid, ABodyStandingAlongAnyAxisIsStoodUpWithTheSameBones) {
  // Each rig laid along each axis, and turned about it at random: findUpright names the
  // axis, its turn takes the axis onto +y, and the bones are those of the rig standing.
  std::mt19937 rng(20261206);
  std::uniform_real_distribution<double> angle(-3.14159, 3.14159);
  const std::array<std::pair<const char*, Vec3>, 6> axes{{{"+y", Vec3::UnitY()},
                                                          {"+z", Vec3::UnitZ()},
                                                          {"-z", -Vec3::UnitZ()},
                                                          {"+x", Vec3::UnitX()},
                                                          {"-x", -Vec3::UnitX()},
                                                          {"-y", -Vec3::UnitY()}}};
  for (const char* file : {"makehuman_rig_cmu_mb.mhskel", "makehuman_rig_default.mhskel", "CesiumMan.glb"}) {
    const Avatar avatar = loadAvatarFile(kHumanoidAvatars + file);
    const std::vector<JointAt> joints = jointsAt(avatar);
    const std::optional<Humanoid> standing = findHumanoid(joints);
    ASSERT_TRUE(standing.has_value()) << file;
    for (const auto& [name, axis] : axes) {
      // A quarter or half turn about a horizontal axis that takes +y onto `axis`.
      const Quat lay = axis.y() < -0.5 ? Quat(Eigen::AngleAxisd(3.14159265358979, Vec3::UnitZ()))
                                       : Quat::FromTwoVectors(Vec3::UnitY(), axis);
      const Quat about(Eigen::AngleAxisd(angle(rng), axis));
      std::vector<JointAt> laid = joints;
      for (JointAt& j : laid) moveJoint(j, about * lay);
      std::string why;
      const std::optional<Upright> u = findUpright(laid, &why);
      ASSERT_TRUE(u.has_value()) << file << " along " << name << ": " << why;
      EXPECT_EQ(u->axis, name) << file;
      EXPECT_LT((u->turn * axis - Vec3::UnitY()).norm(), 1e-12) << file << " along " << name;
      EXPECT_EQ(u->humanoid.pelvis, standing->pelvis) << file << " along " << name;
      EXPECT_EQ(u->humanoid.spine, standing->spine) << file << " along " << name;
      EXPECT_EQ(u->humanoid.neck, standing->neck) << file << " along " << name;
      for (std::size_t s = 0; s < 2; ++s) {
        EXPECT_EQ(u->humanoid.legs[s].upper, standing->legs[s].upper) << file << " along " << name;
        EXPECT_EQ(u->humanoid.arms[s].lower, standing->arms[s].lower) << file << " along " << name;
      }
    }
  }
  // What stands along no axis is refused with the reason along +y, and that the other axes
  // were tried where the reason depends on the axis.
  std::string why;
  EXPECT_FALSE(findUpright(jointsAt(loadAvatarFile(kHumanoidAvatars + "RiggedSimple.glb")), &why));
  EXPECT_EQ(why, "2 joints are too few for legs, a spine and arms");
  // Legs and a spine without arms: along +y the arms are missing, along the others the legs.
  const std::vector<JointAt> armless{{-1, {0.0, 1.0, 0.0}},   {0, {0.1, 0.95, 0.0}},  {1, {0.1, 0.5, 0.0}},
                                     {2, {0.1, 0.05, 0.0}},   {0, {-0.1, 0.95, 0.0}}, {4, {-0.1, 0.5, 0.0}},
                                     {5, {-0.1, 0.05, 0.0}},  {0, {0.0, 1.4, 0.0}},   {7, {0.0, 1.8, 0.0}}};
  EXPECT_FALSE(findUpright(armless, &why));
  EXPECT_EQ(why, "the spine has no two branches reaching out to the sides (the arms) (and turned to stand along x or z, "
                 "it is no humanoid either)");
}

TEST(Humanoid, TheLowerBodyASkirtIsFittedToOnEachRig) {
  const LowerBody cmu = findLowerBody(loadAvatarFile(kHumanoidAvatars + "makehuman_rig_cmu_mb.mhskel"));
  EXPECT_EQ(cmu.waist, "LowerBack");
  EXPECT_EQ(cmu.hips, (std::vector<std::string>{"Hips", "LHipJoint", "RHipJoint"}));
  EXPECT_EQ(cmu.legs, (std::vector<std::string>{"LeftUpLeg", "RightUpLeg", "LeftLeg", "RightLeg"}));
  // The default rig's first spine joint sits at the CMU rig's Hips, 2 cm above its root: the
  // waist is the next, at LowerBack's place.
  const LowerBody mh = findLowerBody(loadAvatarFile(kHumanoidAvatars + "makehuman_rig_default.mhskel"));
  EXPECT_EQ(mh.waist, "spine04");
  EXPECT_EQ(mh.hips, (std::vector<std::string>{"spine05", "pelvis.L", "pelvis.R"}));
  EXPECT_EQ(mh.legs.size(), 8u);
  const LowerBody cesium = findLowerBody(loadAvatarFile(kHumanoidAvatars + "CesiumMan.glb"));
  EXPECT_EQ(cesium.waist, "joint1");
  EXPECT_EQ(cesium.hips, std::vector<std::string>{"joint0"});
  EXPECT_EQ(cesium.legs, (std::vector<std::string>{"joint11", "joint12", "joint13", "joint14"}));
  try {
    (void)findLowerBody(loadAvatarFile(kHumanoidAvatars + "RiggedSimple.glb"));
    ADD_FAILURE() << "RiggedSimple has no lower body";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("RiggedSimple.glb: its lower body cannot be found by the skeleton's shape: 2 "
                                         "joints are too few"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace drape::scene
