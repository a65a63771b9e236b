// Collada and FBX skinned characters as segmented avatars: CesiumMan, read by drape's glTF
// reader, written through Assimp's exporters and read back through its importers, keeps
// its skeleton, its triangles and its 19 closed segments (mirrors test_avatar_gltf.cpp).

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <map>
#include <unistd.h>

#include "drape/core/error.hpp"
#include "drape/formats/assimp_avatar.hpp"
#include "drape/formats/gltf_avatar.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/scene/avatar_segment.hpp"

namespace drape::scene {
namespace {

std::string data(const std::string& file) { return std::string(DRAPE_DATA_DIR) + "/avatars/" + file; }

struct ScratchDir {
  std::filesystem::path path = std::filesystem::temp_directory_path() / ("drape-avatar-assimp-" + std::to_string(::getpid()));
  ScratchDir() { std::filesystem::create_directories(path); }
  ~ScratchDir() { std::filesystem::remove_all(path); }
};

// Joint name -> parent's name ("" for a root).
std::map<std::string, std::string> hierarchy(const formats::SkinnedModel& m) {
  std::map<std::string, std::string> out;
  for (const formats::SkinnedJoint& j : m.joints)
    out[j.name] = j.parent < 0 ? "" : m.joints[static_cast<std::size_t>(j.parent)].name;
  return out;
}

class CesiumManThroughAssimp : public ::testing::TestWithParam<const char*> {};

TEST_P(CesiumManThroughAssimp, KeepsSkeletonTrianglesAndSegments) {
  const formats::SkinnedModel original = formats::readGltfSkinnedModel(data("CesiumMan.glb"));
  ASSERT_EQ(original.joints.size(), 19u);
  const ScratchDir dir;
  const std::string file = (dir.path / (std::string("CesiumMan") + GetParam())).string();
  formats::writeAssimpSkinnedModel(file, original);
  const formats::SkinnedModel back = formats::readAssimpSkinnedModel(file);

  EXPECT_EQ(hierarchy(back), hierarchy(original));
  ASSERT_EQ(back.triangles.size(), original.triangles.size());
  // Vertices the writer left apart only for UVs are joined on the way back, so compare
  // the triangles' corners (faces keep their order) rather than vertex indices.
  double worst = 0.0;
  for (std::size_t t = 0; t < back.triangles.size(); ++t)
    for (std::size_t c = 0; c < 3; ++c)
      worst = std::max(worst, (back.positions[back.triangles[t][c]] - original.positions[original.triangles[t][c]]).norm());
  EXPECT_LT(worst, 1e-4) << "m";
  for (std::size_t j = 0; j < back.joints.size(); ++j) {
    const int o = [&] {
      for (std::size_t k = 0; k < original.joints.size(); ++k)
        if (original.joints[k].name == back.joints[j].name) return static_cast<int>(k);
      return -1;
    }();
    ASSERT_GE(o, 0);
    EXPECT_LT((back.joints[j].restWorld.block<3, 1>(0, 3) - original.joints[static_cast<std::size_t>(o)].restWorld.block<3, 1>(0, 3)).norm(), 1e-4)
        << back.joints[j].name;
  }

  const Avatar a = buildAvatarFromSkinnedModel(back);
  ASSERT_EQ(a.joints.size(), 19u);
  EXPECT_EQ(a.segments.size(), 19u);
  for (const Segment& s : a.segments) EXPECT_EQ(countBoundaryEdges(s.mesh), 0u) << s.name;
  Avatar copy = a;
  const std::vector<int> segmentOf = segmentSkinnedAvatar(copy);
  ASSERT_EQ(segmentOf.size(), original.triangles.size());
  for (std::size_t t = 0; t < segmentOf.size(); ++t) EXPECT_GE(segmentOf[t], 0) << "triangle " << t;
  const Aabb box = a.skin->mesh.bounds();
  EXPECT_NEAR(box.size().y(), 1.5, 0.05);
  EXPECT_NEAR(box.min.y(), 0.0, 0.02);
}

INSTANTIATE_TEST_SUITE_P(Formats, CesiumManThroughAssimp, ::testing::Values(".dae", ".fbx"),
                         [](const auto& info) { return std::string(info.param + 1); });

TEST(AssimpAvatar, LoadAvatarFileTakesColladaAndFbx) {
  const Avatar a = loadAvatarFile(std::string(DRAPE_TEST_DATA_DIR) + "/avatars/tube_two_joints.dae");
  EXPECT_EQ(a.joints.size(), 2u);
  EXPECT_EQ(a.segments.size(), 2u);
  for (const Segment& s : a.segments) EXPECT_EQ(countBoundaryEdges(s.mesh), 0u) << s.name;
}

TEST(AssimpAvatar, AvatarWithoutSkinCannotBeWritten) {
  Avatar a;
  a.source = "hanim.wrl";
  try {
    (void)skinnedModelOf(a);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "hanim.wrl: the avatar has no skinned mesh to write");
  }
}

}  // namespace
}  // namespace drape::scene
