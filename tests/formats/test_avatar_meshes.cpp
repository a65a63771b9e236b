// An avatar file that holds the character's clothes as well as its body (a second mesh
// moved by the same skin): the skinned-avatar readers read every mesh of the skin, or
// those named, and say which there are.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "drape/formats/assimp_avatar.hpp"
#include "drape/formats/gltf_avatar.hpp"
#include "drape/testing/assimp_export.hpp"
#include "drape/testing/clothed_avatar.hpp"
#include "drape/testing/errors.hpp"
#include "drape/testing/temp_dir.hpp"

namespace drape::formats {
namespace {

using drape::testing::errorOf;
using Names = std::vector<std::string>;

const SkinnedModel& cesiumMan() {
  static const SkinnedModel model = readGltfSkinnedModel(std::string(DRAPE_DATA_DIR) + "/avatars/CesiumMan.glb");
  return model;
}

std::string clothed() {
  static const std::string path = drape::testing::clothedCesiumMan(drape::testing::processTempDir("avatar-meshes"));
  return path;
}

// The largest distance between the vertices of `a` and the same vertices of `b` from `from`.
double largestMove(const std::vector<Vec3>& a, const std::vector<Vec3>& b, std::size_t from = 0) {
  double most = 0.0;
  for (std::size_t v = 0; v < a.size(); ++v) most = std::max(most, (a[v] - b[from + v]).norm());
  return most;
}

TEST(AvatarMeshes, EveryMeshOfTheSkinIsReadUnlessSomeAreNamed) {
  const SkinnedModel& plain = cesiumMan();
  const SkinnedModel all = readGltfSkinnedModel(clothed());
  EXPECT_EQ(all.meshes, (Names{"Body", "Cape"}));
  EXPECT_EQ(all.meshesRead, (Names{"Body", "Cape"}));
  ASSERT_EQ(all.positions.size(), 2 * plain.positions.size());
  ASSERT_EQ(all.triangles.size(), 2 * plain.triangles.size());
  EXPECT_EQ(all.joints.size(), plain.joints.size());

  const SkinnedModel body = readGltfSkinnedModel(clothed(), {"Body"});
  EXPECT_EQ(body.meshes, (Names{"Body", "Cape"}));
  EXPECT_EQ(body.meshesRead, (Names{"Body"}));
  ASSERT_EQ(body.positions.size(), plain.positions.size());
  EXPECT_EQ(body.triangles, plain.triangles);
  EXPECT_EQ(body.vertexJoints, plain.vertexJoints);
  EXPECT_LT(largestMove(body.positions, plain.positions), 1e-12);

  // The cape by its node's name and by its mesh's: the body pushed out by about a centimetre.
  for (const char* name : {"Cape", "CapeMesh"}) {
    SCOPED_TRACE(name);
    const SkinnedModel cape = readGltfSkinnedModel(clothed(), {name});
    EXPECT_EQ(cape.meshesRead, (Names{"Cape"}));
    ASSERT_EQ(cape.positions.size(), plain.positions.size());
    EXPECT_EQ(cape.triangles, plain.triangles);
    double least = 1.0;
    for (std::size_t v = 0; v < cape.positions.size(); ++v) least = std::min(least, (cape.positions[v] - plain.positions[v]).norm());
    const double most = largestMove(cape.positions, plain.positions);
    EXPECT_GT(least, 0.001) << "every cape vertex lies off the body's";
    EXPECT_LT(most, 0.02);
    EXPECT_LT(largestMove(cape.positions, all.positions, plain.positions.size()), 1e-12) << "the cape as all of it reads it";
  }
}

TEST(AvatarMeshes, ANameThatIsNoMeshOfTheSkinListsThem) {
  EXPECT_EQ(errorOf([] { (void)readGltfSkinnedModel(clothed(), {"Body", "Hair"}); }),
            clothed() + ": has no node or mesh named 'Hair' (its skinned meshes: Body, Cape)");
  // A mesh of a skin whose joints are apart from the body's (a second character): not read,
  // and an error when named.
  const std::string apart = drape::testing::clothedCesiumMan(drape::testing::processTempDir("avatar-meshes-apart"),
                                                             {.capeSkin = drape::testing::CapeSkin::Apart});
  EXPECT_EQ(readGltfSkinnedModel(apart).meshes, (Names{"Body"}));
  EXPECT_NE(errorOf([&] { (void)readGltfSkinnedModel(apart, {"Cape"}); })
                .find("its mesh 'Cape' is moved by skin 1, whose joints are apart from the first skin's skeleton"),
            std::string::npos);
}

TEST(AvatarMeshes, ShellPatternsChooseMeshesByNodeOrMeshName) {
  EXPECT_EQ(readGltfSkinnedModel(clothed(), {"B*"}).meshesRead, (Names{"Body"}));
  EXPECT_EQ(readGltfSkinnedModel(clothed(), {"*Mesh"}).meshesRead, (Names{"Cape"})) << "by the mesh's name";
  EXPECT_EQ(readGltfSkinnedModel(clothed(), {"[BC]?[dp]?"}).meshesRead, (Names{"Body", "Cape"}));
  EXPECT_EQ(errorOf([] { (void)readGltfSkinnedModel(clothed(), {"Body", "Hair*"}); }),
            clothed() + ": has no node or mesh matching 'Hair*' (its skinned meshes: Body, Cape)");
  // A pattern that matches a second character's mesh does not ask for it: it is left out.
  const std::string apart = drape::testing::clothedCesiumMan(
      drape::testing::processTempDir("avatar-meshes-apart-pattern"), {.capeSkin = drape::testing::CapeSkin::Apart});
  EXPECT_EQ(readGltfSkinnedModel(apart, {"*"}).meshesRead, (Names{"Body"}));
}

TEST(AvatarMeshes, AMeshNoSceneShowsIsNotTheBodys) {
  // The cape's node taken out of the node tree the scene shows: a proxy nothing draws.
  std::ifstream in(clothed());
  nlohmann::json doc = nlohmann::json::parse(in);
  const std::size_t cape = doc["nodes"].size() - 1;
  ASSERT_EQ(doc["nodes"][cape]["name"], "Cape");
  for (nlohmann::json& node : doc["nodes"])
    if (node.contains("children"))
      node["children"].erase(std::remove(node["children"].begin(), node["children"].end(), cape), node["children"].end());
  const std::string path = (std::filesystem::path(clothed()).parent_path() / "proxy.gltf").string();
  std::ofstream(path) << doc.dump();
  const SkinnedModel read = readGltfSkinnedModel(path);
  EXPECT_EQ(read.meshes, (Names{"Body"}));
  EXPECT_EQ(read.triangles, cesiumMan().triangles);
}

TEST(AvatarMeshes, MeshesWithSkinsOfTheirOwnOverOneSkeletonAreOneAvatar) {
  // Unity's and three.js's exporters write a skin per skinned mesh, each listing the joints
  // in its own order: the cape's skin lists the body's joints reversed, its JOINTS_0
  // renumbered to match. The avatar is the same as with one skin, joint for joint and vertex
  // for vertex.
  const SkinnedModel one = readGltfSkinnedModel(clothed());
  for (const auto skin : {drape::testing::CapeSkin::Copy, drape::testing::CapeSkin::Reversed}) {
    SCOPED_TRACE(static_cast<int>(skin));
    const std::string path = drape::testing::clothedCesiumMan(
        drape::testing::processTempDir("avatar-meshes-skin-" + std::to_string(static_cast<int>(skin))), {.capeSkin = skin});
    const SkinnedModel two = readGltfSkinnedModel(path);
    EXPECT_EQ(two.meshes, (Names{"Body", "Cape"}));
    ASSERT_EQ(two.joints.size(), one.joints.size());
    for (std::size_t j = 0; j < one.joints.size(); ++j) {
      EXPECT_EQ(two.joints[j].name, one.joints[j].name);
      EXPECT_EQ(two.joints[j].parent, one.joints[j].parent);
    }
    ASSERT_EQ(two.positions.size(), one.positions.size());
    EXPECT_EQ(two.triangles, one.triangles);
    EXPECT_EQ(two.vertexJoints, one.vertexJoints);
    EXPECT_LT(largestMove(two.positions, one.positions), 1e-9);
    // The file's animation drives every joint of the one skeleton.
    const SkinnedJointMotion motion = readGltfJointMotion(path, 30.0, "");
    EXPECT_EQ(motion.joints.size(), one.joints.size());
  }
}

TEST(AvatarMeshes, ColladaAndFbxChooseTheirMeshesAsGltfDoes) {
  const SkinnedModel& plain = cesiumMan();
  for (const auto& [id, extension] : {std::pair{"collada", ".dae"}, std::pair{"fbxa", ".fbx"}}) {
    SCOPED_TRACE(extension);
    const std::string path = (drape::testing::processTempDir("avatar-meshes") / (std::string("clothed") + extension)).string();
    drape::testing::convertThroughAssimp(clothed(), id, path);
    const SkinnedModel all = readAssimpSkinnedModel(path);
    EXPECT_EQ(all.meshes, (Names{"Body", "Cape"}));
    EXPECT_EQ(all.triangles.size(), 2 * plain.triangles.size());
    const SkinnedModel body = readAssimpSkinnedModel(path, {"Body"});
    EXPECT_EQ(body.meshesRead, (Names{"Body"}));
    EXPECT_EQ(body.triangles.size(), plain.triangles.size());
    EXPECT_EQ(body.joints.size(), all.joints.size()) << "the skeleton is every skinned mesh's";
    const SkinnedModel cape = readAssimpSkinnedModel(path, {"Cape"});
    EXPECT_EQ(cape.meshesRead, (Names{"Cape"}));
    EXPECT_EQ(cape.triangles.size(), plain.triangles.size());
    EXPECT_NE(errorOf([&] { (void)readAssimpSkinnedModel(path, {"Hair"}); }).find("(its skinned meshes: Body, Cape)"),
              std::string::npos);
  }
}

}  // namespace
}  // namespace drape::formats
