// `drape run` of garments worn over garments (ClothSet over, overGap): the bundled skirt
// over its petticoat on the walk stays over it, where without `over` the petticoat comes
// out through the skirt; the petticoat does not feel the skirt (its cache is the one it has
// alone, to the byte); the run's stats.json says how. Without a character, a sheet worn over
// a pinned one comes to rest one gap above it.
//
// Measured here independently of drape's code: from each point of the skirt, a horizontal
// ray out from the petticoat's axis crosses the petticoat an odd number of times when the
// point lies inside it.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/pc2.hpp"

namespace drape::testing {
namespace {

const std::string kLayeredDir = std::string(DRAPE_SOURCE_DIR) + "/examples/layered_skirts";

/// The example's scene with its avatar's URL made absolute (for a copy in a scratch
/// directory), each of `cuts` taken out.
std::string layeredScene(const std::vector<std::string>& cuts) {
  std::string scene = exampleSceneWithDataFound(kLayeredDir + "/scene.wrl");
  for (const std::string& cut : cuts) replaceOnce(scene, cut, "");
  return scene;
}

/// Whether the ray from o along d (d.y = 0) crosses the triangle (Moller-Trumbore).
bool crosses(const Vec3& o, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e1 = b - a, e2 = c - a, p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-14) return false;
  const Vec3 s = o - a;
  const double u = s.dot(p) / det;
  if (u < 0 || u > 1) return false;
  const Vec3 q = s.cross(e1);
  const double v = d.dot(q) / det;
  if (v < 0 || u + v > 1) return false;
  return e2.dot(q) / det > 0;
}

/// Of `points`, how many lie inside the tube `tube` (the petticoat at one frame): a
/// horizontal ray from the point away from the tube's axis crosses it an odd number of times.
int insideTube(const std::vector<Vec3>& points, const std::vector<Vec3>& tube,
               const std::vector<mesh::Triangle>& triangles) {
  Vec3 axis = Vec3::Zero();
  for (const Vec3& p : tube) axis += p;
  axis /= static_cast<double>(tube.size());
  int inside = 0;
  for (const Vec3& p : points) {
    Vec3 out(p.x() - axis.x(), 0, p.z() - axis.z());
    if (out.norm() < 1e-6) continue;
    out.normalize();
    int crossings = 0;
    for (const mesh::Triangle& t : triangles) crossings += crosses(p, out, tube[t[0]], tube[t[1]], tube[t[2]]);
    inside += crossings % 2;
  }
  return inside;
}

/// Skirt points inside the petticoat, summed over frames 30, 40, ... of run `out`.
int skirtInsidePetticoat(const std::string& out) {
  const formats::Pc2Cache petticoat = formats::readPc2(out + "/garment-Petticoat.pc2");
  const formats::Pc2Cache skirt = formats::readPc2(out + "/garment-Skirt.pc2");
  const mesh::TriMesh rest = formats::readObj(out + "/garment-Petticoat.obj");
  int inside = 0;
  for (std::size_t f = 30; f < std::min(petticoat.frames.size(), skirt.frames.size()); f += 10)
    inside += insideTube(skirt.frames[f], petticoat.frames[f], rest.triangles);
  return inside;
}

TEST(WornOver, TheSkirtStaysOverThePetticoatWhichDoesNotFeelIt) {
  const ScratchDir dir("worn-over");
  const std::string walk = " --motion '" + kSkirtDir + "/walk.bvh' --frames 90";
  const CliResult r = runDrape("run '" + kLayeredDir + "/scene.wrl'" + walk + " --out '" + (dir / "over") + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("Skirt: kept 4 mm over Petticoat"), std::string::npos) << r.err;
  const nlohmann::json stats = statsOf(dir / "over");
  ASSERT_EQ(stats["garments"].size(), 2u);
  EXPECT_FALSE(stats["garments"][0].contains("worn_over"));
  const nlohmann::json& over = stats["garments"][1]["worn_over"];
  EXPECT_EQ(over["garments"], nlohmann::json::array({"Petticoat"}));
  EXPECT_NEAR(over["gap_m"].get<double>(), 0.004, 1e-9);
  EXPECT_GT(over["contacts"].get<long>(), 1000);
  EXPECT_LE(over["crossings"].get<long>(), over["contacts"].get<long>() / 1000);  // found through, put back
  EXPECT_FALSE(stats["garments"][1].contains("self_collision"));  // its own layers: not asked for
  EXPECT_EQ(stats["vertex_substeps_inside_body"].get<long>(), 0);

  // One way: the petticoat moves as it does alone, to the byte.
  std::string alone = layeredScene({});
  alone.erase(alone.find("DEF Skirt ClothSet"));
  { std::ofstream(dir / "alone.wrl") << alone; }
  const CliResult single = runDrape("run '" + (dir / "alone.wrl") + "'" + walk + " --out '" + (dir / "alone") + "'", dir);
  ASSERT_EQ(single.code, 0) << single.err;
  EXPECT_EQ(slurp(dir / "alone/garment.pc2"), slurp(dir / "over/garment-Petticoat.pc2"));

  // Without `over` the petticoat comes out through the skirt; with it, nowhere.
  { std::ofstream(dir / "through.wrl") << layeredScene({"  over [ \"Petticoat\" ]\n"}); }
  const CliResult through =
      runDrape("run '" + (dir / "through.wrl") + "'" + walk + " --out '" + (dir / "through") + "'", dir);
  ASSERT_EQ(through.code, 0) << through.err;
  EXPECT_FALSE(statsOf(dir / "through")["garments"][1].contains("worn_over"));
  const int withOver = skirtInsidePetticoat(dir / "over"), without = skirtInsidePetticoat(dir / "through");
  EXPECT_EQ(withOver, 0);
  EXPECT_GT(without, 100) << "the skirt's points inside the petticoat in 7 frames";

  // A cloth-server steps a garment with the garments it is worn over.
  const CliResult server =
      runDrape("cloth-server '" + kLayeredDir + "/scene.wrl' --garments Skirt --server nats://127.0.0.1:1", dir);
  EXPECT_EQ(server.code, 2) << server.err;
  EXPECT_NE(server.err.find("--garments: 'Skirt' is worn over 'Petticoat' (its over): give both, as in --garments "
                            "Petticoat,Skirt"),
            std::string::npos)
      << server.err;

  const CliResult inspected = runDrape("inspect '" + kLayeredDir + "/scene.wrl'", dir);
  ASSERT_EQ(inspected.code, 0) << inspected.err;
  EXPECT_NE(inspected.out.find("worn 4 mm over Petticoat (over, overGap; stepped after it)"), std::string::npos)
      << inspected.out;
  // The run says what the layer collision did, as its stats.json counts it.
  const CliResult run = runDrape("inspect '" + (dir / "over") + "'", dir);
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_NE(run.out.find(fmt::format("  Skirt          worn over Petticoat, kept above by 4 mm: {} contacts at {} "
                                     "tests, {} of them crossed through and put back",
                                     over["contacts"].get<long>(), over["tests"].get<long>(),
                                     over["crossings"].get<long>())),
            std::string::npos)
      << run.out;
}

/// A 0.4 m square pinned flat at y = 0 ("Table", its constraint mask with no avatar to bind
/// to) and a free 0.24 m square of 5 x 5 points 3 cm above it, or at `clothHeight(point)`
/// ("Cloth"), `clothFields` in its ClothSet.
std::string tableScene(const std::string& clothFields,
                       const std::function<double(int)>& clothHeight = [](int) { return 0.03; }) {
  const auto grid = [](int n, double size, const std::function<double(int)>& y) {
    std::string points, quads;
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i)
        points += fmt::format("{} {} {}, ", size * (double(i) / n - 0.5), y(j * (n + 1) + i), size * (double(j) / n - 0.5));
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const int a = j * (n + 1) + i;
        quads += fmt::format("{} {} {} {} -1, ", a, a + n + 1, a + n + 2, a + 1);
      }
    return fmt::format("IndexedFaceSet {{ coord Coordinate {{ point [ {} ] }} coordIndex [ {} ] }}", points, quads);
  };
  const std::string table = grid(7, 0.4, [](int) { return 0.0; });
  return fmt::format(
      "#VRML V2.0 utf8\n"
      "Simulation {{ frameRate 30 stepsPerFrame 40 }}\n"
      "DEF Knit ClothMaterial {{ youngsModulus 50000 damping 0.0001 }}\n"
      "DEF Table ClothSet {{ material USE Knit cloth {} constraintMask {} }}\n"
      "DEF Cloth ClothSet {{ material USE Knit {} cloth {} }}\n",
      table, table, clothFields, grid(4, 0.24, clothHeight));
}

/// The heights of the points in a run's OBJ frame.
std::vector<double> heightsIn(const std::string& objPath) {
  std::vector<double> heights;
  for (const Vec3& p : formats::readObj(objPath).positions) heights.push_back(p.y());
  return heights;
}

TEST(WornOver, WithoutACharacterASheetOverAPinnedOneRestsOneGapAboveIt) {
  const ScratchDir dir("worn-over-table");
  { std::ofstream(dir / "over.wrl") << tableScene("over [ \"Table\" ] overGap 0.005"); }
  const CliResult r = runDrape("run '" + (dir / "over.wrl") + "' --frames 24 --out '" + (dir / "over") + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("Cloth: kept 5 mm over Table"), std::string::npos) << r.err;
  const std::vector<double> rests = heightsIn(dir / "over/frames/garment-Cloth_00024.obj");
  ASSERT_EQ(rests.size(), 25u);
  EXPECT_NEAR(*std::min_element(rests.begin(), rests.end()), 0.005, 0.0005);
  EXPECT_NEAR(*std::max_element(rests.begin(), rests.end()), 0.005, 0.0005);
  EXPECT_GT(statsOf(dir / "over")["garments"][1]["worn_over"]["contacts"].get<long>(), 0);

  { std::ofstream(dir / "through.wrl") << tableScene(""); }
  const CliResult through =
      runDrape("run '" + (dir / "through.wrl") + "' --frames 24 --out '" + (dir / "through") + "'", dir);
  ASSERT_EQ(through.code, 0) << through.err;
  const std::vector<double> fallen = heightsIn(dir / "through/frames/garment-Cloth_00024.obj");
  ASSERT_FALSE(fallen.empty());
  EXPECT_LT(*std::max_element(fallen.begin(), fallen.end()), -0.1);
}

TEST(WornOver, AGarmentModelledPartlyUnderTheOneItIsWornOverIsMovedOutOverIt) {
  // The cloth modelled 8 mm over the table but for its middle row, 4 mm under it.
  const ScratchDir dir("worn-over-under");
  const auto middleRowUnder = [](int point) { return point / 5 == 2 ? -0.004 : 0.008; };
  const std::string scene = tableScene("over [ \"Table\" ]", middleRowUnder);
  { std::ofstream(dir / "under.wrl") << scene; }
  const CliResult r = runDrape("run '" + (dir / "under.wrl") + "' --frames 24 --out '" + (dir / "under") + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("Cloth: 5 of its 25 vertices near Table were modelled under it (the deepest, vertex 10, 4.0 "
                       "mm): 5 moved out over it, 4 mm above"),
            std::string::npos)
      << r.err;
  const nlohmann::json over = statsOf(dir / "under")["garments"][1]["worn_over"];
  EXPECT_EQ(over["vertices_starting_under"].get<long>(), 5);
  EXPECT_EQ(over["vertices_lifted_over"].get<long>(), 5);
  EXPECT_EQ(over["vertices_left_under"].get<long>(), 0);
  // The whole cloth rests on the table, one gap above it.
  const std::vector<double> heights = heightsIn(dir / "under/frames/garment-Cloth_00024.obj");
  ASSERT_EQ(heights.size(), 25u);
  for (int point = 0; point < 25; ++point) EXPECT_NEAR(heights[point], 0.004, 0.0004) << "point " << point;

  // A table whose faces are not all wound one way cannot say which side is over: the row is
  // left under it, which the run says, and there it stays.
  std::string mixed = scene;
  replaceOnce(mixed, "0 8 9 1 -1", "1 9 8 0 -1");
  { std::ofstream(dir / "mixed.wrl") << mixed; }
  const CliResult m = runDrape("run '" + (dir / "mixed.wrl") + "' --frames 24 --out '" + (dir / "mixed") + "'", dir);
  ASSERT_EQ(m.code, 0) << m.err;
  EXPECT_NE(m.err.find("Cloth: 5 of its 25 vertices over Table start under it, on the other side from the rest (the "
                       "deepest, vertex 10, 4.0 mm), and the faces of Table are not all wound one way"),
            std::string::npos)
      << m.err;
  EXPECT_EQ(statsOf(dir / "mixed")["garments"][1]["worn_over"]["vertices_lifted_over"].get<long>(), 0);
  EXPECT_EQ(statsOf(dir / "mixed")["garments"][1]["worn_over"]["vertices_left_under"].get<long>(), 5);
  const std::vector<double> kept = heightsIn(dir / "mixed/frames/garment-Cloth_00024.obj");
  ASSERT_EQ(kept.size(), 25u);
  for (int point = 0; point < 25; ++point)
    EXPECT_EQ(kept[point] < 0, point / 5 == 2) << "point " << point << " at " << kept[point];

  // Modelled over it, no word of it.
  { std::ofstream(dir / "over.wrl") << tableScene("over [ \"Table\" ]", [](int) { return 0.008; }); }
  const CliResult clean = runDrape("run '" + (dir / "over.wrl") + "' --frames 2 --out '" + (dir / "over") + "'", dir);
  ASSERT_EQ(clean.code, 0) << clean.err;
  EXPECT_EQ(clean.err.find("modelled under"), std::string::npos) << clean.err;
  EXPECT_EQ(statsOf(dir / "over")["garments"][1]["worn_over"]["vertices_starting_under"].get<long>(), 0);
}

}  // namespace
}  // namespace drape::testing
