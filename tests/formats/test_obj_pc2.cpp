#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "drape/core/error.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/pc2.hpp"
#include "drape/formats/units.hpp"
#include "drape/mesh/topology.hpp"
#include "drape/testing/errors.hpp"
#include "drape/testing/temp_dir.hpp"

namespace drape::formats {
namespace {

std::string tempPath(const std::string& name) {
  return (testing::processTempDir("formats") / name).string();
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

TEST(Obj, GroupsAreChosenByNameOrShellPatternAndOneThatIsNotThereIsAnError) {
  const std::string path = std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_base_hm08.obj";
  auto triangles = [&](const std::vector<std::string>& groups) {
    ObjReadOptions options;
    options.groups = groups;
    options.keepUnusedVertices = false;
    return readObj(path, options).triangles.size();
  };
  const std::size_t body = triangles({"body"}), tights = triangles({"helper-tights"});
  EXPECT_EQ(triangles({"b?dy"}), body);
  EXPECT_EQ(triangles({"helper-ti*"}), tights);
  EXPECT_EQ(triangles({"helper-t*"}), tights + triangles({"helper-tongue"}));
  EXPECT_EQ(triangles({"[bh]*", "joint-*"}) - triangles({"joint-*"}), triangles({"body", "helper-*"}));
  // The groups a pattern matched are what was read, in the file's order.
  std::vector<std::string> read;
  ObjReadOptions byPattern;
  byPattern.groups = {"helper-t*", "b?dy"};
  (void)readObj(path, byPattern, &read);
  EXPECT_EQ(read, (std::vector<std::string>{"body", "helper-tights", "helper-tongue"}));
  const std::string missing = drape::testing::errorOf([&] { (void)triangles({"body", "bdoy"}); });
  EXPECT_EQ(
      missing.rfind(path + ": has no g/o group named 'bdoy' (its groups: body, helper-tights, joint-l-eye, "
                           "joint-r-eye, joint-pelvis, joint-spine-4, joint-spine-3, joint-spine-2, joint-spine-1, "
                           "joint-l-foot-2, joint-l-foot-1, joint-l-toe-5-3, ... ",
                    0),
      0u)
      << missing;
  EXPECT_EQ(missing.substr(missing.size() - 8), " in all)") << missing;
  const std::string unmatched = drape::testing::errorOf([&] { (void)triangles({"hair*"}); });
  EXPECT_NE(unmatched.find(": has no g/o group matching 'hair*' (its groups: body,"), std::string::npos) << unmatched;
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


using drape::testing::errorOf;
using drape::testing::expectCorpus;

// tinyobjloader reads "nan" as 0 and 1e999 as infinity without a word; drape names the spot.
TEST(Obj, MalformedCorpus) {
  expectCorpus(std::string(DRAPE_TEST_DATA_DIR) + "/bad/mesh", {
      {"obj_nan_coordinate.obj", "2:5: expected a number for the vertex's y coordinate, found 'nan'"},
      {"obj_overflow_coordinate.obj", "4:7: expected a number for the vertex's z coordinate, found '1e999'"},
      {"obj_two_coordinates.obj", "2:6: expected 3 coordinates (x y z) on a vertex line, found 2"},
      {"obj_face_out_of_range.obj", " a face in group '' refers to vertex 7 but the file has 3 vertices"},
      {"obj_zero_index.obj", " Failed parse `f' line(e.g. zero value for face index. line 4.)"},
  }, [](const std::string& path) { (void)readObj(path); });
}

TEST(Obj, ParseObjMatchesReadObj) {
  const std::string path = std::string(DRAPE_DATA_DIR) + "/garments/makehuman_female_elegantsuit01_dress.obj";
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const mesh::TriMesh parsed = parseObj(text, path, {});
  const mesh::TriMesh read = readObj(path);
  EXPECT_EQ(parsed.positions, read.positions);
  EXPECT_EQ(parsed.triangles, read.triangles);
  EXPECT_EQ(errorOf([] { (void)parseObj("v 0 0 0\r\nv 1 0 inf\r\n", "crlf.obj", {}); }),
            "crlf.obj:2:7: expected a number for the vertex's z coordinate, found 'inf'");
  // Comments after the coordinates and tabs stay valid, as tinyobjloader reads them.
  EXPECT_EQ(parseObj("v 0 0 0 # origin\nv\t1 0 0\nv 0 1 0\nf 1 2 3\n", "ok.obj", {}).triangles.size(), 1u);
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

TEST(Pc2, MalformedCorpus) {
  expectCorpus(std::string(DRAPE_TEST_DATA_DIR) + "/bad/cache", {
      {"pc2_nan_coordinate.pc2", " sample 1 point 1 has a non-finite coordinate (byte 68)"},
      // 2^31 samples of nothing: 48 GB of empty frames before this check.
      {"pc2_zero_points.pc2", " the header promises 2147483647 samples of 0 points, expected at least 1 point"},
      // 12 x 716165683 x 2146470725 bytes wraps to 10,484 in 64 bits: the size check passed
      // and 8.6 GB were allocated for one sample.
      {"pc2_size_overflow.pc2",
       " truncated: the header promises 2146470725 samples of 716165683 points (18446744073709562132 bytes), the file has 10516"},
      {"pc2_zero_rate.pc2", " the sample rate 0 is not a finite number > 0"},
      {"pc2_truncated.pc2", " truncated: the header promises 2 samples of 3 points (104 bytes), the file has 68"},
  }, [](const std::string& path) { (void)readPc2(path); });
  EXPECT_EQ(errorOf([] { (void)parsePc2("POINTCACHE2", "short.pc2"); }),
            "short.pc2: not a PC2 point cache (expected the POINTCACHE2 header, version 1)");
}

TEST(Units, KnownAndUnknown) {
  EXPECT_DOUBLE_EQ(metresPerUnit("cm"), 0.01);
  EXPECT_DOUBLE_EQ(metresPerUnit("in"), 0.0254);
  EXPECT_THROW((void)metresPerUnit("furlong"), Error);
}

}  // namespace
}  // namespace drape::formats
