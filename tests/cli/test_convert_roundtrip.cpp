// `drape convert AVATAR --to avatar.wrl` and back through drape's own VRML97 reader: the
// segmented H-Anim humanoid keeps its joints, segments and geometry, and its motion.

#include <gtest/gtest.h>

#include <algorithm>
#include <span>

#include <fmt/format.h>

#include "cli_runner.hpp"
#include "drape/formats/hanim_writer.hpp"
#include "drape/formats/vrml_read.hpp"
#include "drape/formats/vrml_write.hpp"
#include "drape/motion/animation.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/scene/scene.hpp"

namespace drape {
namespace {

using testing::CliResult;
using testing::runDrape;
using testing::ScratchDir;

struct Expected {
  const char* file;
  std::size_t joints;
  std::size_t segments;
};

class ConvertRoundTrip : public ::testing::TestWithParam<Expected> {};

TEST_P(ConvertRoundTrip, ReadsBackWithTheSameJointsAndSegments) {
  const Expected e = GetParam();
  ScratchDir dir("convert-roundtrip");
  const std::string wrl = dir / "avatar.wrl";
  const CliResult r = runDrape("convert '" + std::string(DRAPE_DATA_DIR) + "/avatars/" + e.file + "' --to '" + wrl + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const scene::Scene back = scene::loadScene(wrl);
  ASSERT_EQ(back.avatars.size(), 1u);
  const scene::Avatar& a = back.avatars[0];
  EXPECT_EQ(a.joints.size(), e.joints);
  EXPECT_EQ(a.segments.size(), e.segments);
  std::size_t triangles = 0;
  for (const scene::Segment& s : a.segments) triangles += s.mesh.triangleCount();
  EXPECT_GT(triangles, 1000u);
  // The body stands on its feet at human height.
  Aabb box;
  for (const scene::Segment& s : a.segments)
    for (const Vec3& p : s.mesh.positions) box.extend(a.joints[static_cast<std::size_t>(s.joint)].restWorld().apply(p));
  EXPECT_GT(box.size().y(), 1.3);
  EXPECT_LT(box.size().y(), 2.0);
}

INSTANTIATE_TEST_SUITE_P(Avatars, ConvertRoundTrip,
                         ::testing::Values(Expected{"CesiumMan.glb", 19, 19},
                                           Expected{"makehuman_rig_cmu_mb.mhskel", 31, 31}),
                         [](const auto& info) { return std::string(info.param.joints == 19 ? "CesiumMan" : "MakeHuman"); });

}  // namespace
}  // namespace drape

namespace drape {
namespace {

using testing::CliResult;
using testing::runDrape;
using testing::ScratchDir;

struct MotionCase {
  const char* name;
  const char* avatar;  // in DRAPE_DATA_DIR/avatars
  const char* motion;  // "": the avatar file's own animation; else a path from the source tree
  std::size_t frames;
};

class ConvertWithMotion : public ::testing::TestWithParam<MotionCase> {};

// The humanoid written with its motion, read back by drape's VRML97 reader (Coin3D): each
// Joint's interpolated rotation and translation about its centre, composed down the
// hierarchy at the key times, move the segments where the motion puts the avatar's joints
// (AvatarAnimation's frames, from the same files), to a tenth of a millimetre: Coin keeps a
// rotation as a single-precision quaternion and gives a small angle back through acos of
// its w, good to about 3e-4 rad, which a joint 0.1 m out turns into some 30 micrometres.
TEST_P(ConvertWithMotion, TheJointsInterpolatorsPoseTheBodyAsTheMotionDoes) {
  const MotionCase c = GetParam();
  ScratchDir dir(std::string("convert-motion-") + c.name);
  const std::string avatarPath = std::string(DRAPE_DATA_DIR) + "/avatars/" + c.avatar;
  const std::string motionPath = *c.motion ? std::string(DRAPE_SOURCE_DIR) + "/" + c.motion : avatarPath;
  const std::string wrl = dir / "walker.wrl";
  const CliResult r = runDrape("convert '" + avatarPath + "' --to '" + wrl + "'" +
                                   (*c.motion ? " --motion '" + motionPath + "'" : std::string()),
                               dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find(fmt::format("frames at 30 Hz, written with it (interpolators routed into the joints)")),
            std::string::npos)
      << r.err;

  const scene::Avatar avatar = scene::loadAvatarFile(avatarPath);
  motion::MotionOptions options;
  options.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  const motion::AvatarAnimation animation = motion::loadAnimation(avatar, motionPath, options);
  ASSERT_EQ(animation.frameCount(), c.frames);

  const formats::vrml::Document d = formats::vrml::readFile(wrl);
  std::vector<std::int32_t> joints(avatar.joints.size(), -1);
  for (std::size_t j = 0; j < avatar.joints.size(); ++j)
    for (std::size_t i = 0; i < d.nodes.size(); ++i)
      if (d.nodes[i].type == "Joint" && d.nodes[i].def == "hanim_" + formats::vrmlIdentifier(avatar.joints[j].name))
        joints[j] = static_cast<std::int32_t>(i);
  for (std::size_t j = 0; j < joints.size(); ++j) ASSERT_GE(joints[j], 0) << avatar.joints[j].name;

  // The Joints rest in the default pose: drape reads the file back as the avatar at rest.
  const scene::Scene back = scene::loadScene(wrl);
  ASSERT_EQ(back.avatars.size(), 1u);
  EXPECT_EQ(back.avatars[0].joints.size(), avatar.joints.size());

  const double cycle = static_cast<double>(c.frames - 1) / 30.0;
  double worst = 0.0;
  for (const std::size_t f : {std::size_t{0}, std::size_t{1}, c.frames / 3, c.frames / 2, c.frames - 1}) {
    const double t = cycle * static_cast<double>(f) / static_cast<double>(c.frames - 1);
    std::vector<RigidTransform> world(avatar.joints.size());
    for (std::size_t j = 0; j < avatar.joints.size(); ++j) {
      const formats::vrml::Node& node = d.nodes[static_cast<std::size_t>(joints[j])];
      const std::vector<double> rotation = formats::vrml::sampleAnimatedField(d, joints[j], "rotation", t);
      ASSERT_EQ(rotation.size(), 4u) << avatar.joints[j].name << " has no rotation interpolator";
      std::vector<double> translation = formats::vrml::sampleAnimatedField(d, joints[j], "translation", t);
      if (translation.empty()) translation = node.field("translation")->numbers;  // not animated: 0 0 0
      const std::vector<double>& centre = node.field("center")->numbers;
      const Vec3 cj(centre[0], centre[1], centre[2]);
      const Quat q(Eigen::AngleAxisd(rotation[3], Vec3(rotation[0], rotation[1], rotation[2]).normalized()));
      // T(t) T(c) R T(-c): x -> R x + t + c - R c, under the parent Joint.
      const RigidTransform local{q, Vec3(translation[0], translation[1], translation[2]) + cj - q * cj};
      const int p = avatar.joints[j].parent;
      world[j] = p >= 0 ? world[static_cast<std::size_t>(p)] * local : local;
    }
    const std::span<const RigidTransform> expected = animation.frame(f);
    for (const scene::Segment& s : avatar.segments) {
      const auto j = static_cast<std::size_t>(s.joint);
      const RigidTransform rest = avatar.joints[j].restWorld();
      for (std::size_t v = 0; v < s.mesh.positions.size(); v += 7) {
        const Vec3& p = s.mesh.positions[v];  // in the joint's frame
        worst = std::max(worst, (world[j].apply(rest.apply(p)) - expected[j].apply(p)).norm());
      }
    }
  }
  EXPECT_LT(worst, 1e-4) << "m, the largest distance of a segment point from where the motion puts it";
}

INSTANTIATE_TEST_SUITE_P(
    Avatars, ConvertWithMotion,
    ::testing::Values(MotionCase{"CesiumMansOwnWalk", "CesiumMan.glb", "", 61},
                      MotionCase{"MakeHumanWithTheBundledWalk", "makehuman_rig_cmu_mb.mhskel",
                                 "examples/walking_skirt/walk.bvh", 141}),
    [](const auto& info) { return std::string(info.param.name); });

// Errors name what is wrong: an animation the file does not have, and one asked of a file
// that carries none.
TEST(ConvertWithMotion, AnAnimationTheFileDoesNotHaveIsAClearError) {
  ScratchDir dir("convert-motion-errors");
  const std::string cesium = std::string(DRAPE_DATA_DIR) + "/avatars/CesiumMan.glb";
  CliResult r = runDrape("convert '" + cesium + "' --animation Dance --to '" + (dir / "x.wrl") + "'", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("Dance"), std::string::npos) << r.err;
  const std::string body = std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_rig_cmu_mb.mhskel";
  r = runDrape("convert '" + body + "' --animation 0 --to '" + (dir / "y.wrl") + "'", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--animation 0: " + body + " carries no animations"), std::string::npos) << r.err;
  // Without a motion the humanoid is written at rest, as before.
  r = runDrape("convert '" + body + "' --to '" + (dir / "z.wrl") + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(testing::slurp(dir / "z.wrl").find("Interpolator"), std::string::npos);
}

}  // namespace
}  // namespace drape
