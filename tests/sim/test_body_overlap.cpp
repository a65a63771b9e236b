// Where a motion puts one part of the body inside another (sim/body_overlap): the depth read
// from a part's distance field against the exact depth of the vertices in a box, and which
// joints meet.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "drape/field/shapes.hpp"
#include "drape/sim/body_overlap.hpp"

namespace drape::sim {
namespace {

/// Signed distance to the box [-h, h] (exact).
double boxDistance(const Vec3& p, const Vec3& h) {
  const Vec3 q = p.cwiseAbs() - h;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

RigidTransform randomPose(std::mt19937& rng, double reach_m) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(-reach_m, reach_m);
  return {Quat(n(rng), n(rng), n(rng), n(rng)).normalized(), Vec3(u(rng), u(rng), u(rng))};
}

TEST(BodyOverlap, TheDepthIsTheExactDepthOfTheDeepestVertexWithinTheFieldsAccuracy) {
  // A box part (as the collision's field, 5 mm voxels, the paper's DVDP) and a sphere's
  // surface at random poses: the deepest vertex below the box's surface, exactly, against
  // what the field reads (measured: within the shell the worst of 300 cases is half a voxel,
  // beyond it the read is 0.88 of the depth or more).
  const Vec3 half(0.08, 0.05, 0.06);
  field::FieldSettings fs;
  fs.voxelSize_m = 0.005;
  fs.shell_m = 0.03;
  const PartField box{"box", 0, field::DistanceField::build(field::makeBox(-half, half), fs)};
  const mesh::TriMesh sphere = field::makeSphere(0.04, Vec3::Zero(), 24, 12);
  std::mt19937 rng(7);
  int inside = 0, outside = 0;
  double worst = 0;
  for (int c = 0; c < 300; ++c) {
    const RigidTransform boxPose = randomPose(rng, 0.2);
    const RigidTransform spherePose{Quat::Identity(), boxPose.apply(randomPose(rng, 0.12).translation)};
    double exact = 0;
    for (const Vec3& v : sphere.positions)
      exact = std::max(exact, -boxDistance(boxPose.inverse().apply(spherePose.apply(v)), half));
    const double read = overlapDepth(sphere, spherePose, box, boxPose);
    if (exact <= fs.shell_m) {
      // Within the shell the field's distances are exact to half a voxel (docs/FIELDS.md).
      EXPECT_NEAR(read, exact, 0.5 * fs.voxelSize_m + 1e-9) << "case " << c;
      worst = std::max(worst, std::abs(read - exact));
    } else {
      // Beyond it, between three quarters of the distance and the distance.
      EXPECT_GE(read, 0.75 * exact) << "case " << c;
      EXPECT_LE(read, exact + 0.5 * fs.voxelSize_m) << "case " << c;
    }
    ++(exact > 0 ? inside : outside);
  }
  EXPECT_GT(inside, 50) << "the cases must put the sphere into the box often";
  EXPECT_GT(outside, 20) << "and leave it outside sometimes";
  RecordProperty("worst_error_within_shell_m", std::to_string(worst));
}

TEST(BodyOverlap, JointsMeetWithinTwoStepsOfTheHierarchyOrAsSiblings) {
  // root -> a -> b -> c; root -> d.
  scene::Avatar avatar;
  for (const auto& [name, parent] : std::vector<std::pair<std::string, int>>{
           {"root", -1}, {"a", 0}, {"b", 1}, {"c", 2}, {"d", 0}})
    avatar.joints.push_back({name, parent});
  EXPECT_TRUE(jointsMeet(avatar, 1, 1));
  EXPECT_TRUE(jointsMeet(avatar, 1, 2));  // parent and child
  EXPECT_TRUE(jointsMeet(avatar, 2, 1));
  EXPECT_TRUE(jointsMeet(avatar, 1, 3));  // grandparent and grandchild
  EXPECT_TRUE(jointsMeet(avatar, 3, 1));
  EXPECT_TRUE(jointsMeet(avatar, 1, 4));  // siblings
  EXPECT_FALSE(jointsMeet(avatar, 2, 4));  // a sibling's child
  EXPECT_FALSE(jointsMeet(avatar, 3, 4));
  EXPECT_FALSE(jointsMeet(avatar, 0, 3));  // three steps
}

TEST(BodyOverlap, DescribesSpanAndDepth) {
  BodyOverlap o{"LeftForeArm", "LowerBack", 0.0227, 40, 3, 115, 96, {}};
  EXPECT_EQ(describe(o), "LeftForeArm goes up to 23 mm into LowerBack (frames 3 to 115, 96 frames, deepest in frame 40)");
  o.frames = 1;
  o.lastFrame = o.firstFrame = o.deepestFrame = 7;
  EXPECT_EQ(describe(o), "LeftForeArm goes up to 23 mm into LowerBack (frame 7)");
}

}  // namespace
}  // namespace drape::sim
