// `drape convert AVATAR --to avatar.wrl` and back through drape's own VRML97 reader: the
// segmented H-Anim humanoid keeps its joints, segments and geometry.

#include <gtest/gtest.h>

#include "cli_runner.hpp"
#include "drape/scene/scene.hpp"

namespace drape {
namespace {

using testing::CliResult;
using testing::runDrape;
using testing::ScratchDir;

struct Expected {
  const char* file;
  std::size_t joints;
  std::size_t segments;
};

class ConvertRoundTrip : public ::testing::TestWithParam<Expected> {};

TEST_P(ConvertRoundTrip, ReadsBackWithTheSameJointsAndSegments) {
  const Expected e = GetParam();
  ScratchDir dir("convert-roundtrip");
  const std::string wrl = dir / "avatar.wrl";
  const CliResult r = runDrape("convert '" + std::string(DRAPE_DATA_DIR) + "/avatars/" + e.file + "' --to '" + wrl + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const scene::Scene back = scene::loadScene(wrl);
  ASSERT_EQ(back.avatars.size(), 1u);
  const scene::Avatar& a = back.avatars[0];
  EXPECT_EQ(a.joints.size(), e.joints);
  EXPECT_EQ(a.segments.size(), e.segments);
  std::size_t triangles = 0;
  for (const scene::Segment& s : a.segments) triangles += s.mesh.triangleCount();
  EXPECT_GT(triangles, 1000u);
  // The body stands on its feet at human height.
  Aabb box;
  for (const scene::Segment& s : a.segments)
    for (const Vec3& p : s.mesh.positions) box.extend(a.joints[static_cast<std::size_t>(s.joint)].restWorld().apply(p));
  EXPECT_GT(box.size().y(), 1.3);
  EXPECT_LT(box.size().y(), 2.0);
}

INSTANTIATE_TEST_SUITE_P(Avatars, ConvertRoundTrip,
                         ::testing::Values(Expected{"CesiumMan.glb", 19, 19},
                                           Expected{"makehuman_rig_cmu_mb.mhskel", 31, 31}),
                         [](const auto& info) { return std::string(info.param.joints == 19 ? "CesiumMan" : "MakeHuman"); });

}  // namespace
}  // namespace drape
