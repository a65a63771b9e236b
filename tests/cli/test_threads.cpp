// `drape --threads N`: a garment large enough to split its forces and collision tests over
// threads (1,600 vertices, 3,072 triangles, made by `drape make-skirt`) walks the bundled
// motion with one thread and with two; the caches and the collision figures must agree to
// the bit. The option's bounds are checked like any other.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"

namespace drape {
namespace {

using namespace testing;  // the CLI runner's helpers

TEST(Threads, ALargeGarmentRunsTheSameWithOneThreadAndWithTwo) {
  ScratchDir dir("threads");
  const std::string made = dir / "fine";
  const CliResult make = runDrape("make-skirt '" + std::string(DRAPE_DATA_DIR) +
                                      "/avatars/makehuman_rig_cmu_mb.mhskel' --around 64 --rings 24 --out '" + made +
                                      "'",
                                  dir);
  ASSERT_EQ(make.code, 0) << make.err;
  ASSERT_NE(make.out.find("1600 vertices, 3072 triangles"), std::string::npos) << make.out;
  const auto runWith = [&](int threads) {
    const std::string out = dir / ("run" + std::to_string(threads));
    const CliResult r = runDrape("--threads " + std::to_string(threads) + " run '" + made + "/scene.wrl' --motion '" +
                                     kSkirtDir + "/walk.bvh' --lead-in 0.1 --frames 12 --every 12 --face-samples-with LeftUpLeg,RightUpLeg --out '" +
                                     out + "'",
                                 dir);
    EXPECT_EQ(r.code, 0) << r.err;
    return out;
  };
  const std::string one = runWith(1), two = runWith(2);
  const std::string cache = slurp(one + "/garment.pc2");
  ASSERT_GT(cache.size(), 1600u * 12 * 12);
  EXPECT_TRUE(cache == slurp(two + "/garment.pc2"));
  EXPECT_TRUE(slurp(one + "/garment.states") == slurp(two + "/garment.states"));
  const nlohmann::json a = statsOf(one), b = statsOf(two);
  for (const char* key : {"collisions_registered", "vertex_substeps", "vertex_substeps_below_T1",
                          "vertex_substeps_below_T1_pinched", "vertex_substeps_inside_body",
                          "mean_collision_path_voxels", "max_penetration_m", "max_strain", "max_stretch",
                          "max_compression", "vertex_tests_pinched", "crease_moves", "crease_moves_refused", "face_tests",
                          "face_contacts"})
    EXPECT_EQ(a[key], b[key]) << key;
  // The walk must reach the body: what is compared includes collisions.
  EXPECT_GT(a["collisions_registered"].get<long>(), 0);
  // ... and the face samples, whose parts each range marks (FieldCollider::markSlidingParts).
  EXPECT_GT(a["face_contacts"].get<long>(), 0);
}

TEST(Threads, TheCountIsChecked) {
  ScratchDir dir("threads-bad");
  for (const char* bad : {"0", "-2", "many"}) {
    const CliResult r = runDrape(std::string("--threads ") + bad + " inspect '" + kSkirtDir + "/walk.bvh'", dir);
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_NE(r.err.find("--threads"), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace drape
