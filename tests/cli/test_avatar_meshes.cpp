// A character file that holds its clothes as well as its body (games and character tools
// ship them so): the Avatar node's meshes choose the body the cloth collides with, and the
// garment comes from the same file by its own mesh's name.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "drape/formats/mesh_file.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/pc2.hpp"
#include "drape/formats/run_manifest.hpp"
#include "drape/render/image.hpp"
#include "drape/testing/clothed_avatar.hpp"
#include "drape/testing/glb_read.hpp"

namespace drape {
namespace {

using testing::CliResult;
using testing::runDrape;
using testing::ScratchDir;
using testing::statsOf;

using testing::loadGlb;

/// The cape's triangles from the shoulders up, as an OBJ: the constraint mask.
std::string shouldersMask(const std::string& clothed, const ScratchDir& dir) {
  formats::MeshFileOptions options;
  options.parts = {"Cape"};
  const mesh::TriMesh cape = formats::readMeshFile(clothed, options).mesh;
  std::vector<Vec3> positions;
  std::vector<mesh::Triangle> top;
  std::vector<std::uint32_t> index(cape.vertexCount(), UINT32_MAX);
  for (const mesh::Triangle& t : cape.triangles) {
    if (cape.positions[t[0]].y() < 1.2 || cape.positions[t[1]].y() < 1.2 || cape.positions[t[2]].y() < 1.2) continue;
    mesh::Triangle kept;
    for (std::size_t c = 0; c < 3; ++c) {
      if (index[t[c]] == UINT32_MAX) {
        index[t[c]] = static_cast<std::uint32_t>(positions.size());
        positions.push_back(cape.positions[t[c]]);
      }
      kept[c] = index[t[c]];
    }
    top.push_back(kept);
  }
  const std::string path = dir / "shoulders.obj";
  formats::writeObj(path, positions, top, "the cape from the shoulders up (m)");
  return path;
}

TEST(AvatarMeshes, ACharacterFileWithItsClothesCollidesTheClothWithTheBodyAlone) {
  // CesiumMan with a cape, his skin 1 cm out, in the same file and skin. Worn as a garment
  // from that file, the cape collides with the body its meshes field names and starts
  // outside its offset surfaces (T2 = 6 mm); with every mesh of the skin taken for the body,
  // the cape collides with itself as a body and starts inside them everywhere.
  ScratchDir dir("avatar-meshes");
  const std::string clothed = testing::clothedCesiumMan(dir / "clothed", {.offset_m = 0.01});
  const std::string mask = shouldersMask(clothed, dir);
  auto make = [&](const std::string& options, const std::string& out) {
    return runDrape("make-scene '" + clothed + "' --garment '" + clothed + "' --garment-parts Cape --mask '" + mask +
                        "' --name cape --offsets 0.002,0.004,0.006,0.012 " + options + " --out '" + (dir / out) + "'",
                    dir);
  };
  auto run = [&](const std::string& out) {
    const CliResult ran = runDrape("run '" + (dir / out) + "/scene.wrl' --motion '" + clothed + "' --frames 3 --out '" +
                                       (dir / out) + "/run'",
                                   dir);
    EXPECT_EQ(ran.code, 0) << ran.err;
    return statsOf(dir / out + "/run");
  };
  const CliResult body = make("--avatar-meshes Body", "body");
  ASSERT_EQ(body.code, 0) << body.err;
  EXPECT_NE(testing::slurp(dir / "body/scene.wrl").find("  meshes [ \"Body\" ]\n"), std::string::npos);
  EXPECT_NE(body.out.find(clothed + ": the body is Body of its meshes Body, Cape\n"), std::string::npos) << body.out;
  const CliResult inspected = runDrape("inspect '" + (dir / "body/scene.wrl") + "'", dir);
  EXPECT_NE(inspected.out.find(", its body the meshes Body"), std::string::npos) << inspected.out;
  EXPECT_NE(inspected.out.find("its skin moves 2 meshes (Body, Cape); the body is Body\n"), std::string::npos)
      << inspected.out;
  const nlohmann::json alone = run("body");
  EXPECT_LT(alone.at("pairs_embedded_at_start").get<int>(), 20);
  EXPECT_EQ(alone.at("vertex_substeps_below_T1").get<long>(), 0);
  EXPECT_EQ(alone.at("vertex_substeps_inside_body").get<long>(), 0);

  const CliResult all = make("", "all");
  ASSERT_EQ(all.code, 0) << all.err;
  EXPECT_EQ(testing::slurp(dir / "all/scene.wrl").find("  meshes ["), std::string::npos);
  EXPECT_NE(all.out.find(clothed + ": the body is every mesh of its skin (Body, Cape); --avatar-meshes chooses"),
            std::string::npos)
      << all.out;
  EXPECT_GT(run("all").at("pairs_embedded_at_start").get<int>(), 1000);
}

TEST(AvatarMeshes, DrawnMeshesMoveWithTheSkinAndTheClothNeverMeetsThem) {
  // The cape drawn with the body, as hair or eyes would be, and worn as before: the cloth
  // collides with the body alone, and the run writes the drawn cape skinned frame by frame,
  // 1 cm out of the body as the file has it, without fitting it to the parts.
  ScratchDir dir("avatar-drawn-meshes");
  const std::string clothed = testing::clothedCesiumMan(dir / "clothed", {.offset_m = 0.01});
  const std::string mask = shouldersMask(clothed, dir);
  const CliResult made = runDrape("make-scene '" + clothed + "' --garment '" + clothed + "' --garment-parts Cape --mask '" +
                                      mask + "' --name cape --offsets 0.002,0.004,0.006,0.012 --avatar-meshes Body "
                                      "--avatar-drawn-meshes Cape --out '" + (dir / "scene") + "'",
                                  dir);
  ASSERT_EQ(made.code, 0) << made.err;
  EXPECT_NE(testing::slurp(dir / "scene/scene.wrl").find("  meshes [ \"Body\" ]\n  drawnMeshes [ \"Cape\" ]\n"),
            std::string::npos);
  EXPECT_NE(made.out.find(clothed + ": Cape drawn with the body, not collided with\n"), std::string::npos) << made.out;
  const CliResult inspected = runDrape("inspect '" + (dir / "scene/scene.wrl") + "'", dir);
  EXPECT_NE(inspected.out.find(", its body the meshes Body, drawn with it the meshes Cape"), std::string::npos)
      << inspected.out;
  EXPECT_NE(inspected.out.find("    drawn with it, not collided with: Cape (4672 triangles)\n"), std::string::npos)
      << inspected.out;

  const std::string run = dir / "scene/run";
  const CliResult ran =
      runDrape("run '" + (dir / "scene/scene.wrl") + "' --motion '" + clothed + "' --frames 6 --out '" + run + "'", dir);
  ASSERT_EQ(ran.code, 0) << ran.err;
  const nlohmann::json stats = statsOf(run);
  EXPECT_LT(stats.at("pairs_embedded_at_start").get<int>(), 20);
  EXPECT_EQ(stats.at("vertex_substeps_inside_body").get<long>(), 0);

  const formats::RunManifest manifest = formats::readRunManifest(run);
  const auto drawn = std::find_if(manifest.meshes.begin(), manifest.meshes.end(),
                                  [](const formats::RunMesh& m) { return m.role == "drawn"; });
  ASSERT_NE(drawn, manifest.meshes.end());
  EXPECT_EQ(formats::readObj(run + "/" + drawn->topology).triangleCount(), 4672u);
  const formats::Pc2Cache cape = formats::readPc2(run + "/" + drawn->cache);
  const formats::Pc2Cache body = formats::readPc2(run + "/body.pc2");
  ASSERT_EQ(cape.frames.size(), static_cast<std::size_t>(manifest.frames));
  ASSERT_EQ(cape.pointCount, body.pointCount);
  // Vertex i of the cape is vertex i of the body pushed 1 cm out at rest and skinned by the
  // same weights, so it stays within 1 cm of it (rotations blended shorten the offset a
  // little); the body's skin is fitted to the parts near the joints, which moves it by
  // millimetres. And the cape walks: its last frame is not its first.
  for (const std::size_t f : {std::size_t{0}, cape.frames.size() - 1}) {
    std::vector<double> apart;
    for (std::size_t i = 0; i < cape.pointCount; ++i) apart.push_back((cape.frames[f][i] - body.frames[f][i]).norm());
    std::nth_element(apart.begin(), apart.begin() + static_cast<long>(apart.size() / 2), apart.end());
    EXPECT_NEAR(apart[apart.size() / 2], 0.01, 0.002) << "frame " << f;
  }
  double moved = 0.0;
  for (std::size_t i = 0; i < cape.pointCount; ++i)
    moved = std::max(moved, (cape.frames.back()[i] - cape.frames.front()[i]).norm());
  EXPECT_GT(moved, 0.02);
  // Exported with --body skin, the file carries the body and the drawn cape as the players
  // draw them, frame by frame, and no part; by default, the parts and neither of them.
  const CliResult exported = runDrape("export '" + run + "' --body skin --glb '" + (dir / "skin.glb") + "'", dir);
  ASSERT_EQ(exported.code, 0) << exported.err;
  ASSERT_EQ(runDrape("export '" + run + "' --glb '" + (dir / "parts.glb") + "'", dir).code, 0);
  const auto nodeNames = [](const tinygltf::Model& model) {
    std::vector<std::string> names;
    for (const tinygltf::Node& n : model.nodes) names.push_back(n.name);
    return names;
  };
  if (std::filesystem::exists(std::string(DRAPE_SOURCE_DIR) + "/tools/gltf-validator/node_modules/gltf-validator")) {
    const std::string report = dir / "validator.json";
    (void)std::system(("node '" + std::string(DRAPE_SOURCE_DIR) + "/tools/gltf-validator/validate.js' '" +
                       (dir / "skin.glb") + "' >'" + report + "' 2>&1")
                          .c_str());
    EXPECT_NE(testing::slurp(report).find("\"errors\":0"), std::string::npos) << testing::slurp(report);
  }
  const tinygltf::Model skin = loadGlb(dir / "skin.glb");
  EXPECT_EQ(nodeNames(skin), (std::vector<std::string>{"cape", "body", "drawn"}));
  EXPECT_EQ(nodeNames(loadGlb(dir / "parts.glb")).size(), 1 + manifest.meshes.size() - 3) << "the cape and every part";
  const tinygltf::Primitive& drawnPrimitive = skin.meshes.at(static_cast<std::size_t>(skin.nodes[2].mesh)).primitives[0];
  ASSERT_EQ(drawnPrimitive.targets.size(), cape.frames.size() - 1);
  std::vector<float> last = testing::accessorData<float>(skin, drawnPrimitive.attributes.at("POSITION"));
  const std::vector<float> delta = testing::accessorData<float>(skin, drawnPrimitive.targets.back().at("POSITION"));
  for (std::size_t i = 0; i < last.size(); ++i) last[i] += delta[i];
  for (std::size_t v = 0; v < cape.pointCount; ++v)
    for (std::size_t k = 0; k < 3; ++k) ASSERT_NEAR(last[3 * v + k], cape.frames.back()[v][static_cast<Eigen::Index>(k)], 1e-5);

  const CliResult listed = runDrape("inspect '" + run + "'", dir);
  EXPECT_NE(listed.out.find("  drawn    drawn          3273 vertices, 4672 triangles (skinned with the body, not "
                            "collided with)\n"),
            std::string::npos)
      << listed.out;

  // A mesh drawn and the body's both is refused: with no meshes named, the body is all of them.
  const CliResult twice = runDrape("run --garment '" + clothed + "' --avatar '" + clothed +
                                       "' --avatar-drawn-meshes Cape --frames 1 --out '" + (dir / "twice") + "'",
                                   dir);
  EXPECT_EQ(twice.code, 2);
  EXPECT_NE(twice.err.find(clothed + ": drawnMeshes (Cape) name Cape, which is the body's: a mesh is drawn or makes the "
                           "body, not both (the body is every mesh of its skin unless meshes names those that make "
                           "it; its skinned meshes: Body, Cape)"),
            std::string::npos)
      << twice.err;
}

TEST(AvatarMeshes, TheLivePlayerDrawsTheDrawnMeshesOverTheSkin) {
  // drape play simulates and draws through its own path (cli::ShownBodies): a skirt on the
  // body, and the cape drawn over it darkens the character's pixels against the same scene
  // without it.
  if (std::system("command -v xvfb-run >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed (scripts/install-deps installs xvfb)";
  ScratchDir dir("avatar-drawn-play");
  const std::string clothed = testing::clothedCesiumMan(dir / "clothed", {.offset_m = 0.01});
  auto shot = [&](const std::string& drawn, const std::string& name) {
    const CliResult made =
        runDrape("make-skirt '" + clothed + "' --avatar-meshes Body " + drawn + " --out '" + (dir / name) + "'", dir);
    EXPECT_EQ(made.code, 0) << made.err;
    const std::string png = dir / (name + ".png");
    const CliResult played = runDrape("play '" + (dir / name) + "/scene.wrl' --frames 3 --fast --size 320x240 "
                                      "--screenshot '" + png + "'",
                                      dir, "xvfb-run -a ");
    EXPECT_EQ(played.code, 0) << played.out << played.err;
    return render::readPng(png);
  };
  const render::Image with = shot("--avatar-drawn-meshes Cape", "with"), without = shot("", "without");
  ASSERT_EQ(with.rgb.size(), without.rgb.size());
  long darker = 0, brighter = 0;
  for (int y = 0; y < with.height; ++y)
    for (int x = 0; x < with.width; ++x) {
      const int a = with.pixel(x, y)[0] + with.pixel(x, y)[1] + with.pixel(x, y)[2];
      const int b = without.pixel(x, y)[0] + without.pixel(x, y)[1] + without.pixel(x, y)[2];
      darker += a + 60 < b;
      brighter += a > b + 60;
    }
  EXPECT_GT(darker, 1500) << "the drawn cape does not show";  // 4,710 measured
  EXPECT_LT(brighter, darker / 5);
}

TEST(AvatarMeshes, ConvertWritesTheMeshesChosen) {
  ScratchDir dir("avatar-meshes-convert");
  const std::string clothed = testing::clothedCesiumMan(dir / "clothed");
  const CliResult body = runDrape("convert '" + clothed + "' --avatar-meshes Body --to '" + (dir / "body.dae") + "'", dir);
  ASSERT_EQ(body.code, 0) << body.err;
  const CliResult inspected = runDrape("inspect '" + (dir / "body.dae") + "'", dir);
  ASSERT_EQ(inspected.code, 0) << inspected.err;
  EXPECT_NE(inspected.out.find(" vertices, 4672 triangles, height 1.507 m\n"), std::string::npos) << inspected.out;
  EXPECT_EQ(inspected.out.find("  meshes "), std::string::npos) << inspected.out;
}

TEST(AvatarMeshes, InspectListsTheMeshesAndAWrongNameIsRefusedWithThem) {
  ScratchDir dir("avatar-meshes-errors");
  const std::string clothed = testing::clothedCesiumMan(dir / "clothed");
  const CliResult inspected = runDrape("inspect '" + clothed + "'", dir);
  ASSERT_EQ(inspected.code, 0) << inspected.err;
  EXPECT_NE(inspected.out.find("  meshes     2 skinned: Body, Cape (make-scene --avatar-meshes chooses those that make "
                               "the body, --avatar-drawn-meshes those drawn with it)\n"),
            std::string::npos)
      << inspected.out;

  const std::string garment = std::string(DRAPE_DATA_DIR) + "/garments/makehuman_female_elegantsuit01_dress.obj";
  const std::string mask = std::string(DRAPE_SOURCE_DIR) + "/examples/hanging_dress/shoulders_mask.obj";
  const CliResult hair = runDrape("make-scene '" + clothed + "' --avatar-meshes Body,Hair --garment '" + clothed +
                                      "' --garment-parts Cape --mask '" + clothed + "' --out '" + (dir / "hair") + "'",
                                  dir);
  EXPECT_EQ(hair.code, 2);
  EXPECT_NE(hair.err.find(clothed + ": has no node or mesh named 'Hair' (its skinned meshes: Body, Cape)"), std::string::npos)
      << hair.err;
  const std::string makehuman = std::string(DRAPE_SOURCE_DIR) + "/data/avatars/makehuman_rig_cmu_mb.mhskel";
  const CliResult one = runDrape("make-scene '" + makehuman + "' --avatar-meshes Body --garment '" + garment +
                                     "' --units dm --mask '" + mask + "' --out '" + (dir / "one") + "'",
                                 dir);
  EXPECT_EQ(one.code, 2);
  EXPECT_NE(one.err.find("makehuman_rig_cmu_mb.mhskel: meshes (Body) choose among the skinned meshes of a glTF, Collada "
                         "or FBX avatar; a MakeHuman avatar is one body"),
            std::string::npos)
      << one.err;
  const CliResult ran = runDrape("run '" + std::string(DRAPE_SOURCE_DIR) + "/examples/walking_skirt/scene.wrl' "
                                 "--avatar-meshes Body --frames 1 --out '" + (dir / "run") + "'",
                                 dir);
  EXPECT_EQ(ran.code, 2);
  EXPECT_NE(ran.err.find("--avatar-meshes chooses the meshes of --avatar FILE; in a scene the Avatar node's meshes field "
                         "does"),
            std::string::npos)
      << ran.err;
}

}  // namespace
}  // namespace drape
