// Collada and FBX animations as the motion of a skin's joints (formats/assimp_avatar): keys
// written by drape's writer and read back through Assimp are interpolated as the reader
// says (translations linearly, rotations by SLERP, children carried by their parents),
// checked against the values computed by hand; CesiumMan's glTF walk, written as Collada
// and as FBX, reads back as the glTF reader samples it; and a file without the animation
// asked for is an error that lists those it has.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <set>
#include <numbers>
#include <string>
#include <vector>

#include "drape/formats/assimp_avatar.hpp"
#include "drape/formats/avatar_motion.hpp"
#include "drape/formats/gltf_avatar.hpp"
#include "drape/testing/errors.hpp"
#include "drape/testing/temp_dir.hpp"

namespace drape::formats {
namespace {

using drape::testing::errorOf;

const std::string kCesium = std::string(DRAPE_DATA_DIR) + "/avatars/CesiumMan.glb";

/// Two joints: "hip" at the origin and its child "knee" 1 m above it, one triangle weighed
/// by each.
SkinnedModel twoJoints() {
  SkinnedModel m;
  m.source = "two_joints";
  SkinnedJoint hip{"hip", -1, Eigen::Matrix4d::Identity()};
  SkinnedJoint knee{"knee", 0, Eigen::Matrix4d::Identity()};
  knee.restWorld(1, 3) = 1.0;
  m.joints = {hip, knee};
  m.positions = {Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0, 1, 0), Vec3(0.1, 1, 0)};
  m.triangles = {{0, 1, 2}, {1, 3, 2}};
  m.vertexJoints = {{0, 0, 0, 0}, {0, 0, 0, 0}, {1, 0, 0, 0}, {1, 0, 0, 0}};
  m.vertexWeights = {{1, 0, 0, 0}, {1, 0, 0, 0}, {1, 0, 0, 0}, {1, 0, 0, 0}};
  return m;
}

/// Two keys a second apart: the hip moves 2 m along x and turns 90 degrees about z; the
/// knee, fixed to it 1 m up, is carried along.
SkinnedJointMotion turnAndStride(const std::string& name) {
  SkinnedJointMotion m;
  m.animation = name;
  m.animationNames = {name};
  m.rate = 1.0;
  m.start_s = 0.0;
  m.end_s = 1.0;
  m.joints = {"hip", "knee"};
  m.restCenters = {Vec3(0, 0, 0), Vec3(0, 1, 0)};
  const Quat turned(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitZ()));
  m.frames = {{Quat::Identity(), Vec3(0, 0, 0)}, {Quat::Identity(), Vec3(0, 1, 0)},
              {turned, Vec3(2, 0, 0)},           {turned, Vec3(2, 0, 0) + turned * Vec3(0, 1, 0)}};
  return m;
}

class AssimpMotion : public ::testing::TestWithParam<std::string> {
 protected:
  [[nodiscard]] std::string written(const std::string& stem, const std::vector<SkinnedJointMotion>& animations) const {
    const std::string path = (drape::testing::processTempDir("assimp-motion") / (stem + GetParam())).string();
    writeAssimpSkinnedModel(path, twoJoints(), animations);
    return path;
  }
};

TEST_P(AssimpMotion, KeysAreInterpolatedAsTheReaderSays) {
  const std::string path = written("turn", {turnAndStride("turn")});
  const SkinnedJointMotion m = readAssimpJointMotion(path, 4.0);
  ASSERT_EQ(m.joints, (std::vector<std::string>{"hip", "knee"}));
  ASSERT_EQ(m.frameCount(), 5u);
  EXPECT_NEAR(m.start_s, 0.0, 1e-6);
  EXPECT_NEAR(m.end_s, 1.0, 1e-6);
  EXPECT_NEAR((m.restCenters[1] - Vec3(0, 1, 0)).norm(), 0.0, 1e-6);
  for (std::size_t f = 0; f < 5; ++f) {
    const double u = static_cast<double>(f) / 4.0;
    const double angle = u * std::numbers::pi / 2;  // SLERP about one axis: the angle in proportion
    const Quat expected(Eigen::AngleAxisd(angle, Vec3::UnitZ()));
    const Vec3 hip(2.0 * u, 0, 0);
    const Vec3 knee = hip + expected * Vec3(0, 1, 0);
    const RigidTransform& h = m.frames[2 * f];
    const RigidTransform& k = m.frames[2 * f + 1];
    SCOPED_TRACE("frame " + std::to_string(f));
    EXPECT_LT(h.rotation.angularDistance(expected), 1e-5);
    EXPECT_LT(k.rotation.angularDistance(expected), 1e-5);
    EXPECT_LT((h.translation - hip).norm(), 1e-5);
    EXPECT_LT((k.translation - knee).norm(), 1e-5);
  }
}

TEST_P(AssimpMotion, ChoosesAnimationsByNameOrIndexAndListsThemWhenAbsent) {
  const std::string path = written("two", {turnAndStride("walk"), turnAndStride("run")});
  const std::vector<SkinnedJointMotion> all = readAssimpJointMotions(path, 2.0);
  ASSERT_EQ(all.size(), 2u);
  const std::string walk = all[0].animation, run = all[1].animation;
  EXPECT_NE(walk.find("walk"), std::string::npos) << walk;  // Collada's reader prefixes it
  EXPECT_NE(run.find("run"), std::string::npos) << run;
  EXPECT_EQ(readAssimpJointMotion(path, 2.0, "1").animation, run);
  EXPECT_EQ(readAssimpJointMotion(path, 2.0, run).animation, run);
  EXPECT_EQ(readAvatarMotion(path, 2.0, walk).animation, walk);
  EXPECT_EQ(errorOf([&] { (void)readAssimpJointMotion(path, 2.0, "jog"); }),
            path + ": has no animation 'jog' (it has 2: 0 '" + walk + "', 1 '" + run + "')");

  const std::string still = written("still", {});
  EXPECT_TRUE(readAssimpJointMotions(still, 30.0).empty());
  EXPECT_EQ(errorOf([&] { (void)readAssimpJointMotion(still, 30.0); }), still + ": has no animation");
}

TEST_P(AssimpMotion, TheSkinsReaderNamesTheAnimationsTheFileCarries) {
  // What an avatar loaded from the file could play by itself: the motion reader's names, in
  // its order; none for a file without animations. The skin is the same either way.
  const std::string two = written("two-named", {turnAndStride("walk"), turnAndStride("run")});
  const SkinnedModel model = readAssimpSkinnedModel(two);
  EXPECT_EQ(model.animations, readAssimpJointMotions(two, 2.0).front().animationNames);
  ASSERT_EQ(model.animations.size(), 2u);
  const SkinnedModel still = readAssimpSkinnedModel(written("still-named", {}));
  EXPECT_TRUE(still.animations.empty());
  EXPECT_EQ(still.positions, model.positions);
  EXPECT_EQ(still.triangles, model.triangles);
  ASSERT_EQ(still.joints.size(), model.joints.size());
  for (std::size_t j = 0; j < model.joints.size(); ++j) {
    EXPECT_EQ(still.joints[j].name, model.joints[j].name);
    EXPECT_TRUE(still.joints[j].restWorld.isApprox(model.joints[j].restWorld, 1e-12)) << model.joints[j].name;
  }
}

TEST_P(AssimpMotion, WriterRefusesAnAnimationThatMissesAJoint) {
  SkinnedJointMotion hipOnly = turnAndStride("walk");
  hipOnly.joints = {"hip"};
  hipOnly.restCenters.resize(1);
  hipOnly.frames = {hipOnly.frames[0], hipOnly.frames[2]};
  const std::string path = (drape::testing::processTempDir("assimp-motion") / ("hip" + GetParam())).string();
  EXPECT_EQ(errorOf([&] { writeAssimpSkinnedModel(path, twoJoints(), {hipOnly}); }),
            path + ": animation 'walk' does not move joint 'knee' of the avatar");
}

TEST_P(AssimpMotion, CesiumMansWalkReadsBackAsTheGltfReaderSamplesIt) {
  const GltfJointMotion walk = readGltfJointMotion(kCesium, 30.0);
  const std::string path = (drape::testing::processTempDir("assimp-motion") / ("cesium" + GetParam())).string();
  writeAssimpSkinnedModel(path, readGltfSkinnedModel(kCesium), {walk});
  const SkinnedJointMotion back = readAssimpJointMotion(path, 30.0);
  // The same joints, parents first in the order of each file's node tree.
  ASSERT_EQ(std::set<std::string>(back.joints.begin(), back.joints.end()),
            std::set<std::string>(walk.joints.begin(), walk.joints.end()));
  ASSERT_EQ(back.frameCount(), walk.frameCount());
  EXPECT_NEAR(back.start_s, walk.start_s, 1e-6);
  EXPECT_NEAR(back.end_s, walk.end_s, 1e-6);
  // Collada keeps single-precision keys; Assimp's ASCII FBX writer prints six significant
  // digits (centimetres, Euler angles in degrees), which a chain of joints adds up.
  const bool fbx = GetParam() == ".fbx";
  const double restTolerance = fbx ? 1e-4 : 1e-6, angleTolerance = fbx ? 1e-3 : 1e-5, positionTolerance = fbx ? 5e-4 : 1e-5;
  const std::size_t jn = walk.joints.size();
  double worstAngle = 0.0, worstPosition = 0.0;
  for (std::size_t j = 0; j < jn; ++j) {
    const auto k = static_cast<std::size_t>(std::find(back.joints.begin(), back.joints.end(), walk.joints[j]) - back.joints.begin());
    EXPECT_LT((back.restCenters[k] - walk.restCenters[j]).norm(), restTolerance) << walk.joints[j];
    for (std::size_t f = 0; f < walk.frameCount(); ++f) {
      const RigidTransform& a = walk.frames[f * jn + j];
      const RigidTransform& b = back.frames[f * jn + k];
      worstAngle = std::max(worstAngle, b.rotation.angularDistance(a.rotation));
      worstPosition = std::max(worstPosition, (b.translation - a.translation).norm());
    }
  }
  EXPECT_LT(worstAngle, angleTolerance);
  EXPECT_LT(worstPosition, positionTolerance);
}

TEST(AssimpMotionFbx, PivotsAndPreRotationsMoveTheJointsAsFbxSays) {
  // The turning hip of turnAndStride, as ASCII FBX with a pre-rotation of 30 degrees about
  // z and a rotation pivot 0.5 m up added to it, as Maya and the tools that export for it
  // write: FBX places it at T(t) Rp Rpre R(t) Rp^-1, so its frame turns by Rz(30 + 90 u)
  // about the pivot, and the knee, 1 m up the hip's frame, follows. (Assimp hands such a
  // node's animation over as channels of helper nodes, one per part of that product.)
  const std::string path = (drape::testing::processTempDir("assimp-motion") / "pivot.fbx").string();
  writeAssimpSkinnedModel(path, twoJoints(), {turnAndStride("turn")});
  std::string text;
  {
    std::ifstream in(path);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const std::size_t model = text.find("\"Model::hip\", \"LimbNode\"");
  ASSERT_NE(model, std::string::npos);
  const std::size_t props = text.find("Properties70:  {\n", model);
  ASSERT_NE(props, std::string::npos);
  text.insert(props + std::strlen("Properties70:  {\n"),
              "\t\t\tP: \"PreRotation\", \"Vector3D\", \"Vector\", \"\",0,0,30\n"
              "\t\t\tP: \"RotationPivot\", \"Vector3D\", \"Vector\", \"\",0,50,0\n");
  std::ofstream(path, std::ios::trunc) << text;

  const SkinnedJointMotion m = readAssimpJointMotion(path, 4.0);
  ASSERT_EQ(m.frameCount(), 5u);
  const Vec3 pivot(0, 0.5, 0);
  const auto frame = [&](double degrees) { return Quat(Eigen::AngleAxisd(degrees * std::numbers::pi / 180, Vec3::UnitZ())); };
  for (std::size_t f = 0; f < 5; ++f) {
    const double u = static_cast<double>(f) / 4.0;
    const Quat turn = frame(30 + 90 * u);
    const Vec3 hip = Vec3(2.0 * u, 0, 0) + pivot - turn * pivot;
    const Vec3 knee = hip + turn * Vec3(0, 1, 0);
    SCOPED_TRACE("frame " + std::to_string(f));
    EXPECT_LT(m.frames[2 * f].rotation.angularDistance(frame(90 * u)), 1e-5);  // from the rest turn of 30
    EXPECT_LT((m.frames[2 * f].translation - hip).norm(), 1e-5);
    EXPECT_LT((m.frames[2 * f + 1].translation - knee).norm(), 1e-5);
  }
}

TEST_P(AssimpMotion, RiggedSimplesConvertedWalkReadsBack) {
  // tests/data/avatars/rigged_simple_animated.*: `drape convert` of the bundled RiggedSimple.
  const std::string gltf = std::string(DRAPE_DATA_DIR) + "/avatars/RiggedSimple.glb";
  const std::string converted = std::string(DRAPE_TEST_DATA_DIR) + "/avatars/rigged_simple_animated" + GetParam();
  const std::vector<SkinnedJointMotion> all = readAvatarMotions(converted, 30.0);
  ASSERT_EQ(all.size(), 1u);
  const SkinnedJointMotion walk = readAvatarMotion(gltf, 30.0);
  ASSERT_EQ(all[0].frameCount(), walk.frameCount());
  ASSERT_EQ(all[0].joints, walk.joints);
  for (std::size_t i = 0; i < walk.frames.size(); ++i) {
    EXPECT_LT(all[0].frames[i].rotation.angularDistance(walk.frames[i].rotation), 1e-3) << i;
    EXPECT_LT((all[0].frames[i].translation - walk.frames[i].translation).norm(), 1e-4) << i;
  }
}

INSTANTIATE_TEST_SUITE_P(Formats, AssimpMotion, ::testing::Values(".dae", ".fbx"),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param == ".dae" ? "Collada" : "Fbx"; });

}  // namespace
}  // namespace drape::formats
