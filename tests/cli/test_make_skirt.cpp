// `drape make-skirt` end to end: a skirt fitted to the bundled MakeHuman body, to another
// rig's avatar, whose segments it names itself, and to a small glTF character; the scenes it
// writes load and run, the glTF character's on its own walk, read from the glTF file or
// from the Collada and FBX files `drape convert` writes of it.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/pc2.hpp"
#include "drape/scene/scene.hpp"

namespace drape {
namespace {

using testing::CliResult;
using testing::runDrape;
using testing::ScratchDir;
using testing::statsOf;

const std::string kAvatars = std::string(DRAPE_DATA_DIR) + "/avatars";

/// `drape run SCENE` for `frames` frames of the bundled walk, into DIR/walk; the run's
/// result (its stats.json in DIR/walk).
CliResult walk(const ScratchDir& dir, const std::string& scene, int frames) {
  return runDrape("run '" + scene + "' --motion '" + std::string(DRAPE_SOURCE_DIR) +
                      "/examples/walking_skirt/walk.bvh' --frames " + std::to_string(frames) + " --out '" +
                      (dir / "walk") + "'",
                  dir);
}

/// Runs the scene `dir/scene.wrl` for a few frames (the avatar stands, whatever animation
/// its file carries) and checks the skirt stayed out of the body.
void runsClean(const ScratchDir& scratch, const std::string& dir) {
  const std::string out = dir + "-run";
  const CliResult r = runDrape("run '" + dir + "/scene.wrl' --motion none --frames 5 --out '" + out + "'", scratch);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json stats = statsOf(out);
  EXPECT_EQ(stats["frames"], 5);
  EXPECT_EQ(stats["vertex_substeps_inside_body"], 0);
}

/// CesiumMan's skirt (his glTF names his segments joint0, joint1, ..., and make-skirt finds
/// his lower body by his skeleton's shape), in `dir`/skirt; ""
/// (with the failure recorded) if make-skirt fails.
std::string makeCesiumSkirt(const ScratchDir& dir) {
  const std::string out = dir / "skirt";
  const CliResult r = runDrape("make-skirt '" + kAvatars + "/CesiumMan.glb' --out '" + out + "'", dir);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("found by the skeleton's shape: waist joint1; hips joint0; legs joint11, joint12, joint13, "
                       "joint14\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("run it: drape run " + out + "/scene.wrl (the avatar plays its own file's animation 'animation "
                       "0'; --motion FILE plays another)\n"),
            std::string::npos)
      << r.out;
  return r.code == 0 ? out : "";
}

TEST(MakeSkirt, FitsTheMakeHumanBodyWithItsDefaultSegments) {
  ScratchDir dir("make-skirt-makehuman");
  const std::string out = dir / "skirt";
  const CliResult r = runDrape("make-skirt '" + kAvatars + "/makehuman_rig_cmu_mb.mhskel' --out '" + out + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("run it: drape run " + out + "/scene.wrl --motion FILE (a BVH or AMC capture, or an animated "
                       "avatar file; without it the avatar stands at rest)\n"),
            std::string::npos)
      << r.out;
  const scene::Scene sc = scene::loadScene(out + "/scene.wrl");
  ASSERT_EQ(sc.garments.size(), 1u);
  EXPECT_EQ(sc.garments[0].mesh.triangleCount(), 480u);
  EXPECT_EQ(sc.garments[0].collidesWith,
            (std::vector<std::string>{"LowerBack", "Hips", "LeftUpLeg", "RightUpLeg", "LeftLeg", "RightLeg"}));
  runsClean(dir, out);
}

TEST(MakeSkirt, AWideSkirtsWaistbandIsBoundWhereItSits) {
  // A wide clearance sets the waistband farther from the body than the usual 4 cm bind
  // threshold: the scene's threshold reaches it, and the skirt binds and runs.
  ScratchDir dir("make-skirt-wide");
  const std::string out = dir / "skirt";
  const CliResult r = runDrape("make-skirt '" + kAvatars + "/makehuman_rig_cmu_mb.mhskel' --clearance 0.05 --flare 0.3 " +
                                   "--out '" + out + "'",
                               dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const scene::Scene sc = scene::loadScene(out + "/scene.wrl");
  ASSERT_EQ(sc.garments.size(), 1u);
  EXPECT_GT(sc.garments[0].bindThreshold, 0.045);
  EXPECT_LT(sc.garments[0].bindThreshold, 0.07);
  runsClean(dir, out);
  // Given, it is written as given.
  const CliResult given = runDrape("make-skirt '" + kAvatars + "/makehuman_rig_cmu_mb.mhskel' --clearance 0.05 " +
                                       "--flare 0.3 --bind-threshold 0.04 --out '" + (dir / "given") + "'",
                                   dir);
  ASSERT_EQ(given.code, 0) << given.err;
  EXPECT_NEAR(scene::loadScene(dir / "given/scene.wrl").garments[0].bindThreshold, 0.04, 1e-7);  // SFFloat
}

TEST(MakeSkirt, AnotherRigsLowerBodyIsFoundByItsShape) {
  // MakeHuman's game-engine rig names its segments as game engines do: without the CMU
  // rig's names, make-skirt finds the waist, hips and legs by the skeleton's shape, and
  // fits the same skirt to the same body (within the 1.5 cm its other segments' outlines
  // make). Segments named on the command line win, and a wrong name is refused.
  ScratchDir dir("make-skirt-game-engine");
  const std::string avatar = "'" + kAvatars + "/makehuman_rig_game_engine.mhskel'";
  const std::string out = dir / "skirt";
  const CliResult found = runDrape("make-skirt " + avatar + " --out '" + out + "'", dir);
  ASSERT_EQ(found.code, 0) << found.err;
  EXPECT_NE(found.out.find("found by the skeleton's shape: waist spine_01; hips pelvis; legs thigh_l, thigh_r, calf_l, "
                           "calf_r\n"),
            std::string::npos)
      << found.out;
  const scene::Scene sc = scene::loadScene(out + "/scene.wrl");
  ASSERT_EQ(sc.garments.size(), 1u);
  EXPECT_EQ(sc.garments[0].collidesWith,
            (std::vector<std::string>{"spine_01", "pelvis", "thigh_l", "thigh_r", "calf_l", "calf_r"}));
  const CliResult cmu = runDrape("make-skirt '" + kAvatars + "/makehuman_rig_cmu_mb.mhskel' --out '" + (dir / "cmu") + "'", dir);
  ASSERT_EQ(cmu.code, 0) << cmu.err;
  EXPECT_EQ(cmu.out.find("found by the skeleton's shape"), std::string::npos) << cmu.out;
  const mesh::TriMesh onCmu = scene::loadScene(dir / "cmu/scene.wrl").garments[0].mesh;
  ASSERT_EQ(onCmu.vertexCount(), sc.garments[0].mesh.vertexCount());
  double farthest = 0;
  for (std::size_t v = 0; v < onCmu.vertexCount(); ++v)
    farthest = std::max(farthest, (onCmu.positions[v] - sc.garments[0].mesh.positions[v]).norm());
  EXPECT_LT(farthest, 0.025);
  runsClean(dir, out);

  const CliResult wrongLeg = runDrape("make-skirt " + avatar + " --leg-segments thigh_l,knee_l --out '" +
                                          (dir / "wrong") + "'",
                                      dir);
  EXPECT_EQ(wrongLeg.code, 2);
  EXPECT_NE(wrongLeg.err.find("no segment 'knee_l'; name one of its own with --leg-segments"), std::string::npos)
      << wrongLeg.err;
  const CliResult given = runDrape("make-skirt " + avatar + " --hip-segments pelvis,thigh_l,thigh_r --leg-segments " +
                                       "calf_l,calf_r --out '" + (dir / "given") + "'",
                                   dir);
  ASSERT_EQ(given.code, 0) << given.err;
  EXPECT_EQ(scene::loadScene(dir / "given/scene.wrl").garments[0].collidesWith,
            (std::vector<std::string>{"spine_01", "pelvis", "thigh_l", "thigh_r", "calf_l", "calf_r"}));

  // A skeleton with no legs to find: refused, naming what to give.
  const CliResult simple = runDrape("make-skirt '" + kAvatars + "/RiggedSimple.glb' --out '" + (dir / "simple") + "'", dir);
  EXPECT_EQ(simple.code, 2);
  EXPECT_NE(simple.err.find("its lower body cannot be found by the skeleton's shape: 2 joints are too few for legs, a "
                            "spine and arms; name its own with --waist-segment, --hip-segments and --leg-segments (it "
                            "has: joint0, joint1)"),
            std::string::npos)
      << simple.err;
}

TEST(MakeSkirt, ASmallRobotsSkirtCollidesAtItsScaleAndWalksStable) {
  // Choreonoid's GR001 is 0.26 m tall, its parts a few centimetres across: a person's
  // offsets (T3 = 3 cm) overlapped each other around them, and its skirt went unstable at
  // rest. make-skirt scales the voxel, offsets and clearance with its height; its waistband then lies
  // beyond the parts' fields (they reach T3 = 4.5 mm) and is bound by the parts' surfaces,
  // within the scene's 4 cm bindThreshold.
  ScratchDir dir("make-skirt-small-robot");
  const std::string out = dir / "robot";
  const CliResult r = runDrape("make-skirt '" + std::string(DRAPE_DATA_DIR) + "/vrml/choreonoid_GR001/GR001.wrl' --out '" +
                                   out + "'",
                               dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("GR001.wrl is 0.26 m tall: distance-field voxel 0.75 mm, offsets T0..T3 0.75 to 4.50 mm (a "
                       "person's: 5 mm, 5 to 30 mm); clearance 3.0 mm (a person's: 20 mm)\n"),
            std::string::npos)
      << r.out;
  const std::string text = testing::slurp(out + "/scene.wrl");
  EXPECT_NE(text.find("  offsets [ 0.00075 0.00150 0.00225 0.00450 ]\n  voxelSize 0.00075\n"), std::string::npos);
  const scene::Scene sc = scene::loadScene(out + "/scene.wrl");
  ASSERT_EQ(sc.garments.size(), 1u);
  EXPECT_NEAR(sc.garments[0].bindThreshold, 0.04, 1e-7);
  const std::string run = dir / "walk";
  const CliResult walked = walk(dir, out + "/scene.wrl", 40);
  ASSERT_EQ(walked.code, 0) << walked.err;
  EXPECT_EQ(walked.err.find("warning"), std::string::npos) << walked.err;
  const nlohmann::json stats = statsOf(run);
  EXPECT_EQ(stats["nan_detected"], false);
  EXPECT_EQ(stats["unstable"], false);
  EXPECT_EQ(stats["last_resort_projections"], 0);
  EXPECT_EQ(stats["vertex_substeps_inside_body"], 0);
  EXPECT_LT(stats["max_stretch"].get<double>(), 0.15);  // with a person's offsets: 0.50, strain-limited
  // make-scene alike, with the skirt as modelled on the robot's file (lying along +z: the
  // quarter turn that stood it up undone), unless --voxel is given.
  for (const char* name : {"skirt", "waistband"}) {
    mesh::TriMesh m = formats::readObj(out + "/" + name + ".obj");
    for (Vec3& p : m.positions) p = Vec3(p.x(), -p.z(), p.y());
    formats::writeObj(dir / (std::string(name) + "-lying.obj"), m.positions, m.triangles);
  }
  const std::string dress = "make-scene '" + std::string(DRAPE_DATA_DIR) + "/vrml/choreonoid_GR001/GR001.wrl' --garment '" +
                            (dir / "skirt-lying.obj") + "' --mask '" + (dir / "waistband-lying.obj") + "' --out '";
  const CliResult scened = runDrape(dress + (dir / "scened") + "'", dir);
  ASSERT_EQ(scened.code, 0) << scened.err;
  EXPECT_NE(scened.out.find("GR001.wrl is 0.26 m tall: distance-field voxel 0.75 mm"), std::string::npos) << scened.out;
  EXPECT_NE(testing::slurp(dir / "scened/scene.wrl").find("  offsets [ 0.00075 0.0015 0.00225 0.0045 ]\n  voxelSize 0.00075\n"),
            std::string::npos);
  const CliResult given = runDrape(dress + (dir / "given") + "' --voxel 0.002", dir);
  ASSERT_EQ(given.code, 0) << given.err;
  EXPECT_EQ(given.out.find("tall: distance-field voxel"), std::string::npos) << given.out;
  EXPECT_NE(testing::slurp(dir / "given/scene.wrl").find("  voxelSize 0.002\n"), std::string::npos);
  // A person's size keeps a person's voxel.
  const CliResult person =
      runDrape("make-skirt '" + kAvatars + "/makehuman_rig_cmu_mb.mhskel' --out '" + (dir / "person") + "'", dir);
  ASSERT_EQ(person.code, 0) << person.err;
  EXPECT_EQ(person.out.find("tall: distance-field voxel"), std::string::npos) << person.out;
  EXPECT_NE(testing::slurp(dir / "person/scene.wrl").find("  offsets [ 0.005 0.010 0.015 0.030 ]\n  voxelSize 0.005\n"),
            std::string::npos);
}

TEST(MakeSkirt, ASecondSkirtOnASmallRobotIsScaledAsItsFirst) {
  // make-skirt --add-to on GR001 (0.26 m) scales the new skirt's clearance and its gap over
  // the skirt under it, as a new scene's are; the scene's voxel and offsets are its own, and
  // a scene whose voxel is too coarse for so small a character is warned of. Both skirts then
  // walk with no warning, through the lead-in and 10 frames of the walk (before, adding
  // failed: the check of the layers at the start measured the skirt under it with its
  // waistband free, where a run holds it).
  ScratchDir dir("make-skirt-small-second");
  const std::string gr001 = "'" + std::string(DRAPE_DATA_DIR) + "/vrml/choreonoid_GR001/GR001.wrl'";
  const CliResult first = runDrape("make-skirt " + gr001 + " --out '" + (dir / "robot") + "'", dir);
  ASSERT_EQ(first.code, 0) << first.err;
  const std::string scene = dir / "robot/scene.wrl";
  const CliResult second = runDrape("make-skirt --add-to '" + scene + "' --name Over --over Skirt", dir);
  ASSERT_EQ(second.code, 0) << second.err;
  EXPECT_NE(second.out.find("Body is 0.26 m tall: clearance 3.0 mm (a person's: 20 mm), 0.60 mm above Skirt (a person's: "
                            "4 mm)\n"),
            std::string::npos)
      << second.out;
  EXPECT_EQ(second.err.find("warning"), std::string::npos) << second.err;
  const scene::Scene sc = scene::loadScene(scene);
  ASSERT_EQ(sc.garments.size(), 2u);
  EXPECT_NEAR(sc.garments[1].overGap, 0.0006, 1e-9);
  EXPECT_NEAR(sc.simulation.voxelSize, 0.00075, 1e-9);
  const std::string run = dir / "walk";
  const CliResult walked = walk(dir, scene, 40);
  ASSERT_EQ(walked.code, 0) << walked.err;
  EXPECT_EQ(walked.err.find("warning"), std::string::npos) << walked.err;
  EXPECT_EQ(statsOf(run)["vertex_substeps_inside_body"], 0);
  // --clearance and --over-gap given are kept, and said nowhere. (This third skirt, 8 mm out
  // from the second, was refused as lying under it: the side a garment below is worn on was
  // told by the nearest vertex of the body, and the robot's boxes have eight; the body's
  // points now lie on its triangles too, sim::restBodyPoints.)
  const CliResult given =
      runDrape("make-skirt --add-to '" + scene + "' --name Third --over Over --clearance 0.012 --over-gap 0.001", dir);
  ASSERT_EQ(given.code, 0) << given.err;
  EXPECT_EQ(given.out.find("m tall:"), std::string::npos) << given.out;
  EXPECT_EQ(given.out.find("lie under"), std::string::npos) << given.out;
  EXPECT_NEAR(scene::loadScene(scene).garments[2].overGap, 0.001, 1e-9);

  // A scene on the robot with a person's voxel (written by hand, or with make-scene --voxel):
  // the new skirt is added, with a warning naming the voxel it would need.
  std::string coarse = testing::slurp(dir / "robot/scene.wrl");
  const std::string fine = "  offsets [ 0.00075 0.00150 0.00225 0.00450 ]\n  voxelSize 0.00075\n";
  const std::size_t at = coarse.find(fine);
  ASSERT_NE(at, std::string::npos);
  coarse.replace(at, fine.size(), "  offsets [ 0.005 0.010 0.015 0.030 ]\n  voxelSize 0.005\n");
  std::ofstream(dir / "robot/coarse.wrl") << coarse;
  const CliResult warned = runDrape("make-skirt --add-to '" + (dir / "robot/coarse.wrl") + "' --name Fourth", dir);
  ASSERT_EQ(warned.code, 0) << warned.err;
  EXPECT_NE(warned.err.find("robot/coarse.wrl: the scene's distance-field voxel is 5.00 mm, for a character 0.26 m tall; "
                            "0.75 mm (offsets T0..T3 0.75 to 4.50 mm) keeps the offset surfaces of its small parts apart"),
            std::string::npos)
      << warned.err;
}

TEST(MakeSkirt, ARobotStandingAlongZIsStoodUpDressedAndWalked) {
  // Choreonoid's SR1 robot stands along +z, as robotics tools stand everything, and has no
  // head. make-skirt stands it up (the scene's Avatar node turns it), finds its lower body
  // by its shape, and the CMU walk moves it through a joint map by shape, the skirt hanging
  // down along -y and out of the body.
  ScratchDir dir("make-skirt-robot");
  const std::string robot = "'" + std::string(DRAPE_DATA_DIR) + "/vrml/choreonoid_SR1.wrl'";
  const std::string out = dir / "robot";
  const CliResult r = runDrape("make-skirt " + robot + " --out '" + out + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("stands along +z: turned to stand along +y, as drape's scenes do (its Avatar node's rotation 1 0 "
                       "0 -1.5708)\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("found by the skeleton's shape: waist WAIST_LINK1; hips WAIST_LINK0; legs LLEG_LINK1, LLEG_LINK2, "
                       "RLEG_LINK1, RLEG_LINK2, LLEG_LINK3, LLEG_LINK4, RLEG_LINK3, RLEG_LINK4\n"),
            std::string::npos)
      << r.out;
  // Its header's run hint names no walk.bvh it does not have beside it.
  EXPECT_NE(testing::slurp(out + "/scene.wrl").find("--motion CAPTURE.bvh --out out/skirt\n"), std::string::npos);
  const scene::Scene sc = scene::loadScene(out + "/scene.wrl");
  ASSERT_EQ(sc.externalAvatars.size(), 1u);
  EXPECT_LT((sc.externalAvatars[0].placement.rotation * Vec3::UnitZ() - Vec3::UnitY()).norm(), 1e-4);
  ASSERT_EQ(sc.garments.size(), 1u);
  const Aabb rest = sc.garments[0].mesh.bounds();
  EXPECT_NEAR(rest.max.y(), 0.89, 0.005);  // at the waist joint, 0.89 m up the robot's z

  const std::string run = dir / "walk";
  const CliResult walked = walk(dir, out + "/scene.wrl", 40);
  ASSERT_EQ(walked.code, 0) << walked.err;
  EXPECT_NE(walked.err.find("joint map 'by shape' drives 26 of the avatar's 30 joints"), std::string::npos) << walked.err;
  const nlohmann::json stats = statsOf(run);
  EXPECT_EQ(stats["frames"], 40);
  EXPECT_EQ(stats["nan_detected"], false);
  EXPECT_EQ(stats["vertex_substeps_inside_body"], 0);
  // The skirt hangs from the waist: in the last frame no vertex has risen above it or
  // fallen below the hem by more than the walk's bounce and sway.
  const formats::Pc2Cache cache = formats::readPc2(run + "/garment.pc2");
  ASSERT_EQ(cache.frames.size(), 41u);
  for (const Vec3& p : cache.frames.back()) {
    EXPECT_LT(p.y(), rest.max.y() + 0.1);
    EXPECT_GT(p.y(), rest.min.y() - 0.1);
  }

  // The same scene without the Avatar node's rotation: the run warns that the robot lies
  // across gravity, with the rotation that stands it up.
  std::string text = testing::slurp(out + "/scene.wrl");
  testing::replaceOnce(text, "  rotation 1 0 0 -1.5708\n", "");
  std::ofstream(out + "/lying.wrl") << text;
  const CliResult across =
      runDrape("run '" + out + "/lying.wrl' --motion none --frames 1 --out '" + (dir / "across") + "'", dir);
  // (The skirt, fitted to the robot standing, then cannot bind to it: the warning comes first.)
  EXPECT_NE(across.err.find("character 'Body' stands along +z, where gravity pulls along -y: its garments would fall "
                            "across it; give its Avatar node (or a Transform around its Humanoid) rotation 1 0 0 -1.5708 "
                            "to stand it up"),
            std::string::npos)
      << across.err;
  EXPECT_EQ(walked.err.find("where gravity pulls along -y"), std::string::npos) << walked.err;

  // Placed lying in a scene, as its file stands it: --add-to says how to stand it up.
  const std::string lying = dir / "lying.wrl";
  {
    std::ofstream f(lying);
    f << "#VRML V2.0 utf8\nDEF Robot Avatar { url \"" << DRAPE_DATA_DIR
      << "/vrml/choreonoid_SR1.wrl\" }\n";
  }
  const CliResult added = runDrape("make-skirt --add-to '" + lying + "'", dir);
  EXPECT_EQ(added.code, 2);
  EXPECT_NE(added.err.find("--add-to " + lying + ": character 'Robot' stands along +z, not along +y as drape's scenes "
                           "do, and a garment would fall across it; give its Avatar node (or a Transform around its "
                           "Humanoid) rotation 1 0 0 -1.5708 to stand it up, then dress it"),
            std::string::npos)
      << added.err;
  EXPECT_EQ(added.err.find("warning"), std::string::npos) << "said once, as the error: " << added.err;
  // make-scene --add-to refuses it alike, before it reads the garment.
  const CliResult addedScene = runDrape("make-scene --add-to '" + lying + "' --garment '" + out + "/skirt.obj' --mask '" +
                                            out + "/waistband.obj'",
                                        dir);
  EXPECT_EQ(addedScene.code, 2);
  EXPECT_NE(addedScene.err.find("--add-to " + lying + ": character 'Robot' stands along +z"), std::string::npos)
      << addedScene.err;
}

/// Of `drape inspect RUN --deepest N`'s rows, those of free vertices (not bound) whose
/// deepest point lies inside the skin of a forearm, hand or finger.
int freeVerticesInsideTheArms(const std::string& inspected) {
  int count = 0;
  std::istringstream rows(inspected.substr(inspected.find("garment         vertex")));
  std::string row;
  std::getline(rows, row);  // the header
  while (std::getline(rows, row) && row.rfind("Skirt", 0) == 0) {
    std::istringstream words(row);
    std::vector<std::string> w{std::istream_iterator<std::string>(words), std::istream_iterator<std::string>()};
    // garment, vertex, frame, time code, the state's words, the depth in the skin, its part, ...
    std::size_t depth = 4;
    while (depth < w.size() && w[depth].find_first_not_of("+-.0123456789") != std::string::npos) ++depth;
    if (depth + 1 >= w.size() || w[4] == "bound" || std::stod(w[depth]) >= 0) continue;
    const std::string& part = w[depth + 1];
    for (const char* arm : {"ForeArm", "Hand", "Finger", "Thumb"})
      if (part.find(arm) != std::string::npos) {
        ++count;
        break;
      }
  }
  return count;
}

TEST(MakeSkirt, WithArmsTheSwingingHandsPushTheSkirtInsteadOfSinkingIn) {
  // The paper's part list (hips, thighs, shins) lets the walker's right hand and forearm
  // sink into the skirt's flare: `drape inspect --deepest` finds free skirt vertices inside
  // them. With --with-arms the forearms, hands and fingers (found by shape) collide too, and
  // none is left inside them; nothing enters the body. The scene keeps the upper arms and
  // forearms out of the body (keepApart): the walk swings the right forearm 26 mm into the
  // hips, through the waistband, whose bound vertices cannot give way (313 vertex-substeps
  // inside it without).
  ScratchDir dir("make-skirt-arms");
  const std::string body = "'" + kAvatars + "/makehuman_rig_cmu_mb.mhskel'";
  const std::string walk = "'" + std::string(DRAPE_SOURCE_DIR) + "/examples/walking_skirt/walk.bvh'";
  const CliResult plain = runDrape("make-skirt " + body + " --out '" + (dir / "plain") + "'", dir);
  ASSERT_EQ(plain.code, 0) << plain.err;
  const CliResult arms = runDrape("make-skirt " + body + " --with-arms --out '" + (dir / "arms") + "'", dir);
  ASSERT_EQ(arms.code, 0) << arms.err;
  EXPECT_NE(arms.out.find("collides with the forearms and hands too: LeftForeArm, LeftHand, LThumb, LeftFingerBase, "
                          "LeftHandFinger1, RightForeArm, RightHand, RThumb, RightFingerBase, RightHandFinger1\n"),
            std::string::npos)
      << arms.out;
  EXPECT_EQ(scene::loadScene(dir / "arms/scene.wrl").garments[0].collidesWith.size(), 16u);
  EXPECT_NE(arms.out.find("keeps the arms out of the body as they swing (the scene's keepApart): LeftArm, "
                          "LeftForeArm, RightArm, RightForeArm\n"),
            std::string::npos)
      << arms.out;
  EXPECT_EQ(scene::loadScene(dir / "arms/scene.wrl").simulation.keepApart,
            (std::vector<std::string>{"LeftArm", "LeftForeArm", "RightArm", "RightForeArm"}));
  EXPECT_TRUE(scene::loadScene(dir / "plain/scene.wrl").simulation.keepApart.empty());
  std::array<int, 2> inside{};
  for (std::size_t k = 0; k < 2; ++k) {
    const std::string name = k == 0 ? "plain" : "arms";
    const std::string run = dir / (name + "-run");
    const CliResult r = runDrape("run '" + (dir / name) + "/scene.wrl' --motion " + walk + " --frames 110 --out '" +
                                     run + "'",
                                 dir);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(statsOf(run)["vertex_substeps_inside_body"], 0) << name;
    const CliResult deepest = runDrape("inspect '" + run + "' --deepest 40", dir);
    ASSERT_EQ(deepest.code, 0) << deepest.err;
    inside[k] = freeVerticesInsideTheArms(deepest.out);
    std::printf("%s: %d free skirt vertices deepest inside a forearm or hand\n", name.c_str(), inside[k]);
  }
  EXPECT_GT(inside[0], 0);
  EXPECT_EQ(inside[1], 0);

  // Added to a scene (--add-to), the skirt keeps the scene's Simulation: where it keeps no
  // arms apart, the command warns and says which to add.
  const std::string plainScene = dir / "plain/scene.wrl";
  const CliResult added =
      runDrape("make-skirt --add-to '" + plainScene + "' --name Over --over Skirt --with-arms", dir);
  EXPECT_EQ(added.code, 0) << added.err;
  EXPECT_NE(added.err.find(plainScene + " keeps no parts out of the body; a walk swings the arms into the hips, "
                           "through the waistband, which cannot give way: add LeftArm, LeftForeArm, RightArm, "
                           "RightForeArm to its Simulation node's keepApart, or run it with --keep-apart "
                           "LeftArm,LeftForeArm,RightArm,RightForeArm\n"),
            std::string::npos)
      << added.err;
  const CliResult again = runDrape("make-skirt --add-to '" + (dir / "arms/scene.wrl") + "' --name Over --over Skirt "
                                   "--with-arms",
                                   dir);
  EXPECT_EQ(again.code, 0) << again.err;
  EXPECT_EQ(again.err.find("keepApart"), std::string::npos) << again.err;
}

TEST(MakeSkirt, ASmallCharactersSkirtGetsTheSubstepsItNeeds) {
  // CesiumMan (glTF, 1.5 m): its skirt's triangles are smaller and stiffer than the paper's,
  // and the knit's damping would make 33 substeps per frame unstable, which drape run
  // refuses; the scene asks for as many as it needs.
  ScratchDir dir("make-skirt-cesium");
  const std::string out = dir / "skirt";
  const CliResult made = runDrape("make-skirt '" + kAvatars + "/CesiumMan.glb' --waist-segment joint1 " +
                                      "--hip-segments joint0 --leg-segments joint11,joint12,joint13,joint14 --out '" +
                                      out + "'",
                                  dir);
  ASSERT_EQ(made.code, 0) << made.err;
  const scene::Scene sc = scene::loadScene(out + "/scene.wrl");
  EXPECT_GT(sc.simulation.stepsPerFrame, 33);
  EXPECT_NE(made.out.find(std::to_string(sc.simulation.stepsPerFrame) + " substeps per frame"), std::string::npos)
      << made.out;
  runsClean(dir, out);
}

TEST(MakeSkirt, CesiumMansSkirtWalksOnItsOwnAnimation) {
  // The glTF file's own walk drives the avatar it was loaded from: no joint map, no
  // retargeting; 1 s of lead-in and the 2 s walk (61 frames at 30 Hz).
  ScratchDir dir("make-skirt-cesium-walk");
  const std::string cesium = kAvatars + "/CesiumMan.glb";
  const std::string out = makeCesiumSkirt(dir);
  ASSERT_FALSE(out.empty());
  const std::string run = dir / "walk";
  const CliResult r = runDrape("run '" + out + "/scene.wrl' --motion '" + cesium + "' --out '" + run + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("61 frames at 30 Hz in m (glTF); joint map 'its own skin's joints (animation 0)' drives 19 "
                       "of the avatar's 19 joints"),
            std::string::npos)
      << r.err;
  const nlohmann::json stats = statsOf(run);
  EXPECT_EQ(stats["frames"], 90);
  EXPECT_EQ(stats["vertex_substeps_inside_body"], 0);

  // Without --motion the avatar plays its own file's walk, as a glTF viewer would, and says
  // so (as `drape inspect` of the scene does): the same run to the byte. --motion none keeps
  // it at rest.
  const CliResult inspected = runDrape("inspect '" + out + "/scene.wrl'", dir);
  ASSERT_EQ(inspected.code, 0) << inspected.err;
  EXPECT_NE(inspected.out.find("CesiumMan.glb: 19 joints, 19 segments, a skin of 4672 triangles\n    its file carries 1 "
                               "animation ('animation 0')\n    drape run " + out + "/scene.wrl plays its own file's "
                               "animation 'animation 0' by itself (--motion none: at rest)\n"),
            std::string::npos)
      << inspected.out;
  const std::string byItself = dir / "by-itself";
  const CliResult own = runDrape("run '" + out + "/scene.wrl' --out '" + byItself + "'", dir);
  ASSERT_EQ(own.code, 0) << own.err;
  EXPECT_NE(own.err.find("CesiumMan.glb: the avatar's own file carries 1 animation; it plays 'animation 0' (--motion "
                         "none keeps it at rest)"),
            std::string::npos)
      << own.err;
  EXPECT_EQ(statsOf(byItself)["frames"], 90);
  EXPECT_EQ(testing::slurp(byItself + "/garment.pc2"), testing::slurp(run + "/garment.pc2"));
  const CliResult still = runDrape("run '" + out + "/scene.wrl' --motion none --frames 2 --out '" + (dir / "still") + "'", dir);
  ASSERT_EQ(still.code, 0) << still.err;
  EXPECT_EQ(still.err.find("joint map"), std::string::npos) << still.err;
  const CliResult jogItself =
      runDrape("run '" + out + "/scene.wrl' --animation jog --frames 2 --out '" + (dir / "jog-itself") + "'", dir);
  EXPECT_EQ(jogItself.code, 2);
  EXPECT_NE(jogItself.err.find("CesiumMan.glb: has no animation 'jog' (it has 1: 0 'animation 0')"), std::string::npos)
      << jogItself.err;
  // The bundled skirt's MakeHuman body carries none: --animation alone has nothing to choose.
  const CliResult none = runDrape("run '" + testing::kSkirtDir + "/scene.wrl' --animation 0 --frames 2 --out '" +
                                      (dir / "none") + "'",
                                  dir);
  EXPECT_EQ(none.code, 2);
  EXPECT_NE(none.err.find("--animation 0: the avatar's own file carries no animation to choose from; give the motion "
                          "with --motion FILE"),
            std::string::npos)
      << none.err;

  // An animation the file does not have; --animation with a BVH.
  const CliResult jog = runDrape("run '" + out + "/scene.wrl' --motion '" + cesium + "' --animation jog --frames 2 --out '" +
                                     (dir / "jog") + "'",
                                 dir);
  EXPECT_EQ(jog.code, 2);
  EXPECT_NE(jog.err.find(cesium + ": has no animation 'jog' (it has 1: 0 'animation 0')"), std::string::npos) << jog.err;
  const CliResult bvh = runDrape("run '" + testing::kSkirtDir + "/scene.wrl' --motion '" + testing::kSkirtDir +
                                     "/walk.bvh' --animation 1 --frames 2 --out '" + (dir / "bvh") + "'",
                                 dir);
  EXPECT_EQ(bvh.code, 2);
  EXPECT_NE(bvh.err.find("--animation: " + testing::kSkirtDir +
                         "/walk.bvh is not an avatar file (.glb, .gltf, .vrm, .dae, .fbx, .wrl); animations are chosen from an avatar's own file"),
            std::string::npos)
      << bvh.err;

  // Onto another avatar the walk is retargeted; no shipped map pairs CesiumMan's joints
  // (joint0, joint1, ...), so they are paired by the two skeletons' shapes, and the run says so.
  const CliResult other = runDrape("run '" + testing::kSkirtDir + "/scene.wrl' --motion '" + cesium + "' --frames 2 --out '" +
                                       (dir / "other") + "'",
                                   dir);
  EXPECT_EQ(other.code, 0) << other.err;
  EXPECT_NE(other.err.find("joint map 'by shape' drives 21 of "), std::string::npos) << other.err;
}

TEST(MakeSkirt, CesiumMansWalkAsColladaAndFbxDrivesTheSameBody) {
  // The walk converted with the character into Collada and FBX, played on the skirt scene
  // made from the glTF file: the skinned body moves as the glTF walk moves it, to within
  // what each file's keys keep (single-precision Collada; six digits in ASCII FBX).
  ScratchDir dir("make-skirt-cesium-formats");
  const std::string cesium = kAvatars + "/CesiumMan.glb";
  const std::string out = makeCesiumSkirt(dir);
  ASSERT_FALSE(out.empty());
  const auto bodyOf = [&](const std::string& motion, const std::string& name) {
    const std::string run = dir / name;
    const CliResult r = runDrape("run '" + out + "/scene.wrl' --motion '" + motion + "' --frames 45 --out '" + run + "'", dir);
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(statsOf(run)["vertex_substeps_inside_body"], 0) << name;
    return formats::readPc2(run + "/body.pc2");
  };
  const formats::Pc2Cache gltf = bodyOf(cesium, "glb");
  ASSERT_EQ(gltf.frames.size(), 46u);  // the first frame and 45 simulated
  for (const std::string ext : {".dae", ".fbx"}) {
    const std::string converted = dir / ("CesiumMan" + ext);
    const CliResult c = runDrape("convert '" + cesium + "' --to '" + converted + "'", dir);
    ASSERT_EQ(c.code, 0) << c.err;
    const formats::Pc2Cache other = bodyOf(converted, ext.substr(1));
    ASSERT_EQ(other.frames.size(), gltf.frames.size()) << ext;
    double worst = 0.0;
    for (std::size_t f = 0; f < gltf.frames.size(); ++f) {
      ASSERT_EQ(other.frames[f].size(), gltf.frames[f].size());
      for (std::size_t v = 0; v < gltf.frames[f].size(); ++v) worst = std::max(worst, (other.frames[f][v] - gltf.frames[f][v]).norm());
    }
    EXPECT_LT(worst, ext == ".fbx" ? 5e-5 : 1e-5) << ext << ": the body moved up to " << worst << " m away";
  }
}

TEST(MakeSkirt, RungeKuttaWritesTheSubstepsItsBoundAllows) {
  // The fourth-order step's bound on the skirt's stiffest mode, damped as the knit is: 10
  // substeps a frame instead of 33, bending in each stage (drape run walks it:
  // RunScene.RungeKuttaWalksTheSkirtAtTheSubstepsItsBoundAllows).
  ScratchDir dir("make-skirt-runge-kutta");
  const std::string out = dir / "skirt";
  const CliResult r = runDrape(
      "make-skirt '" + kAvatars + "/makehuman_rig_cmu_mb.mhskel' --integrator runge-kutta-4 --out '" + out + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("; 10 substeps per frame, each a fourth-order Runge-Kutta step\n"), std::string::npos) << r.out;
  const scene::Scene sc = scene::loadScene(out + "/scene.wrl");
  EXPECT_EQ(sc.simulation.integrator, "runge-kutta-4");
  EXPECT_EQ(sc.simulation.stepsPerFrame, 10);
  EXPECT_EQ(sc.simulation.bendEvery, 1);
}

TEST(MakeSkirt, BackwardEulerWritesAnImplicitSceneThatWalks) {
  // An eighth of the paper's 33 substeps, rounded up, each a backward-Euler solve to the
  // tolerance asked for; the skirt walks out of the body with every solve converged.
  ScratchDir dir("make-skirt-implicit");
  const std::string out = dir / "skirt";
  const CliResult r = runDrape("make-skirt '" + kAvatars +
                                   "/makehuman_rig_cmu_mb.mhskel' --integrator backward-euler --implicit-tolerance "
                                   "0.0005 --out '" + out + "'",
                               dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("; 5 substeps per frame, each a backward-Euler solve\n"), std::string::npos) << r.out;
  const scene::Scene sc = scene::loadScene(out + "/scene.wrl");
  EXPECT_EQ(sc.simulation.integrator, "backward-euler");
  EXPECT_EQ(sc.simulation.stepsPerFrame, 5);
  EXPECT_EQ(sc.simulation.bendEvery, 1);
  EXPECT_NEAR(sc.simulation.implicitTolerance, 5e-4, 1e-10);
  const CliResult ran = walk(dir, out + "/scene.wrl", 40);
  ASSERT_EQ(ran.code, 0) << ran.err;
  EXPECT_NE(ran.err.find("Skirt: backward Euler, 5 substeps per frame"), std::string::npos) << ran.err;
  const nlohmann::json stats = statsOf(dir / "walk");
  EXPECT_EQ(stats["vertex_substeps_inside_body"].get<long>(), 0);
  const nlohmann::json& solves = stats["garments"][0]["implicit_solves"];
  EXPECT_GE(solves["substeps"].get<long>(), 40 * 5);
  EXPECT_EQ(solves["unconverged"].get<long>(), 0);
  // The scene's tolerance is the run's: the default, looser, given on the command line
  // takes fewer iterations per solve than the scene's 0.0005.
  const CliResult looser = runDrape("run '" + out + "/scene.wrl' --motion '" + std::string(DRAPE_SOURCE_DIR) +
                                        "/examples/walking_skirt/walk.bvh' --frames 40 --implicit-tolerance 0.001 "
                                        "--out '" + (dir / "looser") + "'",
                                    dir);
  ASSERT_EQ(looser.code, 0) << looser.err;
  EXPECT_LT(statsOf(dir / "looser")["garments"][0]["implicit_solves"]["mean_iterations"].get<double>(),
            solves["mean_iterations"].get<double>());
  // A tolerance without the implicit step is refused, not ignored.
  const CliResult explicitStep = runDrape("make-skirt '" + kAvatars +
                                              "/makehuman_rig_cmu_mb.mhskel' --implicit-tolerance 0.0005 --out '" +
                                              (dir / "explicit") + "'",
                                          dir);
  EXPECT_EQ(explicitStep.code, 2) << explicitStep.err;
  EXPECT_NE(explicitStep.err.find("--implicit-tolerance applies to --integrator backward-euler, not symplectic-euler"),
            std::string::npos)
      << explicitStep.err;
}

}  // namespace
}  // namespace drape
