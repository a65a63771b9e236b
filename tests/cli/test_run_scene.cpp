// `drape run SCENE --motion FILE` end to end on the bundled walking skirt: every output
// written, the avatar's parts moving, the collision figures present and clean, result.glb
// valid for the Khronos validator and result.wrl readable by drape's own reader.

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/pc2.hpp"
#include "drape/formats/run_manifest.hpp"
#include "drape/formats/state_cache.hpp"
#include "drape/scene/scene.hpp"

namespace drape {
namespace {

using testing::CliResult;
using testing::runDrape;
using testing::ScratchDir;
using testing::slurp;
using testing::statsOf;

using testing::kSkirtDir;

// The smallest bundled scene (an H-Anim humanoid of primitives, no motion: it stands) runs
// as it is, without a warning, and its skirt stays out of the body.
TEST(RunScene, TheDressedAvatarExampleRunsAsItIs) {
  ScratchDir dir("run-dressed-avatar");
  const std::string out = dir / "dressed";
  const CliResult r = runDrape(
      "run '" + std::string(DRAPE_SOURCE_DIR) + "/examples/dressed_avatar/scene.wrl' --frames 20 --out '" + out + "'",
      dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  const nlohmann::json stats = statsOf(out);
  EXPECT_EQ(stats["frames"], 20);
  EXPECT_EQ(stats["vertex_substeps_inside_body"], 0);
  EXPECT_GT(stats["vertex_substeps"].get<long>(), 0);
}

// The CMU original of a capture (Acclaim ASF/AMC; subject 11's soccer kick) drives the
// scene's MakeHuman body through the shipped 'acclaim' map, every joint paired, and the
// skirt keeps out of the body through the kick.
TEST(RunScene, AnAcclaimKickDrivesTheAvatarAndTheSkirtStaysOut) {
  ScratchDir dir("run-acclaim");
  const std::string out = dir / "kick";
  const CliResult r = runDrape("run '" + kSkirtDir + "/scene.wrl' --motion '" + std::string(DRAPE_DATA_DIR) +
                                   "/mocap/cmu_11_01.amc' --out '" + out + "'",
                               dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("cmu_11_01.amc: 597 frames at 120 Hz in CMU units (0.0564 m); joint map 'acclaim' drives 31 "
                       "of the avatar's 31 joints"),
            std::string::npos)
      << r.err;
  const nlohmann::json stats = statsOf(out);
  EXPECT_EQ(stats["frames"].get<int>(), 30 + 150 - 1);  // 1 s of lead-in, then 4.97 s at 30 Hz
  EXPECT_EQ(stats["vertex_substeps_inside_body"].get<long>(), 0);
  EXPECT_LT(stats["vertex_substeps_below_T1"].get<double>(), 1e-3 * stats["vertex_substeps"].get<double>());
}

// The walking skirt on MakeHuman's default rig (twist bones) and game-engine rig (a Root on
// the floor) walking the CMU walk: the shipped maps compose onto each rig and the run is
// stable. On the default rig the skirt stays out of the body but where its waistband, bound
// to the waist, dips into the hip bones' parts (pelvis.L, .R: every part of the body
// collides here) as the spine bends over the hips: 0.025 % of the vertex-substeps, 8 mm at
// most. (Until the hip bones kept their place on the pelvis, the capture's hip bone turned
// pelvis.L up to 97 mm off it, out of the waistband's way.) The game-engine rig's thigh
// segments carry the buttocks (it has no hip bones), so the skirt is pinched between them
// and the pelvis and sinks into it (over the whole walk 0.071 % of vertex-substeps, up to
// 11 mm; docs/MOTION.md).
TEST(RunScene, TheSkirtWalksOnMakeHumansOtherRigs) {
  ScratchDir dir("run-rigs");
  for (const std::string rig : {"default", "game_engine"}) {
    const std::string out = dir / rig;
    const CliResult r = runDrape("run --garment '" + kSkirtDir + "/skirt.obj' --pin-mask '" + kSkirtDir +
                                     "/waistband.obj' --avatar '" + std::string(DRAPE_DATA_DIR) +
                                     "/avatars/makehuman_rig_" + rig + ".mhskel' --motion '" + kSkirtDir +
                                     "/walk.bvh' --frames 60 --every 60 --out '" + out + "'",
                                 dir);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("joint map 'motionbuilder + makehuman_" + rig + "' drives"), std::string::npos) << r.err;
    const nlohmann::json stats = statsOf(out);
    EXPECT_EQ(stats["frames"].get<int>(), 60);
    EXPECT_FALSE(stats["unstable"].get<bool>());
    if (rig == "default") {
      EXPECT_LT(stats["vertex_substeps_inside_body"].get<double>() / stats["vertex_substeps"].get<double>(), 1e-3);
      EXPECT_LT(stats["max_penetration_m"].get<double>(), 0.010);
    }
  }
}

// `--collision-every 3` runs the collision tests on every third substep; stats.json then
// counts penetration on those only, unless `--count-every-substep` asks for all of them,
// which reads and moves nothing: the same motion, three times the substeps counted.
TEST(RunScene, ReducedFrequencyTestsSayWhatTheirFiguresCount) {
  ScratchDir dir("run-collision-every");
  const auto run = [&](const std::string& name, const std::string& extra) {
    return testing::runInto(dir, name,
                            "'" + kSkirtDir + "/scene.wrl' --motion '" + kSkirtDir +
                                "/walk.bvh' --lead-in 0.2 --frames 15 --collision-every 3 " + extra);
  };
  const std::string tested = run("tested", ""), every = run("every", "--count-every-substep");
  const nlohmann::json a = statsOf(tested);
  const nlohmann::json b = statsOf(every);
  EXPECT_EQ(a["collision_every"], 3);
  EXPECT_EQ(a["penetration_counted_on"], "tested substeps");
  EXPECT_EQ(b["penetration_counted_on"], "every substep");
  // 16 frames (the initial one is not stepped: 15 x 33 substeps), 240 free vertices.
  EXPECT_EQ(b["vertex_substeps"].get<long>(), 15L * 33 * 240);
  EXPECT_EQ(b["vertex_substeps"].get<long>(), 3 * a["vertex_substeps"].get<long>());
  EXPECT_EQ(slurp(tested + "/garment.pc2"), slurp(every + "/garment.pc2"));
  EXPECT_EQ(b["vertex_substeps_inside_body"], 0);
  // Sliding tests answered by contact planes unless asked to read the field on each.
  const nlohmann::json exact =
      statsOf(run("exact", "--exact-sliding"));
  EXPECT_GT(a["sliding_reads_from_contact_planes"].get<double>(), 0.5);
  EXPECT_EQ(exact["sliding_reads_from_contact_planes"], 0.0);
  EXPECT_EQ(exact["vertex_substeps_inside_body"], 0);
  // Points pinched at a test held until the next, unless asked to move freely.
  const nlohmann::json free = statsOf(run("free", "--free-pinches"));
  ASSERT_TRUE(a.contains("vertex_substeps_held_in_pinches"));
  EXPECT_EQ(a["vertex_substeps_held_in_pinches"], b["vertex_substeps_held_in_pinches"]);
  EXPECT_EQ(free["vertex_substeps_held_in_pinches"], 0);
  // The measuring is timed apart from the collision work (and left out of its share).
  for (const nlohmann::json* j : {&a, &b}) {
    EXPECT_GT((*j)["penetration_measure_ms_per_frame"].get<double>(), 0.0);
    EXPECT_GT((*j)["collision_time_share"].get<double>(), 0.0);
    EXPECT_LT((*j)["collision_time_share"].get<double>(), 1.0);
  }
}

// The scene's settings stand unless an option is given; one that is overrides them (the
// help says so): twice the scene's density (300 kg/m^3) doubles the skirt's mass.
TEST(RunScene, OptionsGivenOverrideTheScenesSettings) {
  ScratchDir dir("run-overrides");
  const auto stats = [&](const std::string& name, const std::string& extra) {
    const std::string out = testing::runInto(
        dir, name, "'" + kSkirtDir + "/scene.wrl' --motion '" + kSkirtDir + "/walk.bvh' --lead-in 0.1 --frames 1 " + extra);
    return statsOf(out);
  };
  const nlohmann::json scene = stats("scene", "");
  const nlohmann::json given = stats("given", "--density 600 --substeps 40");
  EXPECT_EQ(scene["substeps_per_frame"], 33);
  EXPECT_EQ(given["substeps_per_frame"], 40);
  const double sceneMass = scene["garments"][0]["mass_kg"].get<double>();
  EXPECT_NEAR(given["garments"][0]["mass_kg"].get<double>(), 2 * sceneMass, 1e-9);
}

TEST(RunScene, WalkingSkirtWritesEverything) {
  ScratchDir dir("run-walking-skirt");
  const std::string out = dir / "out";
  const CliResult r = runDrape("run '" + kSkirtDir + "/scene.wrl' --motion '" + kSkirtDir +
                                   "/walk.bvh' --lead-in 0.2 --frames 15 --every 5 --out '" + out + "'",
                               dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("walk.bvh: frame 1 is a reference T-pose, not played"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("start below T2"), std::string::npos) << "the skirt hangs clear of the body:\n" << r.err;
  for (const char* f : {"garment.pc2", "garment.obj", "result.wrl", "result.glb", "stats.json", "manifest.json",
                        "frames/frame_00015.obj", "segments/Hips.pc2", "segments/LeftLeg.obj"})
    EXPECT_TRUE(std::filesystem::exists(out + "/" + f)) << f;

  const formats::RunManifest manifest = formats::readRunManifest(out);
  EXPECT_EQ(manifest.frames, 16);
  std::size_t segments = 0;
  for (const auto& m : manifest.meshes) segments += m.role == "segment";
  EXPECT_EQ(segments, 31u);
  // The skinned body players draw: the MakeHuman mesh, one sample per frame, moving.
  const auto skin = std::find_if(manifest.meshes.begin(), manifest.meshes.end(),
                                 [](const formats::RunMesh& m) { return m.role == "skin"; });
  ASSERT_NE(skin, manifest.meshes.end());
  EXPECT_EQ(skin->topology, "body.obj");
  const formats::Pc2Cache body = formats::readPc2(out + "/" + skin->cache);
  ASSERT_EQ(body.frames.size(), 16u);
  EXPECT_EQ(body.pointCount, formats::readObj(out + "/body.obj").vertexCount());
  EXPECT_GT(body.pointCount, 10000u);
  double moved = 0.0;
  for (std::size_t v = 0; v < body.pointCount; ++v)
    moved = std::max(moved, (body.frames.back()[v] - body.frames.front()[v]).norm());
  EXPECT_GT(moved, 0.05);

  // The skirt's vertex states: one frame per cache frame, its waist bound to the body
  // (0x08) from the first frame, and points on the collision surface (2) once it walks.
  ASSERT_EQ(manifest.meshes.front().states, "garment.states");
  const formats::StateCache states = formats::readStateCache(out + "/garment.states");
  const formats::Pc2Cache skirt = formats::readPc2(out + "/garment.pc2");
  ASSERT_EQ(states.frames.size(), 16u);
  EXPECT_EQ(states.vertexCount, skirt.pointCount);
  std::size_t bound = 0, sliding = 0;
  for (const std::uint8_t s : states.frames.front()) bound += (s & 0x08) != 0;
  for (const std::uint8_t s : states.frames.back()) sliding += (s & 0x03) == 2;
  EXPECT_GT(bound, 10u);
  EXPECT_GT(sliding, 0u);

  // The left shin moves as the avatar walks.
  const formats::Pc2Cache shin = formats::readPc2(out + "/segments/LeftLeg.pc2");
  ASSERT_EQ(shin.frames.size(), 16u);
  EXPECT_GT((shin.frames.back()[0] - shin.frames.front()[0]).norm(), 0.02);

  const nlohmann::json stats = statsOf(out);
  for (const char* key : {"collision_time_share", "mean_collision_path_voxels", "points_per_state",
                          "vertex_substeps_below_T1", "vertex_substeps_below_T0", "vertex_substeps_inside_body",
                          "vertex_substeps_below_T1_pinched", "vertex_substeps_inside_body_pinched",
                          "max_penetration_m", "crease_moves", "crease_moves_refused", "distance_fields",
                          "body_overlaps"})
    EXPECT_TRUE(stats.contains(key)) << key;
  EXPECT_LE(stats["crease_moves"].get<long>() + stats["crease_moves_refused"].get<long>(),
            stats["vertex_tests_pinched"].get<long>());
  EXPECT_LE(stats["vertex_substeps_below_T1_pinched"].get<long>(), stats["vertex_substeps_below_T1"].get<long>());
  EXPECT_LE(stats["vertex_substeps_inside_body_pinched"].get<long>(),
            stats["vertex_substeps_inside_body"].get<long>());
  // Walking, the segmented thigh swung forward presses into the belly's part
  // (docs/ARCHITECTURE.md, body overlaps).
  bool thigh = false;
  for (const auto& o : stats["body_overlaps"]) {
    for (const char* key : {"part", "into", "depth_m", "deepest_frame", "first_frame", "last_frame", "frames"})
      EXPECT_TRUE(o.contains(key)) << key;
    thigh |= o["part"] == "LeftUpLeg" && o["into"] == "LowerBack" && o["depth_m"].get<double>() > 0.02;
  }
  EXPECT_TRUE(thigh) << stats["body_overlaps"].dump();
  EXPECT_EQ(stats["vertex_substeps_inside_body"].get<long>(), 0);
  const double share = stats["collision_time_share"].get<double>();
  EXPECT_GT(share, 0.0);
  EXPECT_LT(share, 1.0);
  EXPECT_EQ(stats["distance_fields"].size(), 6u);
  EXPECT_FALSE(stats["nan_detected"].get<bool>());

  // result.wrl reads back through drape's own VRML97 reader.
  const scene::Scene back = scene::loadScene(out + "/result.wrl");
  EXPECT_FALSE(back.scenery.empty() && back.avatars.empty()) << "result.wrl holds no geometry";

  // result.glb: zero errors from the Khronos validator.
  const std::string validator = std::string(DRAPE_SOURCE_DIR) + "/tools/gltf-validator/validate.js";
  if (std::system("command -v node >/dev/null 2>&1") != 0 ||
      !std::filesystem::exists(std::string(DRAPE_SOURCE_DIR) + "/tools/gltf-validator/node_modules/gltf-validator"))
    GTEST_SKIP() << "node or the glTF validator is not installed (scripts/install-deps installs them)";
  const std::string reportFile = dir / "validator.json";
  const int status = std::system(("node '" + validator + "' '" + out + "/result.glb' >'" + reportFile + "'").c_str());
  const std::string text = slurp(reportFile);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << text;
  const nlohmann::json report = nlohmann::json::parse(text);
  EXPECT_EQ(report["errors"].get<int>(), 0) << text;
}

// Two garments step in parallel, each with its own poses and colliders: the walking
// skirt twice over (garments do not touch each other) gives each copy exactly the skirt
// alone, so nothing passes between garments stepping at the same time.
TEST(RunScene, TwoGarmentsInParallelComeOutAsEachAlone) {
  ScratchDir dir("run-two-garments");
  const std::string twoScene = twoSkirtScene(dir);
  const std::string motion = " --motion '" + kSkirtDir + "/walk.bvh' --frames 20 --out '";
  const CliResult one = runDrape("run '" + kSkirtDir + "/scene.wrl'" + motion + (dir / "one") + "'", dir);
  ASSERT_EQ(one.code, 0) << one.err;
  const CliResult two = runDrape("run '" + twoScene + "'" + motion + (dir / "two") + "'", dir);
  ASSERT_EQ(two.code, 0) << two.err;
  const formats::Pc2Cache alone = formats::readPc2(dir / "one/garment.pc2");
  ASSERT_EQ(alone.frames.size(), 21u);
  for (const char* name : {"garment-Skirt.pc2", "garment-Skirt2.pc2"}) {
    const formats::Pc2Cache copy = formats::readPc2(dir / ("two/" + std::string(name)));
    ASSERT_EQ(copy.frames.size(), alone.frames.size()) << name;
    for (std::size_t f = 0; f < alone.frames.size(); ++f)
      ASSERT_EQ(copy.frames[f], alone.frames[f]) << name << ", frame " << f;
  }
  EXPECT_GT((alone.frames.back()[0] - alone.frames.front()[0]).norm(), 1e-3) << "the skirt must move";
  EXPECT_EQ(statsOf(dir / "two")["garments"].size(), 2u);
}

TEST(RunScene, MotionWithoutAvatarIsABadInput) {
  ScratchDir dir("run-no-avatar");
  const CliResult r = runDrape("run --garment '" + std::string(DRAPE_SOURCE_DIR) +
                                   "/examples/hanging_dress/dress.obj' --units dm --motion '" + kSkirtDir +
                                   "/walk.bvh' --frames 2 --out '" + (dir / "out") + "'",
                               dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--motion: there is no avatar"), std::string::npos) << r.err;
}

TEST(RunScene, OffsetsGivenOverrideTheScenesAndAreChecked) {
  ScratchDir dir("run-offsets");
  const std::string scene = "'" + kSkirtDir + "/scene.wrl' --motion '" + kSkirtDir + "/walk.bvh' --frames 2 ";
  const std::string out = testing::runInto(dir, "out", scene + "--offsets 0.004,0.008,0.012,0.024");
  const nlohmann::json stats = statsOf(out);
  EXPECT_EQ(stats["garments"][0]["offsets_m"], nlohmann::json({0.004, 0.008, 0.012, 0.024}));
  // Without the option, the scene's (5, 10, 15 and 30 mm, VRML97 single-precision floats).
  const std::string plain = testing::runInto(dir, "plain", scene);
  const nlohmann::json scenes = statsOf(plain)["garments"][0]["offsets_m"];
  ASSERT_EQ(scenes.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) EXPECT_NEAR(scenes[k].get<double>(), 0.005 * double(k == 3 ? 6 : k + 1), 1e-8);
  const CliResult bad = runDrape("run " + scene + "--offsets 0.004,0.003,0.012,0.024 --out '" + (dir / "bad") + "'", dir);
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("--offsets must satisfy 0 <= T0 < T1 < T2 < T3 (m), got 0.004 0.003 0.012 0.024"),
            std::string::npos)
      << bad.err;

  // A garment's own offsets (ClothSet offsets) instead of the Simulation node's, the other
  // garment keeping the scene's.
  const std::string two = twoSkirtScene(dir);
  std::string text = slurp(two);
  text.replace(text.find("DEF Skirt2 ClothSet {"), 21, "DEF Skirt2 ClothSet {\n  offsets [ 0.003 0.006 0.009 0.02 ]");
  std::ofstream(two) << text;
  const nlohmann::json own =
      statsOf(testing::runInto(dir, "own", "'" + two + "' --motion '" + kSkirtDir + "/walk.bvh' --frames 2"));
  const std::vector<double> skirt2{0.003, 0.006, 0.009, 0.02};
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_NEAR(own["garments"][0]["offsets_m"][k].get<double>(), 0.005 * double(k == 3 ? 6 : k + 1), 1e-8);
    EXPECT_NEAR(own["garments"][1]["offsets_m"][k].get<double>(), skirt2[k], 1e-8);
  }
}

TEST(RunScene, FaceSamplesAreChosenByPartAndChecked) {
  ScratchDir dir("run-faces");
  const std::string scene = "'" + kSkirtDir + "/scene.wrl' --motion '" + kSkirtDir + "/walk.bvh' --frames 2 ";
  const nlohmann::json plain = statsOf(testing::runInto(dir, "plain", scene));
  EXPECT_EQ(plain["garments"][0]["face_samples_with"], nlohmann::json::array());
  EXPECT_EQ(plain["face_tests"].get<long>(), 0);
  const nlohmann::json legs = statsOf(testing::runInto(dir, "legs", scene + "--face-samples-with LeftUpLeg,RightUpLeg"));
  EXPECT_EQ(legs["garments"][0]["face_samples_with"], nlohmann::json({"LeftUpLeg", "RightUpLeg"}));
  EXPECT_TRUE(legs.contains("face_contacts_inside_body"));
  const CliResult bad =
      runDrape("run " + scene + "--face-samples-with LeftUpLeg,Head --out '" + (dir / "bad") + "'", dir);
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("garment 'Skirt': face samples with 'Head', which it does not collide with (it collides "
                         "with: LowerBack, Hips, LeftUpLeg, RightUpLeg, LeftLeg, RightLeg)"),
            std::string::npos)
      << bad.err;
  const CliResult bodiless = runDrape("run --garment '" + kSkirtDir + "/skirt.obj' --face-samples-with Hips --frames 1 "
                                      "--out '" + (dir / "bodiless") + "'",
                                      dir);
  EXPECT_EQ(bodiless.code, 2);
  EXPECT_NE(bodiless.err.find("--face-samples-with: there is no avatar to collide with"), std::string::npos)
      << bodiless.err;
  // Without a scene, on an avatar: the collision options apply there too (before, the
  // --garment path left out --collision-every).
  const nlohmann::json worn = statsOf(testing::runInto(
      dir, "worn", "--garment '" + kSkirtDir + "/skirt.obj' --avatar '" + std::string(DRAPE_SOURCE_DIR) +
                       "/data/avatars/makehuman_rig_cmu_mb.mhskel' --pin-mask '" + kSkirtDir +
                       "/waistband.obj' --collision-every 3 --face-samples-with LeftUpLeg --frames 1"));
  EXPECT_EQ(worn["collision_every"].get<int>(), 3);
  EXPECT_EQ(worn["garments"][0]["face_samples_with"], nlohmann::json({"LeftUpLeg"}));
}

TEST(RunScene, DampingTheSubstepCannotCarryIsRefusedWithTheWayOut) {
  // The skirt's 1.01 ms substep carries at most 3.87 ms of damping (its membrane's stiffest
  // mode, the waistband held: 605 rad/s); 10 ms diverged in the first frame before the check.
  ScratchDir dir("run-damping");
  const std::string scene = "run '" + kSkirtDir + "/scene.wrl' --motion '" + kSkirtDir + "/walk.bvh' --frames 1 ";
  const CliResult r = runDrape(scene + "--damping 0.01 --out '" + (dir / "out") + "'", dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("internal damping of 0.01 s makes the substep of 1.01 ms unstable"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("set damping to 0.00387 s or less, or use 78 substeps per frame or more"), std::string::npos)
      << r.err;
  // What it suggests runs, and says how close to the bound it is.
  const CliResult ok = runDrape(scene + "--damping 0.01 --substeps 78 --out '" + (dir / "ok") + "'", dir);
  EXPECT_EQ(ok.code, 0) << ok.err;
  EXPECT_NE(ok.err.find("Skirt: internal damping 10 ms, 9"), std::string::npos) << ok.err;
}

TEST(RunScene, BackwardEulerWalksTheSkirtAtFourSubstepsAFrame) {
  // The implicit step at an eighth of the scene's substeps (8.3 ms, about eight times the
  // explicit steps' estimated stable one): the skirt stays out of the body, every solve
  // converges, and the scene's bending rhythm (8) gives way to bending every substep.
  ScratchDir dir("run-backward-euler");
  const std::string scene = "run '" + kSkirtDir + "/scene.wrl' --motion '" + kSkirtDir +
                            "/walk.bvh' --frames 30 --integrator backward-euler --substeps 4 ";
  const CliResult ok = runDrape(scene + "--out '" + (dir / "ok") + "'", dir);
  ASSERT_EQ(ok.code, 0) << ok.err;
  EXPECT_NE(ok.err.find("Skirt: backward Euler, 4 substeps per frame (8.33 ms"), std::string::npos) << ok.err;
  const nlohmann::json stats = statsOf(dir / "ok");
  EXPECT_EQ(stats["integrator"].get<std::string>(), "backward-euler");
  EXPECT_FALSE(stats["unstable"].get<bool>());
  EXPECT_EQ(stats["vertex_substeps_inside_body"].get<long>(), 0);
  const nlohmann::json& skirt = stats["garments"][0];
  EXPECT_EQ(skirt["added_mass_kg"].get<double>(), 0.0);
  EXPECT_EQ(skirt["frames_refined"].get<long>(), 0);
  const nlohmann::json& solves = skirt["implicit_solves"];
  EXPECT_EQ(solves["substeps"].get<long>(), 30 * 4);
  EXPECT_EQ(solves["unconverged"].get<long>(), 0);
  EXPECT_EQ(solves["indefinite"].get<long>(), 0);
  EXPECT_GT(solves["mean_iterations"].get<double>(), 1.0);
  EXPECT_TRUE(skirt["strain_limited_from_frame"].is_null());

  EXPECT_EQ(ok.err.find("fewer run faster"), std::string::npos) << ok.err;
  // At the scene's own 33 substeps it runs, and says that fewer would do.
  const CliResult many = runDrape("run '" + kSkirtDir + "/scene.wrl' --motion '" + kSkirtDir +
                                      "/walk.bvh' --frames 1 --integrator backward-euler --out '" + (dir / "many") + "'",
                                  dir);
  EXPECT_EQ(many.code, 0) << many.err;
  EXPECT_NE(many.err.find("warning: Skirt: backward Euler is stable at substeps many times the explicit steps' "
                          "1.23 ms; fewer run faster (e.g. --substeps 5, an eighth)"),
            std::string::npos)
      << many.err;
  const CliResult automatic = runDrape("run '" + kSkirtDir + "/scene.wrl' --motion '" + kSkirtDir +
                                           "/walk.bvh' --frames 3 --integrator backward-euler --substeps auto --out '" +
                                           (dir / "auto") + "'",
                                       dir);
  EXPECT_EQ(automatic.code, 2) << automatic.err;
  EXPECT_NE(automatic.err.find("backward-euler is stable at any: give a count"), std::string::npos) << automatic.err;
  const CliResult rhythm = runDrape(scene + "--bend-every 2 --out '" + (dir / "rhythm") + "'", dir);
  EXPECT_EQ(rhythm.code, 2) << rhythm.err;
  EXPECT_NE(rhythm.err.find("--bend-every must be 1 with the backward-euler integrator"), std::string::npos)
      << rhythm.err;
}

TEST(RunScene, ForwardEulerRunsInsideItsDampingWindowOnly) {
  // The paper's integrator: the skirt's 2 ms of damping lies inside the window its 1.01 ms
  // substep allows; undamped, every mode would grow, and the run is refused with the window.
  ScratchDir dir("run-forward-euler");
  const std::string scene = "run '" + kSkirtDir + "/scene.wrl' --motion '" + kSkirtDir +
                            "/walk.bvh' --frames 3 --integrator forward-euler ";
  const CliResult ok = runDrape(scene + "--out '" + (dir / "ok") + "'", dir);
  EXPECT_EQ(ok.code, 0) << ok.err;
  EXPECT_NE(ok.err.find("Skirt: forward Euler with internal damping 2 ms, within the 1.01 to 4.88 ms"),
            std::string::npos)
      << ok.err;
  EXPECT_EQ(statsOf(dir / "ok")["integrator"].get<std::string>(), "forward-euler");
  const CliResult undamped = runDrape(scene + "--damping 0 --out '" + (dir / "undamped") + "'", dir);
  EXPECT_EQ(undamped.code, 2) << undamped.err;
  EXPECT_NE(undamped.err.find("garment 'Skirt': forward Euler is unstable at a substep of 1.01 ms with internal "
                              "damping of 0 ms"),
            std::string::npos)
      << undamped.err;
  EXPECT_NE(undamped.err.find("set damping above 1.01 ms and at most 4.88 ms"), std::string::npos) << undamped.err;
}

TEST(RunScene, RungeKuttaWalksTheSkirtAtTheSubstepsItsBoundAllows) {
  // The classical Runge-Kutta step: --substeps auto asks what its bound on the membrane's
  // stiffest mode allows with the skirt's 2 ms of damping (10 a frame, a third of the scene's
  // 33), and the skirt walks out of the body at them; past the bound the run is refused with
  // the count that holds, and a bending rhythm cannot go with it.
  ScratchDir dir("run-runge-kutta");
  const std::string scene = "run '" + kSkirtDir + "/scene.wrl' --motion '" + kSkirtDir +
                            "/walk.bvh' --integrator runge-kutta-4 ";
  const CliResult ok = runDrape(scene + "--frames 60 --substeps auto --out '" + (dir / "ok") + "'", dir);
  ASSERT_EQ(ok.code, 0) << ok.err;
  EXPECT_NE(ok.err.find("--substeps auto: 10 substeps per frame (3.333 ms)\n"), std::string::npos) << ok.err;
  EXPECT_NE(ok.err.find("Skirt: Runge-Kutta (fourth order), 10 substeps per frame (3.33 ms, 84 % of the 3.98 ms"),
            std::string::npos)
      << ok.err;
  const nlohmann::json stats = statsOf(dir / "ok");
  EXPECT_EQ(stats["integrator"].get<std::string>(), "runge-kutta-4");
  EXPECT_EQ(stats["substeps_per_frame"].get<int>(), 10);
  EXPECT_FALSE(stats["unstable"].get<bool>());
  EXPECT_EQ(stats["vertex_substeps_inside_body"].get<long>(), 0);
  EXPECT_EQ(stats["garments"][0]["frames_refined"].get<long>(), 0);
  EXPECT_EQ(stats["garments"][0]["added_mass_kg"].get<double>(), 0.0);

  const CliResult fast = runDrape(scene + "--frames 3 --substeps 8 --out '" + (dir / "fast") + "'", dir);
  EXPECT_EQ(fast.code, 2) << fast.err;
  EXPECT_NE(fast.err.find("garment 'Skirt': the runge-kutta-4 step is unstable at a substep of 4.17 ms (the "
                          "membrane's stiffest mode, 605.5 rad/s, with internal damping of 2 ms allows at most "
                          "3.98 ms); use 9 substeps per frame or more"),
            std::string::npos)
      << fast.err;
  const CliResult rhythm = runDrape(scene + "--frames 3 --bend-every 2 --out '" + (dir / "rhythm") + "'", dir);
  EXPECT_EQ(rhythm.code, 2) << rhythm.err;
  EXPECT_NE(rhythm.err.find("--bend-every must be 1 with the runge-kutta-4 integrator"), std::string::npos)
      << rhythm.err;

  // The walking dress's slivers, overdamped at their frequency, hold the step to 355
  // substeps unscaled; with mass scaling aimed at its own bound (the elements scaled for a
  // step sqrt(2) shorter, as its undamped reach is that much longer, within the scene's 2 %)
  // it takes 108, where symplectic Euler's count with its own scaling is 152, for about as
  // much mass (over the whole walk no frame is computed again: docs/PERFORMANCE.md).
  const std::string dressScene = "run '" + std::string(DRAPE_SOURCE_DIR) + "/examples/walking_dress/scene.wrl' ";
  const CliResult dress = runDrape(dressScene + "--integrator runge-kutta-4 --substeps auto --frames 2 --out '" +
                                       (dir / "dress") + "'",
                                   dir);
  ASSERT_EQ(dress.code, 0) << dress.err;
  EXPECT_NE(dress.err.find("--substeps auto: 108 substeps per frame (0.309 ms), with mass scaling within "
                           "--max-added-mass"),
            std::string::npos)
      << dress.err;
  EXPECT_NE(dress.err.find("dress: Runge-Kutta (fourth order), 108 substeps per frame (0.309 ms, 60 % of the"),
            std::string::npos)
      << dress.err;
  const nlohmann::json rk = statsOf(dir / "dress")["garments"][0];
  const CliResult symplectic =
      runDrape(dressScene + "--substeps auto --frames 2 --out '" + (dir / "dress-se") + "'", dir);
  ASSERT_EQ(symplectic.code, 0) << symplectic.err;
  EXPECT_NE(symplectic.err.find("--substeps auto: 152 substeps per frame"), std::string::npos) << symplectic.err;
  const nlohmann::json se = statsOf(dir / "dress-se")["garments"][0];
  EXPECT_GT(rk["added_mass_kg"].get<double>(), 0.0);
  EXPECT_NEAR(rk["added_mass_kg"].get<double>(), se["added_mass_kg"].get<double>(),
              0.1 * se["added_mass_kg"].get<double>());
  EXPECT_EQ(rk["frames_refined"].get<long>(), 0);
}

}  // namespace
}  // namespace drape

namespace drape {
namespace {

TEST(PlayScene, SimulatesTheWalkingSkirtLiveUnderXvfb) {
  if (std::system("command -v xvfb-run >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed (scripts/install-deps installs xvfb)";
  ScratchDir dir("play-walking-skirt");
  const std::string shot = dir / "live.png";
  const std::string cmd = std::string("ASAN_OPTIONS=detect_leaks=0 xvfb-run -a '") + DRAPE_EXE + "' play '" + kSkirtDir +
                          "/scene.wrl' --motion '" + kSkirtDir + "/walk.bvh' --frames 4 --fast --collision-states " +
                          "--screenshot '" + shot + "' >'" + (dir / "out.txt") + "' 2>&1";
  const int status = std::system(cmd.c_str());
  const std::string out = slurp(dir / "out.txt");
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << out;
  EXPECT_NE(out.find("simulated and showed 4 frames"), std::string::npos) << out;
  // Frames 0 to 3 of the 1 s lead-in: said, without drape run's --lead-in.
  EXPECT_NE(out.find("warning: --frames 4 ends before the motion's first frame: the first 30 frames are the 1 s "
                     "lead-in, blending from the rest pose into the motion; --frames 34 shows 4 frames of the motion "
                     "itself\n"),
            std::string::npos)
      << out;
  EXPECT_TRUE(std::filesystem::exists(shot));
}

}  // namespace
}  // namespace drape

namespace drape {
namespace {

TEST(RenderScene, SimulatesThenRendersAContactSheet) {
  ScratchDir dir("render-walking-skirt");
  const std::string sheet = dir / "sheet.png", run = dir / "run";
  const CliResult r = runDrape("render '" + kSkirtDir + "/scene.wrl' --motion '" + kSkirtDir +
                                   "/walk.bvh' --frames 6 --run-out '" + run + "' --contact-sheet '" + sheet + "'",
                               dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(sheet));
  EXPECT_EQ(formats::readRunManifest(run).frames, 7);
  // Six frames of the 1 s lead-in (30 frames) never reach the walk: said, without drape run's
  // --lead-in, which drape render does not take.
  EXPECT_NE(r.err.find("warning: --frames 6 ends before the motion's first frame: the first 30 frames are the 1 s "
                       "lead-in, blending from the rest pose into the motion; --frames 36 renders 6 frames of the "
                       "motion itself\n"),
            std::string::npos)
      << r.err;
}

}  // namespace
}  // namespace drape
