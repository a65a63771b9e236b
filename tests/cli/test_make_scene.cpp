// `drape make-scene`: the MakeHuman dress on the MakeHuman body becomes a scene that drape
// reads, binds and simulates on the walk; the substeps come from mass scaling.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "drape/scene/scene.hpp"
#include "drape/testing/long_scenario.hpp"

namespace drape {
namespace {

using testing::CliResult;
using testing::runDrape;
using testing::ScratchDir;
using testing::statsOf;

const std::string kSource = DRAPE_SOURCE_DIR;

/// `drape make-scene` on the MakeHuman body with the dress (`garment`: its .obj or .mhclo)
/// and the hanging-dress mask, plus `options`, writing to `out`.
std::string makeDressScene(const std::string& garment, const std::string& options, const std::string& out) {
  return "make-scene '" + kSource + "/data/avatars/makehuman_rig_cmu_mb.mhskel' --garment '" + kSource +
         "/data/garments/makehuman_female_elegantsuit01_dress." + garment + "' --units dm --mask '" + kSource +
         "/examples/hanging_dress/shoulders_mask.obj' " + options + " --out '" + out + "'";
}

TEST(MakeScene, WritesWhereTheAvatarsPartsAreCut) {
  // --cut-at-joints is written as the Avatar node's cutAtJoints, and the collidable parts
  // are found on the parts as cut; a joint the avatar lacks is an error before anything is
  // written.
  ScratchDir dir("make-scene-cut");
  const std::string sceneDir = dir / "dress";
  const CliResult made =
      runDrape(makeDressScene("mhclo", "--name dress --cut-at-joints LeftArm,RightArm", sceneDir), dir);
  ASSERT_EQ(made.code, 0) << made.err;
  const scene::Scene sc = scene::loadScene(sceneDir + "/scene.wrl");
  ASSERT_EQ(sc.externalAvatars.size(), 1u);
  EXPECT_EQ(sc.externalAvatars[0].cutAtJoints, (std::vector<std::string>{"LeftArm", "RightArm"}));
  const std::vector<std::string>& parts = sc.garments.at(0).collidesWith;
  EXPECT_NE(std::find(parts.begin(), parts.end(), "LeftShoulder"), parts.end());
  const CliResult bad = runDrape(makeDressScene("mhclo", "--name dress --cut-at-joints Tail", dir / "bad"), dir);
  EXPECT_EQ(bad.code, 2) << bad.err;
  EXPECT_NE(bad.err.find("cutAtJoints names 'Tail', which is not a joint of avatar"), std::string::npos) << bad.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "bad/scene.wrl"));
}

TEST(MakeScene, DressOnTheWalkingBody) {
  DRAPE_LONG_SCENARIO();
  ScratchDir dir("make-scene-dress");
  const std::string sceneDir = dir / "dress";
  const CliResult made = runDrape(makeDressScene("obj",
                                                  "--name dress --offsets 0.002,0.004,0.006,0.016 --collides-with "
                                                  "Hips,LowerBack,Spine,Spine1,Neck,LeftShoulder,RightShoulder,"
                                                  "LeftArm,RightArm,LeftUpLeg,RightUpLeg --face-samples-with "
                                                  "LeftUpLeg,RightUpLeg --keep-apart LeftForeArm,RightForeArm --self-collision 0.003",
                                                  sceneDir),
                                   dir);
  ASSERT_EQ(made.code, 0) << made.err;
  EXPECT_NE(made.out.find("substeps per frame"), std::string::npos) << made.out;

  const scene::Scene sc = scene::loadScene(sceneDir + "/scene.wrl");
  ASSERT_EQ(sc.garments.size(), 1u);
  EXPECT_EQ(sc.garments[0].mesh.triangleCount(), 4192u);
  EXPECT_EQ(sc.garments[0].maskVertices.size(), 222u);
  EXPECT_EQ(sc.garments[0].faceSamplesWith, (std::vector<std::string>{"LeftUpLeg", "RightUpLeg"}));
  EXPECT_EQ(sc.simulation.keepApart, (std::vector<std::string>{"LeftForeArm", "RightForeArm"}));
  EXPECT_NEAR(sc.garments[0].selfCollision, 0.003, 1e-9);
  ASSERT_EQ(sc.externalAvatars.size(), 1u);
  EXPECT_TRUE(sc.externalAvatars[0].cutAtJoints.empty());
  EXPECT_GT(sc.simulation.stepsPerFrame, 33) << "the dress's slivers need more substeps than the skirt";
  EXPECT_GT(sc.simulation.maxAddedMass, 0.0);

  const std::string out = dir / "out";
  const CliResult ran = runDrape("run '" + sceneDir + "/scene.wrl' --motion '" + kSource +
                                     "/examples/walking_skirt/walk.bvh' --lead-in 0.2 --frames 3 --self-collision 0 --out '" + out + "'",
                                 dir);
  ASSERT_EQ(ran.code, 0) << ran.err;
  const nlohmann::json stats = statsOf(out);
  EXPECT_EQ(stats["frames"].get<int>(), 3);
  EXPECT_EQ(stats["vertex_substeps_inside_body"].get<long>(), 0);
  EXPECT_GT(stats["pairs_embedded_at_start"].get<long>(), 0) << "the dress is modelled tight on the body";
  const nlohmann::json& g = stats["garments"][0];
  EXPECT_GT(g["added_mass_kg"].get<double>(), 0.0);
  EXPECT_LT(g["added_mass_kg"].get<double>(), 0.02 * g["mass_kg"].get<double>());
  EXPECT_EQ(g["face_samples_with"], nlohmann::json({"LeftUpLeg", "RightUpLeg"}));
  EXPECT_FALSE(g.contains("self_collision")) << "--self-collision 0 overrides the scene's";
  // 'none' takes the scene's face samples away.
  const std::string plain = dir / "plain";
  const CliResult none = runDrape("run '" + sceneDir + "/scene.wrl' --motion '" + kSource +
                                      "/examples/walking_skirt/walk.bvh' --lead-in 0.2 --frames 1 --face-samples-with none "
                                      "--out '" + plain + "'",
                                  dir);
  ASSERT_EQ(none.code, 0) << none.err;
  EXPECT_EQ(statsOf(plain)["garments"][0]["face_samples_with"], nlohmann::json::array());
}

TEST(MakeScene, AMakeHumanGarmentIsRefittedWithItsMask) {
  // The .mhclo route: the dress refitted to drape's MakeHuman body; the mask, given on the
  // OBJ as modelled, moves with the fit, so the scene still matches all of it.
  ScratchDir dir("make-scene-mhclo");
  const std::string sceneDir = dir / "dress";
  const CliResult made =
      runDrape(makeDressScene("mhclo", "--substeps 155 --bend-every 2 --collision-every 3 --collides-with Hips,Spine1 "
                              "--stitch-gaps 0.02",
                              sceneDir),
               dir);
  ASSERT_EQ(made.code, 0) << made.err;
  EXPECT_NE(made.out.find("16 stitches across gaps of up to 15.8 mm"), std::string::npos) << made.out;
  const scene::Scene sc = scene::loadScene(sceneDir + "/scene.wrl");
  ASSERT_EQ(sc.garments.size(), 1u);
  EXPECT_EQ(sc.garments[0].mesh.triangleCount(), 4192u);
  EXPECT_EQ(sc.garments[0].maskVertices.size(), 222u);
  EXPECT_EQ(sc.simulation.stepsPerFrame, 155);
  EXPECT_EQ(sc.simulation.bendEvery, 2);
  EXPECT_EQ(sc.simulation.collisionEvery, 3);
  // Refitted: the sleeves' cuffs rise to the body's wrists (about 0.2-0.3 m up, not 0.14-0.19).
  double highestCuff = -1;
  for (const Vec3& p : sc.garments[0].mesh.positions)
    if (std::abs(p.x()) > 0.39) highestCuff = std::max(highestCuff, p.y());
  EXPECT_GT(highestCuff, 0.25);
  // The jacket's two fronts, modelled overlapping 5 to 16 mm apart, sewn shut: every stitch
  // joins the edges of the fronts, on the body's midline, from the hem up to the breastbone.
  const scene::Garment& dress = sc.garments[0];
  ASSERT_EQ(dress.stitches.size(), 16u);
  for (const auto& [a, b] : dress.stitches) {
    const Vec3 pa = dress.mesh.positions[a], pb = dress.mesh.positions[b];
    EXPECT_LT(std::abs(pa.x()), 0.01) << a;
    EXPECT_LT(std::abs(pb.x()), 0.01) << b;
    EXPECT_GT(std::min(pa.z(), pb.z()), 0.1) << "the front";
    EXPECT_LE((pa - pb).norm(), 0.02);
  }

  const CliResult wrong = runDrape("make-scene '" + kSource + "/data/avatars/CesiumMan.glb' --garment '" + kSource +
                                       "/data/garments/makehuman_female_elegantsuit01_dress.mhclo' --mask '" + kSource +
                                       "/examples/hanging_dress/shoulders_mask.obj' --out '" + (dir / "x") + "'",
                                   dir);
  EXPECT_EQ(wrong.code, 2);
  EXPECT_NE(wrong.err.find("give a .mhskel avatar"), std::string::npos) << wrong.err;

  // A bending rhythm beyond the bending forces' stable step is refused as drape run refuses it.
  const CliResult tooSlow = runDrape(
      makeDressScene("mhclo", "--substeps 155 --bend-every 33 --collides-with Hips,Spine1", dir / "slow"), dir);
  EXPECT_EQ(tooSlow.code, 2) << tooSlow.err;
  EXPECT_NE(tooSlow.err.find("bending every 33 substeps spans 7.1 ms"), std::string::npos) << tooSlow.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "slow/scene.wrl"));

  // Gaps narrower than any opening of the garment find nothing to sew, and say so.
  const CliResult narrow = runDrape(
      makeDressScene("mhclo", "--substeps 155 --collides-with Hips,Spine1 --stitch-gaps 0.001", dir / "narrow"), dir);
  EXPECT_EQ(narrow.code, 2) << narrow.err;
  EXPECT_NE(narrow.err.find("--stitch-gaps 0.001: no two boundary vertices of garment "
                            "'makehuman_female_elegantsuit01_dress' face each other within 0.001 m"),
            std::string::npos)
      << narrow.err;
}

TEST(MakeScene, TooFewSubstepsForTheAddedMassIsAClearError) {
  ScratchDir dir("make-scene-substeps");
  const std::string sceneDir = dir / "dress";
  // make-scene refuses a count that needs more mass than allowed, and names one that does not.
  // Face samples only with parts the garment collides with, said before the substep search.
  const CliResult faces =
      runDrape(makeDressScene("obj", "--collides-with Hips,Spine1 --face-samples-with Hips,LeftUpLeg", sceneDir), dir);
  EXPECT_EQ(faces.code, 2) << faces.err;
  EXPECT_NE(faces.err.find("--face-samples-with: 'LeftUpLeg' is not one of the collidable segments (Hips, Spine1)"),
            std::string::npos)
      << faces.err;
  const CliResult refused = runDrape(makeDressScene("obj", "--substeps 33 --collides-with Hips,Spine1", sceneDir), dir);
  EXPECT_EQ(refused.code, 2) << refused.err;
  EXPECT_NE(refused.err.find("more than --max-added-mass 0.02"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("substeps per frame need no more"), std::string::npos) << refused.err;

  // So does drape run, when a scene allows more than the run does.
  const CliResult made = runDrape(
      makeDressScene("obj", "--substeps 60 --max-added-mass 1 --collides-with Hips,Spine1", sceneDir), dir);
  ASSERT_EQ(made.code, 0) << made.err;
  const CliResult ran = runDrape("run '" + sceneDir + "/scene.wrl' --motion '" + kSource +
                                     "/examples/walking_skirt/walk.bvh' --max-added-mass 0.02 --frames 1 --out '" +
                                     (dir / "out") + "'",
                                 dir);
  EXPECT_EQ(ran.code, 2) << ran.err;
  EXPECT_NE(ran.err.find("substeps per frame"), std::string::npos) << ran.err;
}

}  // namespace
}  // namespace drape
