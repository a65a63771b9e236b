// `drape convert` to and from Collada and FBX (with the glTF's animation, or a BVH walk
// retargeted onto the avatar), and `drape inspect` on them: real files exit 0, a bad file
// exits 2 with a message naming it.

#include <gtest/gtest.h>

#include "cli_runner.hpp"

namespace drape {
namespace {

using testing::CliResult;
using testing::runDrape;
using testing::ScratchDir;

std::string cesiumMan() { return std::string(DRAPE_DATA_DIR) + "/avatars/CesiumMan.glb"; }

class ConvertAssimp : public ::testing::TestWithParam<const char*> {};

TEST_P(ConvertAssimp, GlbToSkinnedFileThenInspectAndToHanim) {
  ScratchDir dir(std::string("convert-assimp-") + (GetParam() + 1));
  const std::string skinned = dir / (std::string("CesiumMan") + GetParam());
  CliResult r = runDrape("convert '" + cesiumMan() + "' --to '" + skinned + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find(skinned + ": 1 animation sampled at 30 Hz written with it ("), std::string::npos) << r.err;

  r = runDrape("inspect '" + skinned + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("joints     19"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("segments   19"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("4672 triangles"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("motion     1 animation; drape run plays it on this avatar by itself (--motion none: at rest), "
                       "and --motion " + skinned + " on another, retargeted"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("2.000 s (0.000 to 2.000 s of key times), 61 frames at 30 Hz"), std::string::npos) << r.out;

  const std::string wrl = dir / "CesiumMan.wrl";
  r = runDrape("convert '" + skinned + "' --to '" + wrl + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(testing::slurp(wrl).find(" Humanoid {"), std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(Formats, ConvertAssimp, ::testing::Values(".dae", ".fbx"),
                         [](const auto& info) { return std::string(info.param + 1); });

TEST_P(ConvertAssimp, MakeHumanWithTheWalkThenRunsOnIt) {
  // The MakeHuman body with the bundled CMU walk retargeted onto it, written as one file; the
  // walking skirt's scene then walks on that file's animation.
  ScratchDir dir(std::string("convert-assimp-walker-") + (GetParam() + 1));
  const std::string walker = dir / (std::string("walker") + GetParam());
  const std::string body = std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_rig_cmu_mb.mhskel";
  CliResult r = runDrape("convert '" + body + "' --motion '" + testing::kSkirtDir + "/walk.bvh' --to '" + walker + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find(walker + ": 1 animation sampled at 30 Hz written with it ('walk', 141 frames)"), std::string::npos)
      << r.err;
  const std::string run = dir / "run";
  r = runDrape("run '" + testing::kSkirtDir + "/scene.wrl' --motion '" + walker + "' --frames 40 --out '" + run + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("joint map 'its own skin's joints ("), std::string::npos) << r.err;
  EXPECT_EQ(testing::statsOf(run)["vertex_substeps_inside_body"], 0);
}

TEST(ConvertAssimp, AJointMapNeedsAMotion) {
  ScratchDir dir("convert-assimp-motion-errors");
  const std::string body = std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_rig_cmu_mb.mhskel";
  const CliResult r = runDrape("convert '" + body + "' --joint-map x.json --to '" + (dir / "walker.dae") + "'", dir);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("--joint-map requires --motion"), std::string::npos) << r.err;
}

TEST(ConvertAssimp, HandWrittenColladaToHanim) {
  ScratchDir dir("convert-assimp-tube");
  const std::string tube = std::string(DRAPE_TEST_DATA_DIR) + "/avatars/tube_two_joints.dae";
  const CliResult r = runDrape("convert '" + tube + "' --to '" + (dir / "tube.wrl") + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
}

TEST(ConvertAssimp, BadFileExitsTwo) {
  ScratchDir dir("convert-assimp-bad");
  const std::string bad = std::string(DRAPE_TEST_DATA_DIR) + "/bad/avatar/truncated.dae";
  CliResult r = runDrape("convert '" + bad + "' --to '" + (dir / "x.wrl") + "'", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(bad + ": "), std::string::npos) << r.err;
  r = runDrape("inspect '" + std::string(DRAPE_TEST_DATA_DIR) + "/bad/avatar/text_garbage.fbx'", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("not an FBX file"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace drape
