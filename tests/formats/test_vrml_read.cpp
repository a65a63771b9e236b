// The VRML97 reader: pre-scan, Coin in a child process, hand-over; real files from data/,
// the malformed corpus in tests/data/bad, and the writer's round trip.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "drape/core/error.hpp"
#include "drape/formats/vrml_read.hpp"
#include "drape/formats/vrml_scan.hpp"
#include "drape/formats/vrml_write.hpp"
#include "drape/testing/errors.hpp"
#include "drape/testing/temp_dir.hpp"

namespace drape::formats::vrml {
namespace {

const std::string kData = std::string(DRAPE_DATA_DIR) + "/vrml/";

int count(const Document& d, const std::string& type) {
  int n = 0;
  for (const Node& node : d.nodes) n += node.type == type ? 1 : 0;
  return n;
}

using drape::testing::errorOf;

std::string tempDir() {
  return drape::testing::processTempDir("vrml").string();
}

TEST(VrmlRead, Sr1HasThirtyJointsAndSegments) {
  const Document d = readFile(kData + "choreonoid_SR1.wrl");
  EXPECT_EQ(count(d, "Joint"), 30);
  EXPECT_EQ(count(d, "Segment"), 30);
  EXPECT_EQ(count(d, "Humanoid"), 1);
  // The file declares its own Joint with choreonoid's extra fields: those are the ones read.
  const Node* waist = nullptr;
  for (const Node& n : d.nodes)
    if (n.def == "WAIST") waist = &n;
  ASSERT_NE(waist, nullptr);
  ASSERT_NE(waist->field("jointType"), nullptr);
  EXPECT_EQ(waist->field("jointType")->strings.at(0), "free");
  EXPECT_NEAR(waist->field("translation")->numbers.at(2), 0.7135, 1e-6);
}

TEST(VrmlRead, Gr001ReadsItsSegmentsThroughInline) {
  const Document d = readFile(kData + "choreonoid_GR001/GR001.wrl");
  EXPECT_EQ(count(d, "Joint"), 21);
  EXPECT_EQ(count(d, "Segment"), 21);
  int loaded = 0;
  for (const Node& n : d.nodes)
    if (n.type == "Inline" && n.inlined >= 0) {
      ++loaded;
      EXPECT_NE(d.nodes[static_cast<std::size_t>(n.inlined)].file.find("/parts/"), std::string::npos);
    }
  EXPECT_EQ(loaded, 21);
}

TEST(VrmlRead, TorusKeepsItsRoutesAndVaseItsFaceSet) {
  const Document torus = readFile(kData + "choreonoid_Torus.wrl");
  EXPECT_EQ(count(torus, "Extrusion"), 1);
  const Document vase = readFile(kData + "choreonoid_vase.wrl");
  ASSERT_EQ(count(vase, "IndexedFaceSet"), 1);
  for (const Node& n : vase.nodes) {
    if (n.type != "IndexedFaceSet") continue;
    EXPECT_TRUE(n.hasMesh);
    EXPECT_EQ(n.triangles.size(), 2592u);
    EXPECT_EQ(
        n.positions.size(),
        vase.nodes.at(static_cast<std::size_t>(n.field("coord")->nodes.at(0))).field("point")->numbers.size() / 3);
    ASSERT_NE(n.field("normal"), nullptr);
    EXPECT_GE(n.field("normal")->nodes.at(0), 0);
  }
}

TEST(VrmlRead, EveryFileUnderDataVrmlLoads) {
  int files = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(kData)) {
    if (e.path().extension() != ".wrl") continue;
    ++files;
    EXPECT_NO_THROW((void)readFile(e.path().string())) << e.path();
  }
  EXPECT_EQ(files, 3 + 1 + 21);
}

TEST(VrmlRead, MalformedCorpusGivesTheExpectedMessageAndLine) {
  const std::string dir = std::string(DRAPE_TEST_DATA_DIR) + "/bad/";
  std::ifstream expected(dir + "EXPECTED.txt");
  ASSERT_TRUE(expected);
  std::string line;
  int cases = 0;
  while (std::getline(expected, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::stringstream s(line);
    std::string file, lineNo, text;
    std::getline(s, file, '|');
    std::getline(s, lineNo, '|');
    std::getline(s, text);
    const auto trim = [](std::string v) {
      v.erase(0, v.find_first_not_of(' '));
      v.erase(v.find_last_not_of(' ') + 1);
      return v;
    };
    file = trim(file);
    text = trim(text);
    const int expectedLine = std::stoi(trim(lineNo));
    if (file.rfind("clothset", 0) == 0 || file.rfind("negative", 0) == 0 || file.rfind("poisson", 0) == 0 ||
        file.rfind("mask", 0) == 0 || file.rfind("simulation", 0) == 0)
      continue;  // domain errors: tests/scene checks these
    ++cases;
    const std::string message = errorOf([&] { (void)readFile(dir + file); });
    EXPECT_NE(message.find(text), std::string::npos) << file << ": " << message;
    const std::string prefix =
        expectedLine > 0 ? dir + file + ":" + std::to_string(expectedLine) + ":" : dir + file + ": ";
    EXPECT_EQ(message.rfind(prefix, 0), 0u) << file << ": " << message;
  }
  EXPECT_GE(cases, 14);
}

// The two inputs that crash or hang Coin itself are stopped before Coin sees them.
TEST(VrmlRead, CoinNullDereferenceUseInsideOwnDefIsAScanError) {
  const std::string text = "#VRML V2.0 utf8\nDEF T Transform { children Shape { geometry USE T\n";
  ASSERT_EQ(text.size(), 66u);
  const std::string message = errorOf([&] { (void)readText(text, "crash.wrl", "."); });
  EXPECT_EQ(message, "crash.wrl:2:49: USE T inside its own DEF T (a node cannot contain itself)");
}

TEST(VrmlRead, CoinHangOn3dsBytesIsAScanError) {
  const std::string text("MM\x02\x00", 4);
  EXPECT_NE(errorOf([&] { (void)readText(text, "hang.wrl", "."); }).find("hang.wrl:1:1: not a VRML97 file"),
            std::string::npos);
}

// Without the pre-scan the same inputs reach Coin: its null dereference and its hang stay
// inside the reader's child process and come back as errors.
TEST(VrmlRead, CoinsOwnCrashAndHangStayInTheChild) {
  ReadOptions raw;
  raw.prescan = false;
  raw.limits.seconds = 3.0;
  const std::string crash = "#VRML V2.0 utf8\nDEF T Transform { children Shape { geometry USE T\n";
  const std::string crashMessage = errorOf([&] { (void)readText(crash, "crash.wrl", ".", raw); });
  EXPECT_EQ(crashMessage.rfind("crash.wrl: the VRML97 reader failed (signal ", 0), 0u) << crashMessage;
  const std::string recursive = "#VRML V2.0 utf8\nPROTO P [ ] { Group { children P { } } }\nP { }\n";
  const std::string recursiveMessage = errorOf([&] { (void)readText(recursive, "doll.wrl", ".", raw); });
  // A stack overflow: signal 11, or the time limit when the sanitizers make it slow.
  EXPECT_EQ(recursiveMessage.rfind("doll.wrl: the VRML97 reader failed (", 0), 0u) << recursiveMessage;
  const std::string hang("MM\x02\x00", 4);
  const std::string hangMessage = errorOf([&] { (void)readText(hang, "hang.wrl", ".", raw); });
  EXPECT_EQ(hangMessage.rfind("hang.wrl: the VRML97 reader failed (time limit", 0), 0u) << hangMessage;
}

TEST(VrmlRead, PreludeIsTheShippedFile) {
  std::ifstream shipped(std::string(DRAPE_SOURCE_DIR) + "/share/drape/drape-nodes.wrl");
  std::stringstream s;
  s << shipped.rdbuf();
  EXPECT_EQ(s.str(), std::string(prelude()));
  const ScanResult r = scan(prelude(), "drape-nodes.wrl");
  std::vector<std::string> names;
  for (const ProtoInterface& p : r.declared) names.push_back(p.name);
  EXPECT_EQ(names, (std::vector<std::string>{"ClothSet", "ClothMaterial", "Simulation", "Avatar", "Humanoid", "Joint",
                                             "Segment", "Site", "Displacer", "EventGraph", "Sequence", "Parallel",
                                             "Loop", "Parameters", "Condition", "StateMachine", "State", "Wait",
                                             "Play", "Wind", "Path"}));
}

TEST(VrmlRead, ExternProtoToThePreludeLoads) {
  const std::string dir = tempDir();
  std::filesystem::copy_file(std::string(DRAPE_SOURCE_DIR) + "/share/drape/drape-nodes.wrl", dir + "/drape-nodes.wrl",
                             std::filesystem::copy_options::overwrite_existing);
  std::ofstream(dir + "/ext.wrl")
      << "#VRML V2.0 utf8\n"
         "EXTERNPROTO ClothMaterial [ exposedField SFFloat density exposedField SFFloat thickness ]\n"
         "  \"drape-nodes.wrl#ClothMaterial\"\n"
         "DEF Silk ClothMaterial { density 1300 }\n";
  const Document d = readFile(dir + "/ext.wrl");
  ASSERT_EQ(count(d, "ClothMaterial"), 1);
  for (const Node& n : d.nodes)
    if (n.type == "ClothMaterial") {
      EXPECT_EQ(n.def, "Silk");
      EXPECT_DOUBLE_EQ(n.field("density")->numbers.at(0), 1300.0);
      EXPECT_EQ(n.line, 4);
    }
}

TEST(VrmlRead, MissingTextureIsAWarning) {
  const std::string text =
      "#VRML V2.0 utf8\nShape { appearance Appearance { texture ImageTexture { url \"nowhere.png\" } } geometry Box { "
      "} }\n";
  const Document d = readText(text, "tex.wrl", ".");
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_NE(d.warnings[0].find("nowhere.png"), std::string::npos);
}

TEST(VrmlWrite, RoundTripPositionsAtSeveralTimes) {
  Animation a;
  a.frameRate = 25.0;
  GarmentTrack g;
  g.name = "cape 1";
  g.triangles = {{0, 1, 2}, {0, 2, 3}};
  const auto positionAt = [](std::size_t v, double t) {
    return Vec3(0.1 * static_cast<double>(v) + 0.3 * t, std::sin(t + static_cast<double>(v)), -0.2 * t * t);
  };
  const std::size_t frames = 11;
  for (std::size_t f = 0; f < frames; ++f) {
    std::vector<Vec3> p;
    for (std::size_t v = 0; v < 4; ++v) p.push_back(positionAt(v, static_cast<double>(f) / a.frameRate));
    g.frames.push_back(p);
  }
  a.garments.push_back(g);
  JointTrack j;
  j.name = "hip";
  mesh::TriMesh box;
  box.positions = {{0, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}};
  box.triangles = {{0, 1, 2}};
  j.segments.push_back(box);
  for (std::size_t f = 0; f < frames; ++f)
    j.frames.push_back({Quat(Eigen::AngleAxisd(0.1 * static_cast<double>(f), Vec3::UnitY())),
                        Vec3(0, 1, 0.01 * static_cast<double>(f))});
  a.joints.push_back(j);
  const std::string path = tempDir() + "/result.wrl";
  writeAnimation(path, a);

  const Document d = readFile(path);
  std::int32_t coord = -1, hip = -1;
  for (std::size_t i = 0; i < d.nodes.size(); ++i) {
    if (d.nodes[i].def == "cape_1_coord") coord = static_cast<std::int32_t>(i);
    if (d.nodes[i].def == "hip") hip = static_cast<std::int32_t>(i);
  }
  ASSERT_GE(coord, 0);
  ASSERT_GE(hip, 0);
  for (const std::size_t f : {0u, 3u, 7u, 10u}) {
    const double t = static_cast<double>(f) / a.frameRate;
    const std::vector<double> p = sampleAnimatedField(d, coord, "point", t);
    ASSERT_EQ(p.size(), 12u) << t;
    for (std::size_t v = 0; v < 4; ++v)
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(p[v * 3 + static_cast<std::size_t>(c)], positionAt(v, t)[c], 1e-5) << "t " << t;
    const std::vector<double> translation = sampleAnimatedField(d, hip, "translation", t);
    ASSERT_EQ(translation.size(), 3u);
    EXPECT_NEAR(translation[2], 0.01 * static_cast<double>(f), 1e-6);
  }
  // Half-way between frames 3 and 4 the interpolator is linear.
  const double mid = 3.5 / a.frameRate;
  const std::vector<double> p = sampleAnimatedField(d, coord, "point", mid);
  const Vec3 expected = 0.5 * (positionAt(2, 3 / a.frameRate) + positionAt(2, 4 / a.frameRate));
  EXPECT_NEAR(p[6], expected.x(), 1e-5);
  EXPECT_NEAR(p[7], expected.y(), 1e-5);
}

}  // namespace
}  // namespace drape::formats::vrml
