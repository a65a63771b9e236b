// The avatar's pose cache: joints evaluated one by one on demand, for the last two times
// asked for, must give exactly what evaluating the whole skeleton gives, however the
// requests for joints and times interleave (lead-in, walk, past the end).

#include <gtest/gtest.h>

#include <random>

#include "drape/motion/animation.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/sim/character_world.hpp"

namespace drape::sim {
namespace {

TEST(AvatarPoses, JointsOnDemandMatchTheWholeSkeleton) {
  const scene::Avatar avatar =
      scene::loadAvatarFile(std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_rig_cmu_mb.mhskel");
  motion::MotionOptions mo;
  mo.clip.rate = 30.0;
  mo.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  const motion::AvatarAnimation animation =
      motion::loadAnimation(avatar, std::string(DRAPE_DATA_DIR) + "/mocap/cmu_12_03_walk.bvh", mo);
  const double leadIn = 1.0;
  const AvatarPoses poses(avatar, &animation, leadIn);
  const std::size_t joints = avatar.joints.size();
  ASSERT_GT(joints, 20u);

  // A few substep times in the lead-in, in the walk and past its end; requests alternate
  // between two or three of them so that the two cache slots are reused and refilled.
  const double dt = 1.0 / (30.0 * 33.0);
  const std::vector<double> times = {0.0, 0.5, 0.5 + dt, leadIn, leadIn + 1.234, leadIn + 1.234 + dt,
                                     leadIn + 2.5, poses.end_s() + 0.5};
  std::vector<std::vector<RigidTransform>> whole(times.size(), std::vector<RigidTransform>(joints));
  for (std::size_t k = 0; k < times.size(); ++k) poses.evaluate(times[k], whole[k]);

  std::mt19937 rng(7);
  std::uniform_int_distribution<std::size_t> pickTime(0, times.size() - 1), pickJoint(0, joints - 1);
  for (int request = 0; request < 5000; ++request) {
    // Mostly neighbouring times (as a substep asks for t0 and t1), sometimes a jump.
    const std::size_t k = request % 7 == 0 ? pickTime(rng) : static_cast<std::size_t>(request / 50) % times.size();
    const std::size_t j = pickJoint(rng);
    const RigidTransform& got = poses.jointAt(times[k], static_cast<int>(j));
    ASSERT_EQ(got.translation, whole[k][j].translation) << "time " << times[k] << " joint " << j;
    ASSERT_EQ(got.rotation.coeffs(), whole[k][j].rotation.coeffs()) << "time " << times[k] << " joint " << j;
  }
  // The lead-in starts at the rest pose and the walk differs from it.
  EXPECT_EQ(poses.jointAt(0.0, 0).translation, avatar.joints[0].restWorld().translation);
  EXPECT_NE(whole[4][0].translation, whole[0][0].translation);
}

}  // namespace
}  // namespace drape::sim
