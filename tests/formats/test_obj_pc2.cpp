#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "drape/core/error.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/pc2.hpp"
#include "drape/formats/units.hpp"
#include "drape/mesh/topology.hpp"

namespace drape::formats {
namespace {

std::string tempPath(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("drape_test_formats_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

TEST(Obj, ReadsTheMakeHumanDressInDecimetres) {
  const std::string path = std::string(DRAPE_DATA_DIR) + "/garments/makehuman_female_elegantsuit01_dress.obj";
  ObjReadOptions options;
  options.metresPerUnit = metresPerUnit("dm");
  const mesh::TriMesh m = readObj(path, options);
  EXPECT_EQ(m.positions.size(), 2205u);
  EXPECT_EQ(m.triangles.size(), 4192u);
  const Aabb box = m.bounds();
  EXPECT_NEAR(box.min.y(), -0.299, 0.002);
  EXPECT_NEAR(box.max.y(), 0.562, 0.002);
  const mesh::Topology t = mesh::Topology::build(m);
  EXPECT_EQ(t.boundaryLoops.size(), 5u);  // hem, waist seam, neckline, two sleeves
}

TEST(Obj, KeepsOnlyRequestedGroups) {
  const std::string path = std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_base_hm08.obj";
  ObjReadOptions options;
  options.groups = {"body"};
  options.keepUnusedVertices = false;
  const mesh::TriMesh m = readObj(path, options);
  EXPECT_EQ(m.triangles.size(), 13378u * 2);
  EXPECT_LE(m.positions.size(), 13380u);
}

TEST(Obj, ClearErrors) {
  EXPECT_THROW((void)readObj("/nonexistent/garment.obj"), Error);
  const std::string path = tempPath("bad.obj");
  std::ofstream(path) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n";
  try {
    (void)readObj(path);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  std::ofstream(path) << "# nothing\n";
  EXPECT_THROW((void)readObj(path), Error);
}

TEST(Obj, WriteThenReadRoundTrips) {
  const std::vector<Vec3> p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0.25}};
  const std::vector<mesh::Triangle> t = {{0, 1, 2}};
  const std::string path = tempPath("tri.obj");
  writeObj(path, p, t, "test");
  const mesh::TriMesh m = readObj(path);
  ASSERT_EQ(m.positions.size(), 3u);
  EXPECT_NEAR((m.positions[2] - p[2]).norm(), 0, 1e-6);
  EXPECT_EQ(m.triangles[0], t[0]);
}

TEST(Pc2, WriteThenReadRoundTrips) {
  const std::string path = tempPath("cache.pc2");
  {
    Pc2Writer w(path, 2, 0.0, 1.0);
    for (int f = 0; f < 5; ++f) {
      const std::vector<Vec3> frame = {{double(f), 0, 0}, {0, double(f) * 0.5, -1}};
      w.writeFrame(frame);
    }
  }
  const Pc2Cache c = readPc2(path);
  EXPECT_EQ(c.pointCount, 2u);
  ASSERT_EQ(c.frames.size(), 5u);
  EXPECT_EQ(c.frames[4][0], Vec3(4, 0, 0));
  EXPECT_EQ(c.frames[3][1], Vec3(0, 1.5, -1));
  EXPECT_EQ(std::filesystem::file_size(path), 32u + 5 * 2 * 12);
}

TEST(Pc2, RejectsTruncatedFiles) {
  const std::string path = tempPath("short.pc2");
  {
    Pc2Writer w(path, 3);
    w.writeFrame(std::vector<Vec3>(3, Vec3::Zero()));
  }
  std::filesystem::resize_file(path, 40);
  EXPECT_THROW((void)readPc2(path), Error);
}

TEST(Units, KnownAndUnknown) {
  EXPECT_DOUBLE_EQ(metresPerUnit("cm"), 0.01);
  EXPECT_DOUBLE_EQ(metresPerUnit("in"), 0.0254);
  EXPECT_THROW((void)metresPerUnit("furlong"), Error);
}

}  // namespace
}  // namespace drape::formats
