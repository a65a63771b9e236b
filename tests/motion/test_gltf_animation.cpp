// A glTF avatar's own animation as its motion (AvatarAnimation::fromJointMotion):
// CesiumMan's walk skins its mesh as the file's joint motions say, wherever and at whatever
// scale a scene places the avatar; its walk is a cycle on the floor; an avatar of another
// file is refused.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "drape/formats/gltf_avatar.hpp"
#include "drape/motion/animation.hpp"
#include "drape/motion/skinning.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/testing/errors.hpp"

namespace drape::motion {
namespace {

using drape::testing::errorOf;

std::string cesiumPath() { return std::string(DRAPE_DATA_DIR) + "/avatars/CesiumMan.glb"; }

const scene::Avatar& cesiumMan() {
  static const scene::Avatar avatar = scene::loadAvatarFile(cesiumPath());
  return avatar;
}

const formats::GltfJointMotion& cesiumWalk() {
  static const formats::GltfJointMotion motion = formats::readGltfJointMotion(cesiumPath(), 30.0);
  return motion;
}

/// Where a scene's Avatar node puts an avatar: scaled, then turned and moved (as
/// sim/scene_setup does it).
scene::Avatar placed(scene::Avatar avatar, const RigidTransform& placement, double scale) {
  for (scene::Joint& j : avatar.joints) {
    j.restCenter = placement.apply(scale * j.restCenter);
    j.restOrientation = (placement.rotation * j.restOrientation).normalized();
  }
  for (scene::Segment& s : avatar.segments) s.mesh.scale(scale);
  avatar.skin->mesh.scale(scale);
  avatar.skin->mesh.transform(placement);
  return avatar;
}

TEST(GltfAnimation, CesiumMansWalkSkinsItsMeshAsTheFileMovesItsJoints) {
  const scene::Avatar& avatar = cesiumMan();
  const formats::GltfJointMotion& walk = cesiumWalk();
  const AvatarAnimation anim = loadAnimation(avatar, cesiumPath(), MotionOptions{});
  ASSERT_EQ(anim.frameCount(), 61u);
  ASSERT_EQ(anim.jointCount(), 19u);
  EXPECT_DOUBLE_EQ(anim.rate(), 30.0);
  for (const int j : anim.drivingJoint()) EXPECT_GE(j, 0);
  const std::vector<Vec3>& rest = avatar.skin->mesh.positions;
  std::vector<Vec3> posed;
  for (const std::size_t f : {0u, 17u, 30u, 60u}) {
    poseSkin(avatar, anim.frame(f), posed);
    double worst = 0.0;
    for (std::size_t v = 0; v < rest.size(); ++v) {
      // Each joint k moves a point rigidly: p -> R_k (p - c_k) + c_k(t), blended by weight.
      Vec3 expected = Vec3::Zero();
      for (int i = 0; i < 4; ++i) {
        const std::size_t k = avatar.skin->joints[v][static_cast<std::size_t>(i)];
        const RigidTransform& m = walk.frames[f * walk.joints.size() + k];
        expected += static_cast<double>(avatar.skin->weights[v][static_cast<std::size_t>(i)]) *
                    (m.rotation * (rest[v] - walk.restCenters[k]) + m.translation);
      }
      worst = std::max(worst, (posed[v] - expected).norm());
    }
    EXPECT_LT(worst, 1e-6) << "frame " << f;  // the weights are floats
  }
}

TEST(GltfAnimation, APlacedAvatarWalksThePlacedWalk) {
  const RigidTransform placement{Quat(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitY())), Vec3(1.0, 0.0, 3.0)};
  const double scale = 2.0;
  const scene::Avatar there = placed(cesiumMan(), placement, scale);
  const AvatarAnimation here = AvatarAnimation::fromJointMotion(cesiumMan(), cesiumWalk(), "CesiumMan.glb");
  const AvatarAnimation moved = AvatarAnimation::fromJointMotion(there, cesiumWalk(), "CesiumMan.glb");
  EXPECT_NEAR(moved.rootScale(), scale, 1e-12);
  std::vector<Vec3> a, b;
  for (const std::size_t f : {0u, 25u, 60u}) {
    poseSkin(cesiumMan(), here.frame(f), a);
    poseSkin(there, moved.frame(f), b);
    double worst = 0.0;
    for (std::size_t v = 0; v < a.size(); ++v) worst = std::max(worst, (placement.apply(scale * a[v]) - b[v]).norm());
    EXPECT_LT(worst, 1e-6) << "frame " << f;  // float weights sum to 1 within 1e-7
  }
}

TEST(GltfAnimation, CesiumMansWalkIsACycleOnTheFloor) {
  const AvatarAnimation anim = AvatarAnimation::fromJointMotion(cesiumMan(), cesiumWalk(), "CesiumMan.glb");
  std::vector<Vec3> posed;
  double lowest = 1e9, highestLowest = -1e9;
  for (std::size_t f = 0; f < anim.frameCount(); ++f) {
    poseSkin(cesiumMan(), anim.frame(f), posed);
    double low = 1e9;
    for (const Vec3& p : posed) low = std::min(low, p.y());
    lowest = std::min(lowest, low);
    highestLowest = std::max(highestLowest, low);
  }
  // The feet stay on the floor the avatar stands on at rest (y = 0) within the walk's bob:
  // a wrong unit, placement or joint order would float or sink the body by decimetres.
  EXPECT_GT(lowest, -0.03);
  EXPECT_LT(highestLowest, 0.05);
  // The 2 s walk is a cycle: its last frame is its first.
  for (std::size_t j = 0; j < anim.jointCount(); ++j) {
    EXPECT_LT((anim.frame(0)[j].translation - anim.frame(60)[j].translation).norm(), 1e-12) << j;
    EXPECT_LT(anim.frame(0)[j].rotation.angularDistance(anim.frame(60)[j].rotation), 1e-9) << j;
  }
}

TEST(GltfAnimation, AvatarsOfOtherFilesAreRefused) {
  const scene::Avatar makeHuman =
      scene::loadAvatarFile(std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_rig_cmu_mb.mhskel");
  const std::string e = errorOf([&] { (void)AvatarAnimation::fromJointMotion(makeHuman, cesiumWalk(), "walk.glb"); });
  EXPECT_EQ(e.rfind("walk.glb: its skin has no joint named Hips, ", 0), 0u) << e;
  EXPECT_NE(e.find("(31 of 31 missing): an avatar file's animation drives the avatar of its own file"), std::string::npos) << e;

  scene::Avatar moved = cesiumMan();
  moved.joints[3].restCenter.x() += 0.05;  // the same names, another skeleton
  const std::string rests = errorOf([&] { (void)AvatarAnimation::fromJointMotion(moved, cesiumWalk(), "walk.glb"); });
  EXPECT_EQ(rests.rfind("walk.glb: the skeleton of its animation does not rest as avatar 'CesiumMan' does (joint '", 0), 0u)
      << rests;

  // With a joint map the file's skeleton is retargeted, even onto its own avatar: the map
  // is read.
  EXPECT_EQ(errorOf([&] {
              MotionOptions o;
              o.jointMapPath = "map.json";
              (void)loadAnimation(cesiumMan(), cesiumPath(), o);
            }),
            "map.json: no such file");
  // Onto another avatar without a map, none of the shipped ones pairing its joints: they
  // are paired by the two skeletons' shapes (tests/motion/test_shape_map.cpp).
  MotionOptions shipped;
  shipped.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  JointMap chosen;
  (void)loadAnimation(makeHuman, cesiumPath(), shipped, nullptr, &chosen);
  EXPECT_EQ(chosen.name, "by shape");
}

TEST(GltfAnimation, ASkeletonOfTheSameNamesRestingOtherwiseIsRetargeted) {
  // CesiumMan with one arm bone 5 cm longer: the file's walk does not fit it as its own,
  // so it is retargeted through the pairing of equal names, and the avatar keeps its bones.
  scene::Avatar longer = cesiumMan();
  const auto joint = [&](const char* name) { return static_cast<std::size_t>(longer.findJoint(name)); };
  const std::size_t elbow = joint("joint7"), shoulder = joint("joint5");
  const Vec3 bone = longer.joints[elbow].restCenter - longer.joints[shoulder].restCenter;
  for (scene::Joint& j : longer.joints)
    for (int p = j.parent; p >= 0; p = longer.joints[static_cast<std::size_t>(p)].parent)
      if (static_cast<std::size_t>(p) == shoulder && &j != &longer.joints[shoulder]) {
        j.restCenter += 0.05 * bone.normalized();
        break;
      }
  const double length = (longer.joints[elbow].restCenter - longer.joints[shoulder].restCenter).norm();
  ASSERT_NEAR(length, bone.norm() + 0.05, 1e-12);

  MotionOptions o;
  o.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  JointMap map;
  const AvatarAnimation anim = loadAnimation(longer, cesiumPath(), o, nullptr, &map);
  EXPECT_EQ(map.name, "same names");
  ASSERT_EQ(anim.frameCount(), cesiumWalk().frameCount());
  for (std::size_t f = 0; f < anim.frameCount(); ++f)
    EXPECT_NEAR((anim.frame(f)[elbow].translation - anim.frame(f)[shoulder].translation).norm(), length, 1e-9) << f;
}

}  // namespace
}  // namespace drape::motion
