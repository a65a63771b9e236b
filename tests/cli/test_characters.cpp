// Several characters in one scene, end to end: each simulated in a world of its own, so that
// a character's files in the run directory are, to the byte, what the scene of that character
// alone writes; the run directory says whose each part, skin and garment is, and what plays
// one character only says so (the studio's roles are each given theirs: test_studio.cpp).

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/pc2.hpp"
#include "drape/formats/run_manifest.hpp"
#include "drape/mesh/surface_distance.hpp"

namespace drape {
namespace {

using testing::CliResult;
using testing::kSkirtDir;
using testing::kTwoCharacters;
using testing::runDrape;
using testing::ScratchDir;
using testing::slurp;
using testing::statsOf;
using testing::twoCharactersWithBeaAt;

namespace fs = std::filesystem;

const std::string kDelfem2Walk = std::string(DRAPE_DATA_DIR) + "/mocap/cmu_walk_delfem2.bvh";
constexpr int kCharacterFrames = 40;

/// The walking skirt's scene with its avatar and skirt moved `dx` m along x, as the two
/// characters' scene places Bea, written into `dir`.
std::string skirtSceneMoved(const ScratchDir& dir, const std::string& name, double dx) {
  std::string text = slurp(kSkirtDir + "/scene.wrl");
  const std::string relative = "url \"../../data/", body = "DEF Body Avatar";
  text.replace(text.find(relative), relative.size(), "url \"" + std::string(DRAPE_SOURCE_DIR) + "/data/");
  const std::size_t from = text.find(body);
  text.insert(from, "Transform {\n  translation " + std::to_string(dx) + " 0 0\n  children [\n");
  text += "  ]\n}\n";
  const std::string path = dir / name;
  std::ofstream(path) << text;
  return path;
}

bool sameFile(const std::string& a, const std::string& b) {
  return fs::exists(a) && fs::exists(b) && slurp(a) == slurp(b);
}

/// `drape ARGS` must refuse its input (exit code 2) with `message` on standard error.
void expectRefused(const std::string& args, const std::string& message, const ScratchDir& dir) {
  const CliResult r = runDrape(args, dir);
  EXPECT_EQ(r.code, 2) << args << "\n" << r.err;
  EXPECT_NE(r.err.find(message), std::string::npos) << args << "\n" << r.err;
}

TEST(Characters, EachCharacterOfTheSceneIsWhatItsSceneAloneMakesToTheByte) {
  ScratchDir dir("characters");
  const std::string both = dir / "both";
  const std::string frames = " --frames " + std::to_string(kCharacterFrames);
  const CliResult r = runDrape("run '" + kTwoCharacters + "'" + frames + " --out '" + both + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  // Each plays the motion its Avatar node names.
  EXPECT_NE(r.err.find("walk.bvh: 566 frames at 120 Hz in CMU units (0.0564 m); joint map 'motionbuilder' drives 31 of "
                       "Ada's 31 joints"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("cmu_walk_delfem2.bvh: 344 frames at 120 Hz in CMU units (0.0564 m); joint map 'motionbuilder' "
                       "drives 31 of Bea's 31 joints"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.out.find("the skinned bodies (body-CHARACTER.pc2)"), std::string::npos) << r.out;

  // Ada stands where the walking skirt's body stands and walks its walk; Bea, 1.2 m along x,
  // the other walk. Alone in their scenes, each writes what the scene of two wrote for it.
  const std::string ada = dir / "ada";
  ASSERT_EQ(runDrape("run '" + kSkirtDir + "/scene.wrl' --motion '" + kSkirtDir + "/walk.bvh'" + frames + " --out '" +
                         ada + "'",
                     dir)
                .code,
            0);
  const std::string bea = dir / "bea";
  const CliResult alone = runDrape("run '" + skirtSceneMoved(dir, "bea.wrl", 1.2) + "' --motion '" + kDelfem2Walk +
                                       "'" + frames + " --out '" + bea + "'",
                                   dir);
  ASSERT_EQ(alone.code, 0) << alone.err;
  for (const auto& [who, single] : {std::pair{std::string("Ada"), ada}, std::pair{std::string("Bea"), bea}}) {
    SCOPED_TRACE(who);
    EXPECT_TRUE(sameFile(both + "/garment-" + who + "_skirt.pc2", single + "/garment.pc2"));
    EXPECT_TRUE(sameFile(both + "/garment-" + who + "_skirt.states", single + "/garment.states"));
    EXPECT_TRUE(sameFile(both + "/body-" + who + ".pc2", single + "/body.pc2"));
    for (const char* part : {"Hips", "LeftUpLeg", "RightLeg", "LeftForeArm"})
      EXPECT_TRUE(sameFile(both + "/segments/" + who + "/" + part + ".pc2", single + "/segments/" + part + ".pc2"))
          << part;
  }
  EXPECT_FALSE(sameFile(both + "/garment-Ada_skirt.pc2", both + "/garment-Bea_skirt.pc2"));

  // The manifest names whose each mesh is; stats.json lists the characters.
  const formats::RunManifest manifest = formats::readRunManifest(both);
  int skins = 0, segments = 0;
  for (const formats::RunMesh& m : manifest.meshes) {
    EXPECT_TRUE(m.character == "Ada" || m.character == "Bea") << m.name;
    if (m.role == "garment") {
      EXPECT_EQ(m.name, m.character + " skirt");
    }
    skins += m.role == "skin";
    segments += m.role == "segment";
  }
  EXPECT_EQ(skins, 2);
  EXPECT_EQ(segments, 2 * 31);
  const nlohmann::json stats = statsOf(both);
  ASSERT_EQ(stats["characters"].size(), 2u);
  EXPECT_EQ(stats["characters"][1]["name"], "Bea");
  EXPECT_EQ(stats["characters"][1]["garments"], nlohmann::json::array({"Bea skirt"}));
  EXPECT_EQ(stats["vertex_substeps_inside_body"], 0);
  EXPECT_EQ(stats["vertex_substeps"].get<long>(),
            statsOf(ada)["vertex_substeps"].get<long>() + statsOf(bea)["vertex_substeps"].get<long>());

  // inspect measures each garment against the body that wears it: Bea's skirt is as deep in
  // Bea's skin as in the run of Bea alone (measured against Ada's, it would be a metre out).
  const CliResult deepBoth = runDrape("inspect '" + both + "' --deepest 1 --garment 'Bea skirt'", dir);
  const CliResult deepBea = runDrape("inspect '" + bea + "' --deepest 1", dir);
  ASSERT_EQ(deepBoth.code, 0) << deepBoth.err;
  ASSERT_EQ(deepBea.code, 0) << deepBea.err;
  EXPECT_NE(deepBoth.out.find("worn by Bea"), std::string::npos) << deepBoth.out;
  const auto deepestLine = [](const std::string& out) {
    const std::size_t header = out.find("\ngarment ");
    const std::size_t line = out.find('\n', out.find('\n', header + 1) + 1);
    return out.substr(line + 1, out.find('\n', line + 1) - line - 1);
  };
  // The line after the garment's name: vertex, frame, time code, state, skin, parts.
  const auto afterName = [](const std::string& line, const std::string& name) {
    const std::size_t from = line.find_first_not_of(' ', line.find(name) + name.size());
    return from == std::string::npos ? std::string() : line.substr(from);
  };
  const std::string a = afterName(deepestLine(deepBoth.out), "Bea skirt"), b = afterName(deepestLine(deepBea.out), "Skirt");
  ASSERT_FALSE(b.empty()) << deepBea.out;
  EXPECT_EQ(a, b) << deepBoth.out << deepBea.out;
}

TEST(Characters, TwoCapturesMoveTheirCharactersAsEachMovesItsSceneAlone) {
  // Each character's capture read as it comes (here from files, as a named pipe would give
  // them): each character's files are those of its scene alone on its capture, to the byte.
  ScratchDir dir("characters-live");
  const std::string frames = " --frames 45";  // the lead-in's 30, then 15 of the captures
  const std::string walk = kSkirtDir + "/walk.bvh";
  const std::string both = dir / "both", ada = dir / "ada", bea = dir / "bea";
  const CliResult r = runDrape("run '" + kTwoCharacters + "' --live 'Ada=" + walk + "' --live 'Bea=" + kDelfem2Walk +
                                   "'" + frames + " --out '" + both + "'",
                               dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("live: 17 motion frames of Ada from " + walk), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("live: 17 motion frames of Bea from " + kDelfem2Walk), std::string::npos) << r.out;
  ASSERT_EQ(runDrape("run '" + kSkirtDir + "/scene.wrl' --live '" + walk + "'" + frames + " --out '" + ada + "'", dir).code,
            0);
  ASSERT_EQ(runDrape("run '" + skirtSceneMoved(dir, "bea.wrl", 1.2) + "' --live '" + kDelfem2Walk + "'" + frames +
                         " --out '" + bea + "'",
                     dir)
                .code,
            0);
  for (const auto& [who, single] : {std::pair{std::string("Ada"), ada}, std::pair{std::string("Bea"), bea}}) {
    SCOPED_TRACE(who);
    EXPECT_TRUE(sameFile(both + "/garment-" + who + "_skirt.pc2", single + "/garment.pc2"));
    EXPECT_TRUE(sameFile(both + "/body-" + who + ".pc2", single + "/body.pc2"));
    EXPECT_TRUE(sameFile(both + "/segments/" + who + "/LeftUpLeg.pc2", single + "/segments/LeftUpLeg.pc2"));
  }

  // A capture for one of them: the other plays what her Avatar node names.
  const CliResult one = runDrape("run '" + kTwoCharacters + "' --live 'Bea=" + kDelfem2Walk + "' --frames 2 --out '" +
                                     (dir / "one") + "'",
                                 dir);
  ASSERT_EQ(one.code, 0) << one.err;
  EXPECT_NE(one.err.find("walk.bvh: 566 frames at 120 Hz"), std::string::npos) << one.err;
  EXPECT_NE(one.out.find("live: "), std::string::npos) << one.out;

  const std::string out = " --out '" + (dir / "x") + "'";
  const auto expectError = [&](const std::string& args, const std::string& message) { expectRefused(args, message, dir); };
  expectError("run '" + kTwoCharacters + "' --live '" + walk + "'" + out,
              "--live " + walk + ": the scene has 2 characters (Ada, Bea): say which the capture moves, --live NAME=SOURCE");
  expectError("run '" + kTwoCharacters + "' --live Ada=- --live Bea=-" + out,
              "--live: standard input (-) is one source; give the others theirs");
  expectError("run '" + kTwoCharacters + "' --live 'Ada=" + walk + "' --live Ada=-" + out,
              "--live Ada=-: Ada has a source already (" + walk + ")");
}

/// The deepest any vertex of each of `garments` (PC2 files) goes into the parts `parts` (OBJ and
/// PC2 stems) of run `bodyRun`, over its frames from `from` on (m, signed: negative is inside).
std::vector<double> deepestInto(const std::vector<std::string>& garments, const std::string& bodyRun,
                                const std::vector<std::string>& parts, std::size_t from) {
  std::vector<formats::Pc2Cache> cloth;
  for (const std::string& g : garments) cloth.push_back(formats::readPc2(g));
  std::vector<double> deepest(garments.size(), std::numeric_limits<double>::infinity());
  for (const std::string& part : parts) {
    const mesh::TriMesh rest = formats::readObj(bodyRun + "/" + part + ".obj");
    const formats::Pc2Cache moving = formats::readPc2(bodyRun + "/" + part + ".pc2");
    for (std::size_t f = from; f < moving.frames.size(); ++f) {
      const mesh::SurfaceDistance body(moving.frames[f], rest.triangles);
      for (std::size_t g = 0; g < cloth.size(); ++g)
        if (f < cloth[g].frames.size())
          for (const Vec3& p : cloth[g].frames[f]) deepest[g] = std::min(deepest[g], body.at(p).distance_m);
    }
  }
  return deepest;
}

TEST(Characters, ASkirtBrushingPastAnotherCharacterStaysOutOfHerLegs) {
  // Bea stands two metres ahead of Ada and half a metre to her side, and Ada walks past her: alone
  // in its scene, Ada's skirt sweeps through where Bea's legs stand; with Bea in the scene it
  // collides with them too (sim::Guest), as with Ada's own.
  ScratchDir dir("characters-contact");
  const std::string scene = twoCharactersWithBeaAt(dir, "0.5 0 2");
  const std::string walk = kSkirtDir + "/walk.bvh", frames = " --frames 130";
  const std::string close = dir / "close", ada = dir / "ada";
  const CliResult r =
      runDrape("run '" + scene + "' --motion 'Ada=" + walk + "' --motion Bea=none" + frames + " --out '" + close + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_EQ(runDrape("run '" + kSkirtDir + "/scene.wrl' --motion '" + walk + "'" + frames + " --out '" + ada + "'", dir).code,
            0);
  const std::vector<std::string> beasLegs{"segments/Bea/LeftUpLeg", "segments/Bea/RightUpLeg", "segments/Bea/LeftLeg",
                                          "segments/Bea/RightLeg", "segments/Bea/Hips"};
  // From frame 80 on: Ada comes within her skirt's reach of Bea at about frame 95.
  const std::vector<double> deepest =
      deepestInto({ada + "/garment.pc2", close + "/garment-Ada_skirt.pc2"}, close, beasLegs, 80);
  const double alone = deepest[0], together = deepest[1];
  EXPECT_LT(alone, -0.005) << "Ada's skirt alone was to go into Bea's legs (15 mm deep on 2026-12-04)";
  EXPECT_GT(together, 0.0) << "deepest " << together << " m into Bea's legs (on T2, 15 mm out, on 2026-12-04)";
  EXPECT_EQ(statsOf(close)["vertex_substeps_inside_body"], 0);
}

TEST(Characters, MotionsAreGivenByNameAndWhatPlaysOneCharacterSaysSo) {
  ScratchDir dir("characters-errors");
  const std::string out = " --out '" + (dir / "x") + "'";
  const auto expectError = [&](const std::string& args, const std::string& message) { expectRefused(args, message, dir); };
  expectError("run '" + kTwoCharacters + "' --motion 'Carl=" + kDelfem2Walk + "'" + out,
              "--motion Carl=" + kDelfem2Walk + ": the scene has no character called 'Carl' (it has: Ada, Bea)");
  expectError("run '" + kTwoCharacters + "' --motion 'Ada=" + kDelfem2Walk + "' --motion 'Ada=none'" + out,
              "--motion Ada=none: 'Ada' is given a motion twice");
  expectError("run '" + kTwoCharacters + "' --motion '" + kDelfem2Walk + "' --motion none" + out,
              "--motion none: a motion for every character is given already");
  // An event graph of one character's Plays, on a scene of two.
  expectError("run '" + kTwoCharacters + "' --events '" + std::string(DRAPE_SOURCE_DIR) + "/examples/event_graph/day.egml'" + out,
              "day.egml:14: Play: the scene has 2 characters (Ada, Bea): say which it moves (character \"NAME\", here "
              "or on an event above it)");
  expectError("anim-server '" + kTwoCharacters + "' --server nats://127.0.0.1:1 --give-up 1",
              "the scene has 2 characters (Ada, Bea), and a studio role plays one: give --character NAME");
  expectError("anim-server '" + kTwoCharacters + "' --character Carl --server nats://127.0.0.1:1 --give-up 1",
              "--character Carl: the scene has no character called 'Carl' (it has: Ada, Bea)");

  // NAME=FILE for one, FILE for the others: Ada plays the file for all, Bea her own; none
  // keeps one at rest.
  const CliResult r = runDrape("run '" + kTwoCharacters + "' --motion '" + kDelfem2Walk + "' --motion Bea=none --frames 2" + out, dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("drives 31 of Ada's 31 joints"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("Bea's 31 joints"), std::string::npos) << r.err;

  // A garment among several avatars says which wears it.
  std::string text = slurp(kTwoCharacters);
  const std::string worn = "      avatar USE Bea\n";
  text.erase(text.find(worn), worn.size());
  text.replace(text.find("url \"../../data/"), 16, "url \"" + std::string(DRAPE_SOURCE_DIR) + "/data/");
  text.replace(text.find("url \"../../data/"), 16, "url \"" + std::string(DRAPE_SOURCE_DIR) + "/data/");
  std::ofstream(dir / "unworn.wrl") << text;
  expectError("run '" + (dir / "unworn.wrl") + "' --motion none --frames 2" + out,
              "ClothSet 'Bea skirt': the scene has 2 avatars (Ada, Bea); say which wears it (avatar USE NAME)");
}

}  // namespace
}  // namespace drape
