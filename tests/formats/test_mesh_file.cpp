// Garments and masks from the files modelling tools export (formats/mesh_file.hpp): the
// MakeHuman dress written by Assimp's glTF, Collada and FBX exporters (split at its texture
// seams, or not indexed at all) reads back as the dress of its OBJ; a glTF written by hand
// checks node transforms, strips and fans, two-sided copies and parts chosen by name.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <set>

#include <nlohmann/json.hpp>

#include "drape/core/files.hpp"
#include "drape/formats/assimp_avatar.hpp"
#include "drape/formats/gltf_avatar.hpp"
#include "drape/formats/mesh_file.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/units.hpp"
#include "drape/mesh/weld.hpp"
#include "drape/testing/assimp_export.hpp"
#include "drape/testing/errors.hpp"
#include "drape/testing/temp_dir.hpp"

namespace drape::formats {
namespace {

const std::string kDress = std::string(DRAPE_DATA_DIR) + "/garments/makehuman_female_elegantsuit01_dress.obj";

struct Exporter {
  const char* extension;
  const char* formatId;
  /// Metres per metre of the dress as exported: Assimp's FBX exporter writes the scene's
  /// numbers under UnitScaleFactor 1 (centimetres), so the file says the dress is a
  /// hundredth of its size, and drape reads what the file says.
  double unit;
};

class MeshFileExported : public ::testing::TestWithParam<Exporter> {};

TEST_P(MeshFileExported, TheDressReadsBackAsTheDressOfItsObj) {
  const Exporter e = GetParam();
  const std::string path = (drape::testing::processTempDir("mesh-file") / (std::string("dress") + e.extension)).string();
  // The dress in metres: its OBJ is in decimetres.
  const drape::testing::Exported written = drape::testing::exportThroughAssimp(kDress, 0.1, e.formatId, path);
  ObjReadOptions dm;
  dm.metresPerUnit = metresPerUnit("dm");
  const mesh::TriMesh obj = readObj(kDress, dm);
  ASSERT_GT(written.vertices, obj.vertexCount());  // split where its texture coordinates change

  const MeshFile read = readMeshFile(path);
  ASSERT_EQ(read.mesh.vertexCount(), obj.vertexCount());
  ASSERT_EQ(read.mesh.triangleCount(), obj.triangleCount());
  EXPECT_GE(read.welded, written.vertices - obj.vertexCount());
  EXPECT_EQ(read.droppedTriangles, 0u);
  EXPECT_EQ(read.partsRead.size(), 1u);
  // Each vertex is one of the OBJ's, by brute force, and no two are the same one.
  std::vector<std::uint32_t> objVertex(read.mesh.vertexCount());
  std::vector<bool> taken(obj.vertexCount(), false);
  for (std::size_t v = 0; v < read.mesh.vertexCount(); ++v) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t o = 0; o < obj.vertexCount(); ++o) {
      const double d = (e.unit * obj.positions[o] - read.mesh.positions[v]).norm();
      if (d < best) {
        best = d;
        objVertex[v] = static_cast<std::uint32_t>(o);
      }
    }
    ASSERT_LT(best, 1e-6 * e.unit) << "vertex " << v;
    ASSERT_FALSE(taken[objVertex[v]]) << "vertex " << v << " is OBJ vertex " << objVertex[v] << " a second time";
    taken[objVertex[v]] = true;
  }
  // The same triangles, wound the same way.
  std::set<std::array<std::uint32_t, 3>> objTriangles;
  auto rotated = [](std::array<std::uint32_t, 3> t) {
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    return t;
  };
  for (const mesh::Triangle& t : obj.triangles) objTriangles.insert(rotated(t));
  for (const mesh::Triangle& t : read.mesh.triangles)
    EXPECT_EQ(objTriangles.count(rotated({objVertex[t[0]], objVertex[t[1]], objVertex[t[2]]})), 1u);
}

INSTANTIATE_TEST_SUITE_P(Formats, MeshFileExported,
                         ::testing::Values(Exporter{".glb", "glb2", 1.0}, Exporter{".gltf", "gltf2", 1.0},
                                           Exporter{".dae", "collada", 1.0}, Exporter{".fbx", "fbxa", 0.01}),
                         [](const auto& info) { return std::string(info.param.extension + 1); });

// A skinned mesh is read where its skeleton at rest puts it, as the avatar readers skin it
// (CesiumMan's skin turns his Z-up mesh upright; the robot arm and the tube bend at rest).
TEST(MeshFile, ASkinnedMeshIsReadWhereTheAvatarReadersSkinItAtRest) {
  for (const std::string& path : {std::string(DRAPE_DATA_DIR) + "/avatars/CesiumMan.glb",
                                 std::string(DRAPE_DATA_DIR) + "/avatars/RiggedSimple.glb",
                                 std::string(DRAPE_TEST_DATA_DIR) + "/avatars/rigged_simple_animated.dae",
                                 std::string(DRAPE_TEST_DATA_DIR) + "/avatars/rigged_simple_animated.fbx",
                                 std::string(DRAPE_TEST_DATA_DIR) + "/avatars/tube_two_joints.fbx"}) {
    SCOPED_TRACE(path);
    const SkinnedModel avatar = lowerExtension(path) == ".glb" ? readGltfSkinnedModel(path) : readAssimpSkinnedModel(path);
    mesh::TriMesh skin;
    skin.positions = avatar.positions;
    skin.triangles = avatar.triangles;
    const mesh::TriMesh want = mesh::weld(skin, 1e-6).mesh;
    const MeshFile got = readMeshFile(path);
    ASSERT_EQ(got.mesh.vertexCount(), want.vertexCount());
    ASSERT_EQ(got.mesh.triangleCount(), want.triangleCount());
    for (std::size_t v = 0; v < want.vertexCount(); ++v) {
      double best = std::numeric_limits<double>::infinity();
      for (const Vec3& p : got.mesh.positions) best = std::min(best, (p - want.positions[v]).norm());
      ASSERT_LT(best, 1e-9) << "vertex " << v;
    }
  }
}

/// RiggedSimple (a tube of two bones) as a .gltf whose second joint is turned 90 degrees
/// about x at rest: its skin is bound straight, so at rest it bends.
std::string bentRiggedSimple() {
  std::ifstream in(std::string(DRAPE_DATA_DIR) + "/avatars/RiggedSimple.glb", std::ios::binary);
  const std::string glb((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::uint32_t jsonLength = 0, binLength = 0;
  std::memcpy(&jsonLength, glb.data() + 12, 4);
  std::memcpy(&binLength, glb.data() + 20 + jsonLength, 4);
  nlohmann::json doc = nlohmann::json::parse(glb.substr(20, jsonLength));
  doc["nodes"][3]["rotation"] = {0.70710678, 0.0, 0.0, 0.70710678};
  doc["buffers"][0]["uri"] = "bent.bin";
  const std::filesystem::path dir = drape::testing::processTempDir("mesh-file-bent");
  std::ofstream(dir / "bent.bin", std::ios::binary) << glb.substr(28 + jsonLength, binLength);
  std::ofstream(dir / "bent.gltf") << doc.dump();
  return (dir / "bent.gltf").string();
}

TEST(MeshFile, ASkinnedMeshBentAtRestIsReadBentAsTheAvatarReaderSkinsIt) {
  const std::string path = bentRiggedSimple();
  const SkinnedModel avatar = readGltfSkinnedModel(path);
  const MeshFile got = readMeshFile(path);
  const MeshFile straight = readMeshFile(std::string(DRAPE_DATA_DIR) + "/avatars/RiggedSimple.glb");
  mesh::TriMesh skin;
  skin.positions = avatar.positions;
  skin.triangles = avatar.triangles;
  const mesh::TriMesh want = mesh::weld(skin, 1e-6).mesh;
  ASSERT_EQ(got.mesh.vertexCount(), want.vertexCount());
  ASSERT_EQ(got.mesh.triangleCount(), want.triangleCount());
  double moved = 0.0;
  for (std::size_t v = 0; v < want.vertexCount(); ++v) {
    double best = std::numeric_limits<double>::infinity();
    for (const Vec3& p : got.mesh.positions) best = std::min(best, (p - want.positions[v]).norm());
    ASSERT_LT(best, 1e-9) << "vertex " << v;
    moved = std::max(moved, (got.mesh.positions[v] - straight.mesh.positions[v]).norm());
  }
  EXPECT_GT(moved, 1.0) << "the bent tube's end is metres from the straight one's";
}

// ---- a glTF written by hand ---------------------------------------------------------------

template <typename T>
void append(std::string& bin, std::initializer_list<T> values) {
  for (T v : values) bin.append(reinterpret_cast<const char*>(&v), sizeof v);
}

/// Three nodes: "Front", a quad as two unindexed triangles plus a copy of the first wound the
/// other way (a two-sided face); "Back", a strip of two triangles, moved to z = -1 and scaled
/// by 2; "Fan" (mesh "FanMesh"), a fan of two triangles moved to x = 5; "Pins", the fan's
/// four vertices as points, moved to y = 10; and "Proxy", the front again, in no scene:
/// nothing shows it, and nothing reads it.
std::string handWrittenGltf() {
  const std::filesystem::path dir = drape::testing::processTempDir("mesh-file-hand");
  std::string bin;
  append<float>(bin, {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 1, 0, 0});  // 9 vertices
  append<float>(bin, {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0});                                              // strip, 4
  append<float>(bin, {0, 0, 0, 1, 0, 0, 0, 1, 0, -1, 0, 0});                                             // fan, 4
  append<std::uint16_t>(bin, {0, 1, 2, 3});                                                               // strip indices
  std::ofstream(dir / "hand.bin", std::ios::binary) << bin;
  const std::string json = R"({
  "asset": {"version": "2.0"},
  "scene": 0, "scenes": [{"nodes": [0, 1, 2, 3]}],
  "nodes": [
    {"name": "Front", "mesh": 0},
    {"name": "Back", "mesh": 1, "translation": [0, 0, -1], "scale": [2, 2, 2]},
    {"name": "Fan", "mesh": 2, "translation": [5, 0, 0]},
    {"name": "Pins", "mesh": 3, "translation": [0, 10, 0]},
    {"name": "Proxy", "mesh": 0, "translation": [0, 0, 7]}
  ],
  "meshes": [
    {"name": "FrontMesh", "primitives": [{"attributes": {"POSITION": 0}}]},
    {"name": "BackMesh", "primitives": [{"attributes": {"POSITION": 1}, "indices": 3, "mode": 5}]},
    {"name": "FanMesh", "primitives": [{"attributes": {"POSITION": 2}, "mode": 6}]},
    {"name": "PinsMesh", "primitives": [{"attributes": {"POSITION": 2}, "mode": 0}]}
  ],
  "buffers": [{"uri": "hand.bin", "byteLength": 212}],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 108},
    {"buffer": 0, "byteOffset": 108, "byteLength": 48},
    {"buffer": 0, "byteOffset": 156, "byteLength": 48},
    {"buffer": 0, "byteOffset": 204, "byteLength": 8}
  ],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 9, "type": "VEC3"},
    {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
    {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC3"},
    {"bufferView": 3, "componentType": 5123, "count": 4, "type": "SCALAR"}
  ]
})";
  std::ofstream(dir / "hand.gltf") << json;
  return (dir / "hand.gltf").string();
}

TEST(MeshFile, AHandWrittenGltfIsReadNodeByNode) {
  const MeshFile all = readMeshFile(handWrittenGltf());
  EXPECT_EQ(all.partsRead, (std::vector<std::string>{"Front", "Back", "Fan"}));
  ASSERT_EQ(all.mesh.vertexCount(), 12u);  // the front quad's 9 vertices welded to its 4 corners
  ASSERT_EQ(all.mesh.triangleCount(), 6u);
  EXPECT_EQ(all.welded, 5u);
  EXPECT_EQ(all.droppedTriangles, 1u);  // the front's two-sided copy
  // The front at z = 0, the back at z = -1 and twice as large, the fan at x = 5; every
  // triangle faces +z (the strip's second triangle turned as the spec says).
  double frontArea = 0.0, backArea = 0.0, fanArea = 0.0;
  for (std::size_t t = 0; t < all.mesh.triangleCount(); ++t) {
    const mesh::Triangle& tri = all.mesh.triangles[t];
    const Vec3 n = all.mesh.triangleNormalArea(t);
    EXPECT_GT(n.z(), 0.0) << "triangle " << t;
    const Vec3& a = all.mesh.positions[tri[0]];
    (a.z() == -1.0 ? backArea : a.x() >= 4.0 ? fanArea : frontArea) += all.mesh.triangleArea(t);
  }
  EXPECT_DOUBLE_EQ(frontArea, 1.0);
  EXPECT_DOUBLE_EQ(backArea, 4.0);
  EXPECT_DOUBLE_EQ(fanArea, 1.0);
}

TEST(MeshFile, AMaskKeepsItsLoosePoints) {
  // A garment leaves the points out; a mask keeps them, after the triangles' vertices.
  MeshFileOptions mask;
  mask.looseVertices = true;
  const MeshFile m = readMeshFile(handWrittenGltf(), mask);
  EXPECT_EQ(m.partsRead, (std::vector<std::string>{"Front", "Back", "Fan", "Pins"}));
  ASSERT_EQ(m.mesh.vertexCount(), 16u);
  EXPECT_EQ(m.mesh.triangleCount(), 6u);
  for (std::size_t v = 12; v < 16; ++v) EXPECT_EQ(m.mesh.positions[v].y(), v == 14 ? 11.0 : 10.0) << v;
  mask.parts = {"PinsMesh"};
  const MeshFile pins = readMeshFile(handWrittenGltf(), mask);
  EXPECT_EQ(pins.mesh.vertexCount(), 4u);
  EXPECT_EQ(pins.mesh.triangleCount(), 0u);
  MeshFileOptions garment;
  garment.parts = {"Pins"};
  EXPECT_EQ(drape::testing::errorOf([&] { (void)readMeshFile(handWrittenGltf(), garment); }),
            handWrittenGltf() + ": the parts asked for have no triangles");
}

TEST(MeshFile, PartsAreChosenByNodeOrMeshName) {
  const std::string path = handWrittenGltf();
  MeshFileOptions back;
  back.parts = {"Back"};
  const MeshFile b = readMeshFile(path, back);
  EXPECT_EQ(b.partsRead, (std::vector<std::string>{"Back"}));
  ASSERT_EQ(b.mesh.triangleCount(), 2u);
  for (const Vec3& p : b.mesh.positions) EXPECT_EQ(p.z(), -1.0);
  MeshFileOptions fan;
  fan.parts = {"FanMesh", "Front"};
  const MeshFile f = readMeshFile(path, fan);
  EXPECT_EQ(f.partsRead, (std::vector<std::string>{"Front", "Fan"}));
  EXPECT_EQ(f.mesh.triangleCount(), 4u);
  MeshFileOptions none;
  none.parts = {"Sleeve"};
  EXPECT_EQ(drape::testing::errorOf([&] { (void)readMeshFile(path, none); }),
            path + ": has no node or mesh named 'Sleeve' (its meshes: Front, Back, Fan, Pins)");
}

TEST(MeshFile, AnObjsGroupsAreItsParts) {
  // The MakeHuman base mesh's body group alone: its vertices, not the helpers' (tights,
  // skirt, hair) that share the file; as a mask, every vertex the file lists.
  const std::string path = std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_base_hm08.obj";
  MeshFileOptions body;
  body.parts = {"body"};
  const MeshFile m = readMeshFile(path, body);
  EXPECT_EQ(m.mesh.triangleCount(), 13378u * 2);
  std::vector<bool> used(m.mesh.vertexCount(), false);
  for (const mesh::Triangle& t : m.mesh.triangles)
    for (std::uint32_t v : t) used[v] = true;
  EXPECT_EQ(std::count(used.begin(), used.end(), false), 0);
  EXPECT_EQ(m.partsRead, (std::vector<std::string>{"body"}));
  MeshFileOptions helpers;
  helpers.parts = {"helper-t*"};
  EXPECT_EQ(readMeshFile(path, helpers).partsRead, (std::vector<std::string>{"helper-tights", "helper-tongue"}));
  EXPECT_TRUE(readMeshFile(path).partsRead.empty());
  body.looseVertices = true;
  EXPECT_EQ(readMeshFile(path, body).mesh.vertexCount(), 19158u);
}

TEST(MeshFile, ErrorsNameTheFile) {
  using drape::testing::errorOf;
  EXPECT_EQ(errorOf([] { (void)readMeshFile("skirt.stl"); }),
            "skirt.stl: drape reads meshes from OBJ, glTF (.gltf, .glb, .vrm), Collada (.dae) and FBX (.fbx), not '.stl'");
  const std::filesystem::path dir = drape::testing::processTempDir("mesh-file-bad");
  std::ofstream(dir / "bad.glb") << "glTF but not really";
  EXPECT_NE(errorOf([&] { (void)readMeshFile((dir / "bad.glb").string()); }).find((dir / "bad.glb").string() + ": "),
            std::string::npos);
  std::ofstream(dir / "bad.fbx") << "; FBX 7.5.0 project file\nnothing else";
  EXPECT_NE(errorOf([&] { (void)readMeshFile((dir / "bad.fbx").string()); }).find((dir / "bad.fbx").string() + ": "),
            std::string::npos);
  // Geometry compressed by an extension drape does not read; a mesh of one point.
  std::ofstream(dir / "draco.gltf") << R"({"asset": {"version": "2.0"}, "extensionsRequired": ["KHR_materials_unlit", )"
                                       R"("KHR_draco_mesh_compression"], "nodes": [{"name": "Dress"}]})";
  EXPECT_EQ(errorOf([&] { (void)readMeshFile((dir / "draco.gltf").string()); }),
            (dir / "draco.gltf").string() + ": needs the glTF extension KHR_draco_mesh_compression, which drape does not "
                                            "read (export it without compression or instancing)");
  std::ofstream(dir / "point.bin", std::ios::binary) << std::string(36, '\0');
  std::ofstream(dir / "point.gltf") << R"({"asset": {"version": "2.0"}, "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}], "buffers": [{"uri": "point.bin", "byteLength": 36}],
    "bufferViews": [{"buffer": 0, "byteLength": 36}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}]})";
  EXPECT_EQ(errorOf([&] { (void)readMeshFile((dir / "point.gltf").string()); }),
            (dir / "point.gltf").string() + ": its triangles (1) all collapse when the vertices within 1e-06 m of each other "
                                            "are welded: no surface is left");
  // A file of cameras and empty nodes: nothing to simulate.
  std::ofstream(dir / "empty.gltf") << R"({"asset": {"version": "2.0"}, "nodes": [{"name": "Camera"}]})";
  EXPECT_EQ(errorOf([&] { (void)readMeshFile((dir / "empty.gltf").string()); }), (dir / "empty.gltf").string() + ": has no triangle mesh");
}

}  // namespace
}  // namespace drape::formats
