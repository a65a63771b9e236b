// Collada and FBX skinned characters through Assimp: a hand-written two-joint tube checked
// vertex by vertex in metres and Y up, the writer's files read back, and the malformed
// corpus in tests/data/bad/avatar (each an error naming the file, never a crash).

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <unistd.h>

#include "drape/core/error.hpp"
#include "drape/formats/assimp_avatar.hpp"
#include "drape/testing/errors.hpp"

namespace drape::formats {
namespace {

std::string tube() { return std::string(DRAPE_TEST_DATA_DIR) + "/avatars/tube_two_joints.dae"; }
std::string bad(const std::string& f) { return std::string(DRAPE_TEST_DATA_DIR) + "/bad/avatar/" + f; }

using drape::testing::errorOf;

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The tube as the file describes it: ring r (z = 50 r cm), corner c; index 4 r + c.
Vec3 tubeVertexInMetresYUp(int index) {
  const double xs[4] = {-20, 0, 0, -20}, ys[4] = {-10, -10, 10, 10};
  const double x = xs[index % 4] + 10.0;  // the bind shape matrix moves the mesh +10 cm in x
  const double y = ys[index % 4], z = 50.0 * (index / 4);
  return Vec3(x, z, -y) / 100.0;  // Z up -> Y up, centimetres -> metres
}

const std::vector<std::array<int, 3>> kTubeTriangles = {
    {0, 1, 5}, {0, 5, 4}, {1, 2, 6},  {1, 6, 5},  {2, 3, 7},  {2, 7, 6}, {3, 0, 4},  {3, 4, 7},   {4, 5, 9},  {4, 9, 8},
    {5, 6, 10}, {5, 10, 9}, {6, 7, 11}, {6, 11, 10}, {7, 4, 8}, {7, 8, 11}, {0, 2, 1}, {0, 3, 2}, {8, 9, 10}, {8, 10, 11}};

// A triangle's corners rotated so the smallest comes first (winding kept).
std::array<int, 3> canonical(std::array<int, 3> t) {
  std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  return t;
}

// Index of the file's vertex at `p`, or -1.
int tubeVertexAt(const Vec3& p) {
  for (int i = 0; i < 12; ++i)
    if ((tubeVertexInMetresYUp(i) - p).norm() < 1e-6) return i;
  return -1;
}

void expectTheTube(const SkinnedModel& m) {
  ASSERT_EQ(m.joints.size(), 2u);
  EXPECT_EQ(m.joints[0].name, "hip");
  EXPECT_EQ(m.joints[0].parent, -1);
  EXPECT_EQ(m.joints[1].name, "knee");
  EXPECT_EQ(m.joints[1].parent, 0);
  EXPECT_LT((m.joints[0].restWorld.block<3, 1>(0, 3) - Vec3(0, 0, 0)).norm(), 1e-9);
  EXPECT_LT((m.joints[1].restWorld.block<3, 1>(0, 3) - Vec3(0, 0.5, 0)).norm(), 1e-6);  // 50 cm up Z is 0.5 m up Y

  // Identical vertices joined: the 60 triangle corners are the file's 12 vertices.
  ASSERT_EQ(m.positions.size(), 12u);
  std::vector<int> fileIndex(12);
  for (std::size_t v = 0; v < 12; ++v) {
    fileIndex[v] = tubeVertexAt(m.positions[v]);
    ASSERT_GE(fileIndex[v], 0) << "vertex " << v << " at " << m.positions[v].transpose();
    const int ring = fileIndex[v] / 4;
    std::map<int, float> w;
    for (int k = 0; k < 4; ++k)
      if (m.vertexWeights[v][static_cast<std::size_t>(k)] > 0.0f) w[m.vertexJoints[v][static_cast<std::size_t>(k)]] += m.vertexWeights[v][static_cast<std::size_t>(k)];
    const std::map<int, float> expected = ring == 0 ? std::map<int, float>{{0, 1.0f}}
                                        : ring == 1 ? std::map<int, float>{{0, 0.5f}, {1, 0.5f}}
                                                    : std::map<int, float>{{1, 1.0f}};
    ASSERT_EQ(w.size(), expected.size()) << "vertex " << fileIndex[v];
    for (const auto& [joint, weight] : expected) EXPECT_NEAR(w[joint], weight, 1e-6) << "vertex " << fileIndex[v];
  }
  ASSERT_EQ(m.triangles.size(), 20u);
  std::set<std::array<int, 3>> got, want;
  for (const mesh::Triangle& t : m.triangles)
    got.insert(canonical({fileIndex[t[0]], fileIndex[t[1]], fileIndex[t[2]]}));
  for (const auto& t : kTubeTriangles) want.insert(canonical(t));
  EXPECT_EQ(got, want);  // the same triangles, wound the same way (Z up -> Y up is a rotation)
}

TEST(AssimpAvatar, ColladaTubeInMetresAndYUp) { expectTheTube(readAssimpSkinnedModel(tube())); }

TEST(AssimpAvatar, ParsesInProcessToo) {
  // The same reader without the child process (what the fuzz target exercises).
  const SkinnedModel m = parseAssimpSkinnedModel(slurp(tube()), "tube.dae");
  expectTheTube(m);
  const SkinnedModel back = deserialiseSkinnedModel(serialise(m), "tube.dae");
  EXPECT_EQ(back.positions, m.positions);
  EXPECT_EQ(back.vertexJoints, m.vertexJoints);
}

// tests/data/avatars/tube_two_joints.fbx is the tube written by `drape convert` (ASCII
// FBX, centimetres): a committed FBX file, and the FBX fuzz target's seed.
TEST(AssimpAvatar, AsciiFbxTube) {
  expectTheTube(readAssimpSkinnedModel(std::string(DRAPE_TEST_DATA_DIR) + "/avatars/tube_two_joints.fbx"));
}

struct ScratchDir {
  std::filesystem::path path = std::filesystem::temp_directory_path() / ("drape-assimp-" + std::to_string(::getpid()));
  ScratchDir() { std::filesystem::create_directories(path); }
  ~ScratchDir() { std::filesystem::remove_all(path); }
};

class AssimpWriter : public ::testing::TestWithParam<const char*> {};

// The writer's files (Collada in metres, ASCII FBX in centimetres) read back as the tube.
TEST_P(AssimpWriter, WritesTheTubeSoItReadsBack) {
  const ScratchDir dir;
  const std::string out = (dir.path / (std::string("tube") + GetParam())).string();
  writeAssimpSkinnedModel(out, readAssimpSkinnedModel(tube()));
  expectTheTube(readAssimpSkinnedModel(out));
}

INSTANTIATE_TEST_SUITE_P(Formats, AssimpWriter, ::testing::Values(".dae", ".fbx"),
                         [](const auto& info) { return std::string(info.param + 1); });

void replaceOnce(std::string& text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
}

// Assimp's FBX importer leaves GlobalSettings' units and axes to drape: a file in units of
// 2 cm with Z up reads back scaled by 2 and turned Y up.
TEST(AssimpAvatar, FbxUnitScaleFactorAndUpAxisAreApplied) {
  const ScratchDir dir;
  const std::string plain = (dir.path / "tube.fbx").string(), zUp = (dir.path / "tube_z_up.fbx").string();
  writeAssimpSkinnedModel(plain, readAssimpSkinnedModel(tube()));
  std::string text = slurp(plain);
  replaceOnce(text, "\"UnitScaleFactor\", \"double\", \"Number\", \"\", 1", "\"UnitScaleFactor\", \"double\", \"Number\", \"\", 2");
  replaceOnce(text, "\"UpAxis\", \"int\", \"Integer\", \"\", 1", "\"UpAxis\", \"int\", \"Integer\", \"\", 2");
  std::ofstream(zUp, std::ios::binary) << text;
  const SkinnedModel a = readAssimpSkinnedModel(plain), b = readAssimpSkinnedModel(zUp);
  ASSERT_EQ(a.positions.size(), b.positions.size());
  for (std::size_t v = 0; v < a.positions.size(); ++v) {
    const Vec3& p = a.positions[v];
    EXPECT_LT((b.positions[v] - 2.0 * Vec3(p.x(), p.z(), -p.y())).norm(), 1e-6) << v;
  }
}

TEST(AssimpAvatar, WriterRefusesOtherExtensions) {
  const std::string e = errorOf([] { writeAssimpSkinnedModel("x.obj", readAssimpSkinnedModel(tube())); });
  EXPECT_EQ(e, "x.obj: drape writes skinned avatars as Collada (.dae) or FBX (.fbx), not '.obj'");
}

// ---- malformed input: an error naming the file, never a crash ---------------------------

void expectError(const std::string& file, const std::string& text) {
  const std::string e = errorOf([&] { (void)readAssimpSkinnedModel(bad(file)); });
  EXPECT_EQ(e.rfind(bad(file) + ":", 0), 0u) << e;
  EXPECT_NE(e.find(text), std::string::npos) << e;
}

TEST(AssimpAvatarBad, TruncatedCollada) { expectError("truncated.dae", "Collada"); }

TEST(AssimpAvatarBad, XmlThatIsNotCollada) { expectError("not_collada.dae", "not a Collada file (no XML root element <COLLADA>)"); }

// Bytes that are not FBX never reach any importer (nothing falls through to another format).
TEST(AssimpAvatarBad, TextThatIsNotFbx) { expectError("text_garbage.fbx", "not an FBX file"); }

TEST(AssimpAvatarBad, AsciiFbxGarbage) { expectError("ascii_garbage.fbx", "FBX"); }

// Only the avatar's own bytes are given to Assimp: references to other files resolve to
// nothing, and the import fails naming the avatar.
TEST(AssimpAvatarBad, SkinSourceOutsideTheFolder) {
  expectError("skin_source_outside_folder.dae", "has no mesh");
}

TEST(AssimpAvatarBad, SceneOutsideTheFolder) { expectError("scene_outside_folder.dae", "Unknown reference format"); }

// Images are never read: a texture naming a file outside the folder changes nothing.
TEST(AssimpAvatarBad, ImageOutsideTheFolderIsNeverRead) {
  expectTheTube(readAssimpSkinnedModel(bad("image_outside_folder.dae")));
}

// Found by fuzz/fuzz_dae.cpp: a word that is not a number in <p> made Assimp's Collada
// parser allocate over 4 GB; drape checks index lists first.
TEST(AssimpAvatarBad, IndexThatIsNotANumber) {
  expectError("index_not_a_number.dae", ":29: <p> holds 'abc', not a whole number");
}

// Found by fuzz/fuzz_dae.cpp: Assimp dereferences a null pointer on an array without
// its count attribute.
TEST(AssimpAvatarBad, ArrayWithoutCount) {
  expectError("array_without_count.dae", ":17: <float_array> has no count attribute");
}

// Assimp reserves what a count attribute says before reading the values.
TEST(AssimpAvatarBad, CountLargerThanTheFile) {
  expectError("count_too_large.dae", ":17: count=\"3600000000\" is more than a");
}

// Found by fuzz/fuzz_fbx.cpp: a mutated ASCII FBX makes Assimp 5.2.5 free memory twice
// while it discards the scene. Only the child process dies; drape reports it.
TEST(AssimpAvatarBad, FbxCrashIsAnErrorMessage) {
  expectError("fbx_double_free.fbx", "the FBX reader (Assimp) failed");
}

// Found by fuzz/fuzz_dae.cpp: a mutated Collada file on which Assimp 5.2.5 dereferences a
// null pointer past every check drape makes first; the child process contains it.
TEST(AssimpAvatarBad, ColladaCrashIsAnErrorMessage) {
  expectError("collada_assimp_segv.dae", "the Collada reader (Assimp) failed");
}

TEST(AssimpAvatarBad, WrongExtension) {
  EXPECT_EQ(errorOf([] { (void)readAssimpSkinnedModel("avatar.obj"); }),
            "avatar.obj: drape reads Collada (.dae) and FBX (.fbx) through Assimp, not '.obj'");
}

TEST(AssimpAvatarBad, MissingFile) { expectError("no_such_file.dae", "no such file"); }

}  // namespace
}  // namespace drape::formats
