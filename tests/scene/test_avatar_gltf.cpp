// glTF skinned characters: CesiumMan segmented into 19 closed segments covering every
// triangle; the Assimp failure cases found so far as regressions.

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <nlohmann/json.hpp>

#include "drape/core/error.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/scene/avatar_segment.hpp"
#include "drape/testing/clothed_avatar.hpp"
#include "drape/testing/errors.hpp"
#include "drape/testing/temp_dir.hpp"

namespace drape::scene {
namespace {

std::string avatarData(const std::string& file) { return std::string(DRAPE_DATA_DIR) + "/avatars/" + file; }
std::string badMotion(const std::string& file) { return std::string(DRAPE_TEST_DATA_DIR) + "/bad/motion/" + file; }

using drape::testing::errorOf;

TEST(GltfAvatar, ReadsInProcessToo) {
  // The same reader without the child process (what the fuzz target exercises).
  std::ifstream in(avatarData("CesiumMan.glb"), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const formats::GltfSkinnedModel m = formats::parseGltfSkinnedModel(bytes, "CesiumMan.glb", std::string(DRAPE_DATA_DIR) + "/avatars");
  EXPECT_EQ(m.joints.size(), 19u);
  EXPECT_EQ(m.triangles.size(), 4672u);
  const formats::GltfSkinnedModel back = formats::deserialiseSkinnedModel(formats::serialise(m), "x");
  EXPECT_EQ(back.positions, m.positions);
  EXPECT_EQ(back.vertexJoints, m.vertexJoints);
}

TEST(GltfAvatar, CesiumManHas19ClosedSegmentsCoveringEveryTriangle) {
  const Avatar a = loadGltfAvatar(avatarData("CesiumMan.glb"));
  ASSERT_EQ(a.joints.size(), 19u);
  ASSERT_TRUE(a.skin.has_value());
  EXPECT_EQ(a.skin->mesh.triangles.size(), 4672u);
  EXPECT_EQ(a.segments.size(), 19u);
  for (const Segment& s : a.segments) EXPECT_EQ(countBoundaryEdges(s.mesh), 0u) << s.name;
  Avatar copy = a;
  const std::vector<int> segmentOf = segmentSkinnedAvatar(copy);
  ASSERT_EQ(segmentOf.size(), 4672u);
  for (std::size_t t = 0; t < segmentOf.size(); ++t) EXPECT_GE(segmentOf[t], 0) << "triangle " << t;
  // Y up after the root node's rotation, about 1.5 m tall, standing on y = 0.
  const Aabb box = a.skin->mesh.bounds();
  EXPECT_NEAR(box.size().y(), 1.5, 0.05);
  EXPECT_NEAR(box.min.y(), 0.0, 0.02);
  // Segments sit in their joint's frame: moved back to the rest pose they match the skin.
  for (const Segment& s : a.segments) {
    const Vec3 c = a.joints[static_cast<std::size_t>(s.joint)].restCenter;
    Aabb segBox;
    for (const Vec3& v : s.mesh.positions) segBox.extend(v + c);
    EXPECT_TRUE(box.contains(segBox.center())) << s.name;
  }
}

TEST(GltfAvatar, RiggedSimpleIsTwoSegments) {
  const Avatar a = loadGltfAvatar(avatarData("RiggedSimple.glb"));
  EXPECT_EQ(a.joints.size(), 2u);
  EXPECT_EQ(a.segments.size(), 2u);
  for (const Segment& s : a.segments) EXPECT_EQ(countBoundaryEdges(s.mesh), 0u) << s.name;
}

// Regression: a spec-valid skin without inverseBindMatrices crashed Assimp's glTF2 importer;
// the glTF default (identity) applies.
TEST(GltfAvatar, SkinWithoutInverseBindMatricesUsesIdentity) {
  const Avatar a = loadGltfAvatar(badMotion("skin_without_inverse_bind.gltf"));
  EXPECT_EQ(a.joints.size(), 2u);
  EXPECT_EQ(a.segments.size(), 2u);
}

// Regression: bytes that are not glTF fell through to other Assimp importers.
TEST(GltfAvatar, BytesThatAreNotGltfAreAnError) {
  EXPECT_EQ(errorOf([] { (void)loadGltfAvatar(badMotion("not_gltf.glb")); }).rfind(badMotion("not_gltf.glb") + ": ", 0), 0u);
  const std::string e = errorOf([] { (void)loadGltfAvatar(badMotion("not_gltf.glb")); });
  EXPECT_NE(e, "(no error)");
}

// Regression: a buffer URI that is a plain path outside the model's folder was read from disk.
TEST(GltfAvatar, BufferUriOutsideTheFolderIsRefused) {
  const std::string e = errorOf([] { (void)loadGltfAvatar(badMotion("buffer_outside_folder.gltf")); });
  EXPECT_NE(e.find("outside the model's folder"), std::string::npos) << e;
}

// Found by fuzz/fuzz_gltf.cpp: a number too large for a double made nlohmann_json throw
// out_of_range, which escaped as an uncaught exception.
TEST(GltfAvatar, NumberOverflowIsAnError) {
  const std::string e = errorOf([] { (void)loadGltfAvatar(badMotion("number_overflow.gltf")); });
  EXPECT_EQ(e.rfind(badMotion("number_overflow.gltf") + ":1:40: expected a finite number, found '0.9E99998807907105", 0), 0u) << e;
}

// A syntax error names its line and column, as every other reader's does.
TEST(GltfAvatar, SyntaxErrorsNameTheirLineAndColumn) {
  const std::string e = errorOf([] { (void)loadGltfAvatar(badMotion("trailing_comma.gltf")); });
  EXPECT_EQ(e.rfind(badMotion("trailing_comma.gltf") + ":3:32: syntax error while parsing value - unexpected ']'", 0), 0u) << e;
}

// A VRML97 file of one H-Anim Humanoid is an avatar file; none, or several, is an error
// that says which.
TEST(HumanoidFile, OneHumanoidIsAnAvatarNoneOrSeveralAreErrors) {
  const std::string dir = drape::testing::processTempDir("humanoid-file").string();
  const auto write = [&](const std::string& name, const std::string& body) {
    const std::string path = dir + "/" + name;
    std::ofstream(path) << "#VRML V2.0 utf8\n" << body;
    return path;
  };
  const std::string humanoid = R"(Humanoid { name "%" humanoidBody Joint { name "root" center 0 1 0 children [
    Joint { name "head" center 0 1.6 0 } ] } }
)";
  const auto named = [&](const std::string& name) {
    std::string h = humanoid;
    h.replace(h.find('%'), 1, name);
    return h;
  };
  const Avatar one = loadAvatarFile(write("one.wrl", named("solo")));
  EXPECT_EQ(one.name, "solo");
  ASSERT_EQ(one.joints.size(), 2u);
  EXPECT_EQ(one.joints[1].name, "head");
  EXPECT_EQ(one.joints[1].parent, 0);

  const std::string none = write("none.wrl", "Transform { }\n");
  EXPECT_EQ(errorOf([&] { (void)loadAvatarFile(none); }), none + ": has no H-Anim Humanoid to take as an avatar");
  const std::string two = write("two.wrl", named("a") + named("b"));
  EXPECT_EQ(errorOf([&] { (void)loadAvatarFile(two); }),
            two + ": holds 2 H-Anim Humanoids ('a', 'b'); an avatar file holds one");
}

/// CesiumMan as VRoid Studio and UniVRM save their characters: a binary glTF named .vrm,
/// using VRM's extension (its humanoid bone map, which drape finds by shape instead).
std::string cesiumManAsVrm() {
  std::ifstream in(avatarData("CesiumMan.glb"), std::ios::binary);
  const std::string glb((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::uint32_t jsonLength = 0;
  std::memcpy(&jsonLength, glb.data() + 12, 4);
  nlohmann::json doc = nlohmann::json::parse(glb.substr(20, jsonLength));
  doc["extensionsUsed"] = {"VRM"};
  doc["extensions"]["VRM"] = {{"specVersion", "0.0"}, {"humanoid", {{"humanBones", {{{"bone", "hips"}, {"node", 2}}}}}}};
  std::string json = doc.dump();
  while (json.size() % 4 != 0) json += ' ';
  const std::string binChunk = glb.substr(20 + jsonLength);  // its length, type and bytes
  const auto u32 = [](std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  const std::string vrm = "glTF" + u32(2) + u32(static_cast<std::uint32_t>(12 + 8 + json.size() + binChunk.size())) +
                          u32(static_cast<std::uint32_t>(json.size())) + "JSON" + json + binChunk;
  const std::string path = (drape::testing::processTempDir("vrm") / "CesiumMan.vrm").string();
  std::ofstream(path, std::ios::binary) << vrm;
  return path;
}

TEST(GltfAvatar, AVrmIsReadAsTheGlbItIs) {
  const Avatar glb = loadAvatarFile(avatarData("CesiumMan.glb"));
  const Avatar vrm = loadAvatarFile(cesiumManAsVrm());
  ASSERT_TRUE(vrm.skin.has_value());
  EXPECT_EQ(vrm.skin->mesh.positions, glb.skin->mesh.positions);
  EXPECT_EQ(vrm.skin->mesh.triangles, glb.skin->mesh.triangles);
  ASSERT_EQ(vrm.joints.size(), glb.joints.size());
  for (std::size_t j = 0; j < glb.joints.size(); ++j) EXPECT_EQ(vrm.joints[j].name, glb.joints[j].name);
  EXPECT_EQ(vrm.segments.size(), glb.segments.size());
  EXPECT_EQ(vrm.animations, glb.animations);
}

TEST(AvatarFile, DrawnMeshesAreSkinnedOverTheBodysJointsAndPlacedWithIt) {
  // The cape drawn, the body alone colliding: the drawn skin is exactly the cape's part of
  // the whole skin's read (positions, joints, weights), on the same skeleton, and moves
  // with the avatar's placement as the skin does.
  const std::string clothed = drape::testing::clothedCesiumMan(drape::testing::processTempDir("drawn-meshes"));
  const Avatar whole = loadAvatarFile(clothed);
  Avatar drawn = loadAvatarFile(clothed, {"Body"}, {"Cape"});
  ASSERT_TRUE(drawn.drawnSkin.has_value());
  const Avatar everyOther = loadAvatarFile(clothed, {"B*"}, {"*"});
  EXPECT_EQ(everyOther.meshesRead, std::vector<std::string>{"Body"});
  EXPECT_EQ(everyOther.drawnMeshesRead, std::vector<std::string>{"Cape"}) << "* draws every mesh the body leaves out";
  EXPECT_EQ(drawn.drawnMeshesRead, std::vector<std::string>{"Cape"});
  ASSERT_EQ(drawn.joints.size(), whole.joints.size());
  for (std::size_t j = 0; j < whole.joints.size(); ++j) EXPECT_EQ(drawn.joints[j].name, whole.joints[j].name);
  const std::size_t body = drawn.skin->mesh.vertexCount(), cape = drawn.drawnSkin->mesh.vertexCount();
  ASSERT_EQ(body + cape, whole.skin->mesh.vertexCount());
  ASSERT_EQ(drawn.skin->mesh.triangleCount() + drawn.drawnSkin->mesh.triangleCount(), whole.skin->mesh.triangleCount());
  for (std::size_t v = 0; v < cape; ++v) {
    EXPECT_LT((drawn.drawnSkin->mesh.positions[v] - whole.skin->mesh.positions[body + v]).norm(), 1e-12);
    EXPECT_EQ(drawn.drawnSkin->joints[v], whole.skin->joints[body + v]);
    EXPECT_EQ(drawn.drawnSkin->weights[v], whole.skin->weights[body + v]);
  }
  EXPECT_EQ(drawn.segments.size(), loadAvatarFile(clothed, {"Body"}).segments.size()) << "the drawn meshes are not cut";

  const std::vector<Vec3> before = drawn.drawnSkin->mesh.positions;
  const RigidTransform placement{Quat(Eigen::AngleAxisd(0.7, Vec3::UnitY())), Vec3(1.0, 0.0, -2.0)};
  placeAvatar(drawn, placement, 0.5);
  for (std::size_t v = 0; v < cape; v += 97)
    EXPECT_LT((drawn.drawnSkin->mesh.positions[v] - placement.apply(0.5 * before[v])).norm(), 1e-12);
}

TEST(AvatarFile, AMeshDrawnAndTheBodysIsRefused) {
  const std::string clothed = drape::testing::clothedCesiumMan(drape::testing::processTempDir("drawn-refused"));
  EXPECT_EQ(errorOf([&] { (void)loadAvatarFile(clothed, {}, {"Cape"}); }),
            clothed + ": drawnMeshes (Cape) name Cape, which is the body's: a mesh is drawn or makes the body, not both "
                      "(the body is every mesh of its skin unless meshes names those that make it; its skinned meshes: "
                      "Body, Cape)");
  EXPECT_EQ(errorOf([&] { (void)loadAvatarFile(clothed, {"Body", "Cape"}, {"CapeMesh", "Body"}); }),
            clothed + ": drawnMeshes (CapeMesh, Body) name Body, Cape, which are the body's: a mesh is drawn or makes "
                      "the body, not both");
  EXPECT_NE(errorOf([&] { (void)loadAvatarFile(clothed, {"Body"}, {"Hair"}); })
                .find("has no node or mesh named 'Hair' (its skinned meshes: Body, Cape)"),
            std::string::npos);
  // A pattern draws only meshes the body leaves out: with the whole skin the body, none.
  EXPECT_EQ(errorOf([&] { (void)loadAvatarFile(clothed, {}, {"*"}); }),
            clothed +
                ": drawnMeshes '*' matches none of the skinned meshes the body leaves out (none: the body is "
                "every mesh of its skin)");
  EXPECT_EQ(errorOf([&] { (void)loadAvatarFile(clothed, {"Body"}, {"Hair*"}); }),
            clothed + ": drawnMeshes 'Hair*' matches none of the skinned meshes the body leaves out (Cape)");
  const std::string makeHuman = std::string(DRAPE_SOURCE_DIR) + "/data/avatars/makehuman_rig_cmu_mb.mhskel";
  EXPECT_EQ(errorOf([&] { (void)loadAvatarFile(makeHuman, {}, {"Hair"}); }),
            makeHuman + ": drawnMeshes (Hair) choose among the skinned meshes of a glTF, Collada or FBX avatar; a "
                        "MakeHuman avatar is one body");
}

TEST(GltfAvatar, UnknownAvatarExtension) {
  EXPECT_EQ(errorOf([] { (void)loadAvatarFile("x.obj"); }),
            "x.obj: drape reads avatars from .glb, .gltf, .vrm, .dae, .fbx, MakeHuman .mhskel and VRML97 H-Anim (.wrl) files, not '.obj'");
}

}  // namespace
}  // namespace drape::scene
