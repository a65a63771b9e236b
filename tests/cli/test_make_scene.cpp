// `drape make-scene`: the MakeHuman dress on the MakeHuman body becomes a scene that drape
// reads, binds and simulates on the walk; the substeps come from mass scaling.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <utility>

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "drape/formats/obj.hpp"
#include "drape/scene/scene.hpp"
#include "drape/testing/assimp_export.hpp"
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

TEST(MakeScene, AGarmentModelledOnARobotStandingAlongZIsStoodUpWithIt) {
  // A skirt modelled on Choreonoid's SR1 as its file stands it, along +z: make-scene stands
  // the robot up and the skirt with it, so the scene's skirt is make-skirt's (which fits it
  // to the robot standing) and runs out of the body.
  ScratchDir dir("make-scene-robot");
  const std::string robot = kSource + "/data/vrml/choreonoid_SR1.wrl";
  const CliResult skirt = runDrape("make-skirt '" + robot + "' --out '" + (dir / "skirt") + "'", dir);
  ASSERT_EQ(skirt.code, 0) << skirt.err;
  const scene::Scene fitted = scene::loadScene(dir / "skirt/scene.wrl");
  ASSERT_EQ(fitted.garments.size(), 1u);
  // Laid back along +z, as a tool that stands the robot so would have modelled it.
  const auto writeLaid = [&](const std::string& from, const std::string& to) {
    std::ifstream in(from);
    std::ofstream out(to);
    std::string line;
    while (std::getline(in, line)) {
      if (line.rfind("v ", 0) == 0) {
        double x = 0, y = 0, z = 0;
        std::istringstream(line.substr(2)) >> x >> y >> z;
        out << fmt::format("v {:.9g} {:.9g} {:.9g}\n", x, -z, y);
      } else {
        out << line << "\n";
      }
    }
  };
  writeLaid(dir / "skirt/skirt.obj", dir / "laid_skirt.obj");
  writeLaid(dir / "skirt/waistband.obj", dir / "laid_waistband.obj");
  const std::string out = dir / "scene";
  const CliResult made = runDrape("make-scene '" + robot + "' --garment '" + (dir / "laid_skirt.obj") + "' --mask '" +
                                      (dir / "laid_waistband.obj") + "' --name skirt --out '" + out + "'",
                                  dir);
  ASSERT_EQ(made.code, 0) << made.err;
  EXPECT_NE(made.out.find("stands along +z: turned to stand along +y, as drape's scenes do (its Avatar node's rotation "
                          "1 0 0 -1.5708)\n"),
            std::string::npos)
      << made.out;
  const scene::Scene sc = scene::loadScene(out + "/scene.wrl");
  ASSERT_EQ(sc.externalAvatars.size(), 1u);
  EXPECT_LT((sc.externalAvatars[0].placement.rotation * Vec3::UnitZ() - Vec3::UnitY()).norm(), 1e-4);
  ASSERT_EQ(sc.garments.size(), 1u);
  const mesh::TriMesh& a = sc.garments[0].mesh;
  const mesh::TriMesh& b = fitted.garments[0].mesh;
  ASSERT_EQ(a.vertexCount(), b.vertexCount());
  double farthest = 0.0;
  for (std::size_t v = 0; v < a.vertexCount(); ++v) farthest = std::max(farthest, (a.positions[v] - b.positions[v]).norm());
  EXPECT_LT(farthest, 1e-4) << "m, from make-skirt's skirt on the robot standing";
  const CliResult run = runDrape("run '" + out + "/scene.wrl' --motion none --frames 5 --out '" + (dir / "run") + "'", dir);
  ASSERT_EQ(run.code, 0) << run.err;
  const nlohmann::json stats = statsOf(dir / "run");
  EXPECT_EQ(stats["vertex_substeps_inside_body"], 0);
  EXPECT_EQ(stats["nan_detected"], false);
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
  // Pairs the garment held below T2 past their easing time (pairs_embedded_timed_out) are
  // projected onto T2 from as deep as the dress is modelled: read again where each move
  // lands, none ends inside the body.
  EXPECT_GT(stats["pairs_embedded_timed_out"].get<long>(), 0);
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

TEST(MakeScene, AGarmentExportedAsGltfOrColladaMakesTheSceneItsObjMakes) {
  // The dress and its mask as Assimp's exporters write them (in metres, split at the dress's
  // texture seams, the glTF not indexed at all) give the scene the dress's OBJ gives: the
  // same vertices and triangles, the same mask, collidable parts and substeps.
  ScratchDir dir("make-scene-exported");
  const std::string mask = kSource + "/examples/hanging_dress/shoulders_mask.obj";
  const std::string dressObj = std::string(DRAPE_DATA_DIR) + "/garments/makehuman_female_elegantsuit01_dress.obj";
  (void)testing::exportThroughAssimp(dressObj, 0.1, "glb2", dir / "dress.glb");
  (void)testing::exportThroughAssimp(dressObj, 0.1, "collada", dir / "dress.dae");
  (void)testing::exportThroughAssimp(mask, 0.1, "glb2", dir / "mask.glb");
  const std::string avatar = kSource + "/data/avatars/makehuman_rig_cmu_mb.mhskel";
  auto make = [&](const std::string& garment, const std::string& options, const std::string& out) {
    return runDrape("make-scene '" + avatar + "' --garment '" + garment + "' --name dress --offsets "
                    "0.002,0.004,0.006,0.016 " + options + " --out '" + out + "'", dir);
  };
  const CliResult fromObj = make(dressObj, "--units dm --mask '" + mask + "'", dir / "obj");
  ASSERT_EQ(fromObj.code, 0) << fromObj.err;
  const scene::Scene reference = scene::loadScene(dir / "obj/scene.wrl");
  const mesh::TriMesh maskObj = formats::readObj(mask);
  std::vector<bool> used(maskObj.vertexCount(), false);
  for (const mesh::Triangle& t : maskObj.triangles)
    for (std::uint32_t v : t) used[v] = true;
  const auto maskVerticesNoFaceUses = static_cast<std::size_t>(std::count(used.begin(), used.end(), false));
  ASSERT_GT(maskVerticesNoFaceUses, 0u);
  const mesh::TriMesh& want = reference.garments.at(0).mesh;
  for (const std::string& options : {"--garment-parts defaultobject --units dm --mask '" + mask + "'",
                                     "--mask '" + dir / "mask.glb" + "'"})
    for (const char* file : {"dress.glb", "dress.dae"}) {
      SCOPED_TRACE(std::string(file) + " " + options);
      const std::string out = dir / (std::string(file) + std::to_string(options.size()));
      const CliResult made = make(dir / file, options, out);
      ASSERT_EQ(made.code, 0) << made.err;
      EXPECT_NE(made.out.find(dir / file + ": mesh defaultobject (2205 vertices, 4192 triangles; "), std::string::npos)
          << made.out;
      EXPECT_NE(made.out.find("split vertices welded"), std::string::npos) << made.out;
      const scene::Scene sc = scene::loadScene(out + "/scene.wrl");
      const mesh::TriMesh& got = sc.garments.at(0).mesh;
      ASSERT_EQ(got.vertexCount(), want.vertexCount());
      ASSERT_EQ(got.triangleCount(), want.triangleCount());
      std::vector<std::uint32_t> same(got.vertexCount());
      for (std::size_t v = 0; v < got.vertexCount(); ++v) {
        std::size_t best = 0;
        for (std::size_t w = 1; w < want.vertexCount(); ++w)
          if ((want.positions[w] - got.positions[v]).squaredNorm() < (want.positions[best] - got.positions[v]).squaredNorm())
            best = w;
        ASSERT_LT((want.positions[best] - got.positions[v]).norm(), 1e-6) << "vertex " << v;
        same[v] = static_cast<std::uint32_t>(best);
      }
      std::set<std::array<std::uint32_t, 3>> wantTriangles;
      auto rotated = [](std::array<std::uint32_t, 3> t) {
        std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
        return t;
      };
      for (const mesh::Triangle& t : want.triangles) wantTriangles.insert(rotated(t));
      std::size_t matched = 0;
      for (const mesh::Triangle& t : got.triangles) matched += wantTriangles.count(rotated({same[t[0]], same[t[1]], same[t[2]]}));
      EXPECT_EQ(matched, want.triangleCount());
      std::vector<std::uint32_t> maskVertices;
      for (std::uint32_t v : sc.garments[0].maskVertices) maskVertices.push_back(same[v]);
      std::sort(maskVertices.begin(), maskVertices.end());
      if (options.find("mask.glb") == std::string::npos) {
        EXPECT_EQ(maskVertices, reference.garments[0].maskVertices);
      } else {
        // Assimp's OBJ importer leaves out the mask's vertices that no face uses: the
        // exported mask lacks them, and binds all the others.
        EXPECT_TRUE(std::includes(reference.garments[0].maskVertices.begin(), reference.garments[0].maskVertices.end(),
                                  maskVertices.begin(), maskVertices.end()));
        EXPECT_EQ(maskVertices.size() + maskVerticesNoFaceUses, reference.garments[0].maskVertices.size());
      }
      EXPECT_EQ(sc.garments[0].collidesWith, reference.garments[0].collidesWith);
      EXPECT_EQ(sc.simulation.stepsPerFrame, reference.simulation.stepsPerFrame);
    }
  // A part the file does not have, and --units where no file is an OBJ, are refused.
  const CliResult sleeve = make(dir / "dress.glb", "--garment-parts Sleeve --mask '" + dir / "mask.glb" + "'", dir / "sleeve");
  EXPECT_EQ(sleeve.code, 2);
  EXPECT_NE(sleeve.err.find(dir / "dress.glb" + ": has no node or mesh named 'Sleeve' (its meshes: defaultobject)"),
            std::string::npos)
      << sleeve.err;
  const CliResult units = make(dir / "dress.glb", "--units dm --mask '" + dir / "mask.glb" + "'", dir / "units");
  EXPECT_EQ(units.code, 2);
  EXPECT_NE(units.err.find("--units dm: applies to OBJ files; " + dir / "dress.glb" + " and " + dir / "mask.glb" +
                           " state their own unit"),
            std::string::npos)
      << units.err;
}

TEST(MakeScene, InspectSaysWhatAGarmentFileHoldsAsMakeSceneReadsIt) {
  // `drape inspect` of a glTF or Collada file without a skin lists its meshes, the welding
  // and the dress's five openings (hem, waist seam, neckline, two sleeves), in metres.
  ScratchDir dir("inspect-garment-file");
  const std::string dressObj = std::string(DRAPE_DATA_DIR) + "/garments/makehuman_female_elegantsuit01_dress.obj";
  for (const auto& [format, file] : {std::pair{"glb2", "dress.glb"}, std::pair{"collada", "dress.dae"}}) {
    (void)testing::exportThroughAssimp(dressObj, 0.1, format, dir / file);
    const CliResult r = runDrape("inspect '" + dir / file + "'", dir);
    ASSERT_EQ(r.code, 0) << r.err;
    for (const std::string& line :
         {dir / file + ": static mesh, as drape make-scene --garment reads it (m)\n", std::string("  meshes     1 (defaultobject)\n"),
          std::string("  vertices   2205\n  triangles  4192\n"),
          std::string("  bounds     [-0.4467 -0.2992 -0.0967] .. [0.4452 0.5621 0.1902]\n"),
          std::string("  boundary loops 5\n"), "  as an avatar: " + dir / file + ": "})
      EXPECT_NE(r.out.find(line), std::string::npos) << line << "\n" << r.out;
  }
  // A file that is neither: the avatar reader's error.
  std::ofstream(dir / "bad.glb") << "not a model";
  const CliResult bad = runDrape("inspect '" + dir / "bad.glb" + "'", dir);
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find(dir / "bad.glb" + ": not a glTF 2.0 file"), std::string::npos) << bad.err;
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

TEST(MakeScene, BackwardEulerAsksAnEighthOfTheSubstepsAndNoMass) {
  // The walking dress as its README makes it, but implicit: where the explicit steps need
  // about 150 substeps a frame with mass added, an eighth of them, nothing added and bending
  // every substep; it walks out of the body.
  ScratchDir dir("make-scene-implicit");
  const std::string sceneDir = dir / "dress";
  const CliResult made = runDrape(
      "make-scene '" + kSource + "/data/avatars/makehuman_rig_cmu_mb.mhskel' --garment '" + kSource +
          "/data/garments/makehuman_female_elegantsuit01_dress.mhclo' --units dm --mask '" + kSource +
          "/examples/walking_dress/mask.obj' --name dress --offsets 0.002,0.004,0.006,0.016 --collides-with "
          "Hips,LowerBack,Spine,Spine1,Neck,LeftShoulder,RightShoulder,LeftArm,RightArm,LeftForeArm,RightForeArm,"
          "LeftUpLeg,RightUpLeg,LeftLeg,RightLeg --face-samples-with LeftUpLeg,RightUpLeg,LeftLeg,RightLeg "
          "--keep-apart LeftForeArm,RightForeArm,LeftArm,RightArm --cut-at-joints LeftArm,RightArm,LeftUpLeg,RightUpLeg "
          "--stitch-gaps 0.02 --integrator backward-euler --out '" +
          sceneDir + "'",
      dir);
  ASSERT_EQ(made.code, 0) << made.err;
  const scene::Scene sc = scene::loadScene(sceneDir + "/scene.wrl");
  EXPECT_EQ(sc.simulation.integrator, "backward-euler");
  EXPECT_EQ(sc.simulation.maxAddedMass, 0.0);
  EXPECT_EQ(sc.simulation.bendEvery, 1);
  EXPECT_NEAR(sc.simulation.implicitTolerance, 1e-3, 1e-9);
  EXPECT_GE(sc.simulation.stepsPerFrame, 15);
  EXPECT_LE(sc.simulation.stepsPerFrame, 25);
  EXPECT_NE(made.out.find(std::to_string(sc.simulation.stepsPerFrame) +
                          " substeps per frame at 30 frames/s, each a backward-Euler solve (the explicit steps would "
                          "take "),
            std::string::npos)
      << made.out;
  const std::string out = dir / "out";
  const CliResult ran = runDrape("run '" + sceneDir + "/scene.wrl' --motion '" + kSource +
                                     "/examples/walking_skirt/walk.bvh' --frames 15 --out '" + out + "'",
                                 dir);
  ASSERT_EQ(ran.code, 0) << ran.err;
  EXPECT_EQ(ran.err.find("fewer run faster"), std::string::npos) << ran.err;
  const nlohmann::json stats = statsOf(out);
  EXPECT_EQ(stats["integrator"], "backward-euler");
  EXPECT_EQ(stats["vertex_substeps_inside_body"].get<long>(), 0);
  const nlohmann::json& g = stats["garments"][0];
  EXPECT_EQ(g["added_mass_kg"].get<double>(), 0.0);
  EXPECT_EQ(g["implicit_solves"]["unconverged"].get<long>(), 0);
  // drape inspect says how many of the vertex-substeps below T1 were pinched between parts.
  const long belowT1 = stats["vertex_substeps_below_T1"].get<long>();
  const long pinched = stats["vertex_substeps_below_T1_pinched"].get<long>();
  ASSERT_GT(belowT1, 0);
  EXPECT_LE(pinched, belowT1);
  const CliResult inspected = runDrape("inspect '" + out + "'", dir);
  ASSERT_EQ(inspected.code, 0) << inspected.err;
  EXPECT_NE(inspected.out.find(fmt::format("below T1 {} ({} pinched between parts)", belowT1, pinched)),
            std::string::npos)
      << inspected.out;

  // A bending rhythm cannot go with it; a name that is not an integrator is refused.
  const CliResult rhythm =
      runDrape(makeDressScene("obj", "--integrator backward-euler --bend-every 2", dir / "rhythm"), dir);
  EXPECT_EQ(rhythm.code, 2) << rhythm.err;
  EXPECT_NE(rhythm.err.find("--bend-every 2: backward Euler takes bending into its solve every substep"),
            std::string::npos)
      << rhythm.err;
  const CliResult rungeKuttaRhythm =
      runDrape(makeDressScene("obj", "--integrator runge-kutta-4 --bend-every 2", dir / "rk-rhythm"), dir);
  EXPECT_EQ(rungeKuttaRhythm.code, 2) << rungeKuttaRhythm.err;
  EXPECT_NE(rungeKuttaRhythm.err.find("--bend-every 2: the runge-kutta-4 step takes bending into each of its stages"),
            std::string::npos)
      << rungeKuttaRhythm.err;
  // The Runge-Kutta step on the dress, damped as make-scene's material is: its own bound on
  // the unscaled membrane asks fewer substeps than symplectic Euler's count with mass added,
  // and those are written, with no mass added.
  const CliResult rungeKutta = runDrape(makeDressScene("obj", "--integrator runge-kutta-4", dir / "rk"), dir);
  ASSERT_EQ(rungeKutta.code, 0) << rungeKutta.err;
  const scene::Scene rk = scene::loadScene(dir / "rk" + "/scene.wrl");
  EXPECT_EQ(rk.simulation.integrator, "runge-kutta-4");
  EXPECT_EQ(rk.simulation.bendEvery, 1);
  EXPECT_EQ(rk.simulation.maxAddedMass, 0.0);
  const std::string head = std::to_string(rk.simulation.stepsPerFrame) +
                           " substeps per frame at 30 frames/s, each a fourth-order Runge-Kutta step, no mass added "
                           "(symplectic Euler would take ";
  const std::size_t at = rungeKutta.out.find(head);
  ASSERT_NE(at, std::string::npos) << rungeKutta.out;
  EXPECT_LT(rk.simulation.stepsPerFrame, std::stoi(rungeKutta.out.substr(at + head.size()))) << rungeKutta.out;
  // With more mass allowed, scaling aimed at the Runge-Kutta step's own bound (its elements
  // for a step sqrt(2) shorter) asks fewer still, about 1 / sqrt(2) of symplectic Euler's
  // count within the same allowance.
  const CliResult scaled =
      runDrape(makeDressScene("obj", "--integrator runge-kutta-4 --max-added-mass 0.1", dir / "rk-scaled"), dir);
  ASSERT_EQ(scaled.code, 0) << scaled.err;
  const scene::Scene rkScaled = scene::loadScene(dir / "rk-scaled" + "/scene.wrl");
  EXPECT_FLOAT_EQ(rkScaled.simulation.maxAddedMass, 0.1);
  EXPECT_LT(rkScaled.simulation.stepsPerFrame, rk.simulation.stepsPerFrame);
  const std::string scaledHead = std::to_string(rkScaled.simulation.stepsPerFrame) +
                                 " substeps per frame at 30 frames/s, each a fourth-order Runge-Kutta step (mass "
                                 "scaling adds ";
  const std::size_t scaledAt = scaled.out.find(scaledHead);
  ASSERT_NE(scaledAt, std::string::npos) << scaled.out;
  const double addedPercent = std::stod(scaled.out.substr(scaledAt + scaledHead.size()));
  EXPECT_GT(addedPercent, 0.0);
  EXPECT_LE(addedPercent, 10.0);
  const std::string symplecticHead = "% of the mass; symplectic Euler would take ";
  const std::size_t symplecticAt = scaled.out.find(symplecticHead, scaledAt);
  ASSERT_NE(symplecticAt, std::string::npos) << scaled.out;
  const int symplecticCount = std::stoi(scaled.out.substr(symplecticAt + symplecticHead.size()));
  EXPECT_NEAR(rkScaled.simulation.stepsPerFrame, symplecticCount / std::sqrt(2.0), 0.05 * symplecticCount)
      << scaled.out;
  const CliResult unknown = runDrape(makeDressScene("obj", "--integrator implicit", dir / "unknown"), dir);
  EXPECT_NE(unknown.code, 0);
  EXPECT_NE(unknown.err.find(
                "--integrator must be symplectic-euler, forward-euler, backward-euler or runge-kutta-4, got 'implicit'"),
            std::string::npos)
      << unknown.err;
}

}  // namespace
}  // namespace drape
