// Linear blend skinning of the avatar's smooth mesh (motion/skinning): the rest pose gives
// the rest mesh back, a rigid motion of the whole skeleton moves every vertex rigidly, a
// vertex skinned to one joint follows that joint's rigid motion, and a vertex between two
// joints lands on the weighted mean of where each would take it; bad input is refused.

#include <gtest/gtest.h>

#include <random>

#include "drape/core/error.hpp"
#include "drape/motion/skinning.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "makehuman.hpp"

namespace drape::motion {
namespace {

std::vector<RigidTransform> restPose(const scene::Avatar& avatar) {
  std::vector<RigidTransform> rest;
  for (const scene::Joint& j : avatar.joints) rest.push_back(j.restWorld());
  return rest;
}

RigidTransform randomMotion(std::mt19937& rng) {
  std::normal_distribution<double> n;
  return {Quat(n(rng), n(rng), n(rng), n(rng)).normalized(), Vec3(n(rng), n(rng), n(rng))};
}

TEST(Skinning, TheRestPoseGivesTheRestMesh) {
  const scene::Avatar& a = makeHuman();
  ASSERT_TRUE(a.skin.has_value());
  std::vector<Vec3> posed;
  poseSkin(a, restPose(a), posed);
  ASSERT_EQ(posed.size(), a.skin->mesh.positions.size());
  double worst = 0.0;
  for (std::size_t v = 0; v < posed.size(); ++v) worst = std::max(worst, (posed[v] - a.skin->mesh.positions[v]).norm());
  EXPECT_LT(worst, 1e-6);  // the weights are floats: they sum to 1 within 1e-7
}

TEST(Skinning, ARigidMotionOfTheWholeSkeletonMovesTheMeshRigidly) {
  const scene::Avatar& a = makeHuman();
  std::mt19937 rng(7);
  for (int trial = 0; trial < 5; ++trial) {
    const RigidTransform x = randomMotion(rng);
    std::vector<RigidTransform> pose = restPose(a);
    for (RigidTransform& j : pose) j = x * j;
    std::vector<Vec3> posed;
    poseSkin(a, pose, posed);
    double worst = 0.0;
    for (std::size_t v = 0; v < posed.size(); ++v)
      worst = std::max(worst, (posed[v] - x.apply(a.skin->mesh.positions[v])).norm());
    EXPECT_LT(worst, 1e-5) << "trial " << trial;
  }
}

TEST(Skinning, EachVertexIsTheWeightedMeanOfItsJointsMotions) {
  const scene::Avatar& a = makeHuman();
  std::mt19937 rng(11);
  std::vector<RigidTransform> pose;
  for (std::size_t j = 0; j < a.joints.size(); ++j) pose.push_back(randomMotion(rng));
  std::vector<Vec3> posed;
  poseSkin(a, pose, posed);
  const scene::SkinnedMesh& skin = *a.skin;
  std::size_t single = 0, blended = 0;
  for (std::size_t v = 0; v < posed.size(); v += 7) {
    Vec3 expected = Vec3::Zero();
    int influences = 0;
    for (std::size_t k = 0; k < 4; ++k) {
      const double w = skin.weights[v][k];
      if (w == 0.0) continue;
      const std::size_t j = skin.joints[v][k];
      // Rest world -> the joint's frame -> posed world, written out the long way.
      const Vec3 inJoint = a.joints[j].restWorld().inverse().apply(skin.mesh.positions[v]);
      expected += w * pose[j].apply(inJoint);
      ++influences;
    }
    (influences == 1 ? single : blended) += 1;
    ASSERT_LT((posed[v] - expected).norm(), 1e-9) << "vertex " << v;
  }
  EXPECT_GT(single, 100u);
  EXPECT_GT(blended, 100u);
}

TEST(Skinning, RefusesAMissingSkinAndAWrongJointCount) {
  const scene::Avatar& a = makeHuman();
  std::vector<Vec3> out;
  std::vector<RigidTransform> pose = restPose(a);
  pose.pop_back();
  EXPECT_THROW(poseSkin(a, pose, out), Error);
  scene::Avatar bare = a;
  bare.skin.reset();
  try {
    poseSkin(bare, restPose(bare), out);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("has no skinned mesh"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace drape::motion
