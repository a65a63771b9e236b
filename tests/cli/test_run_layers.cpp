// `drape run` of a garment whose layers meet: a scene's selfCollision and --self-collision
// keep them apart, the run's stats.json says how, and without them the layers pass through.

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"

namespace drape::testing {
namespace {

/// An n x n grid of `size` m in the xz plane at height y, centred on the origin: "x y z"
/// points and quads (0-based, -1 ended) starting at vertex `first`.
void layerGrid(int n, double size, double y, int first, std::string& points, std::string& quads) {
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      points += fmt::format("{} {} {}, ", size * (double(i) / n - 0.5), y, size * (double(j) / n - 0.5));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = first + j * (n + 1) + i;
      quads += fmt::format("{} {} {} {} -1, ", a, a + n + 1, a + n + 2, a + 1);
    }
}

constexpr int kLowerCells = 6, kUpperCells = 4;
constexpr int kLowerVertices = (kLowerCells + 1) * (kLowerCells + 1);

/// A scene of one garment in two layers: a 0.4 m square pinned flat at y = 0 (its constraint
/// mask, with no avatar to bind to) and a 0.24 m square 3 cm above it, free to fall on it.
std::string layersScene(const std::string& selfCollision) {
  std::string points, quads, maskPoints, maskQuads;
  layerGrid(kLowerCells, 0.4, 0.0, 0, points, quads);
  layerGrid(kUpperCells, 0.24, 0.03, kLowerVertices, points, quads);
  layerGrid(kLowerCells, 0.4, 0.0, 0, maskPoints, maskQuads);
  return fmt::format(
      "#VRML V2.0 utf8\n"
      "Simulation {{ frameRate 30 stepsPerFrame 40 }}\n"
      "ClothSet {{\n"
      "  name \"layers\"\n"
      "  {}\n"
      "  material ClothMaterial {{ youngsModulus 50000 damping 0.0001 }}\n"
      "  cloth IndexedFaceSet {{ coord Coordinate {{ point [ {} ] }} coordIndex [ {} ] }}\n"
      "  constraintMask IndexedFaceSet {{ coord Coordinate {{ point [ {} ] }} coordIndex [ {} ] }}\n"
      "}}\n",
      selfCollision, points, quads, maskPoints, maskQuads);
}

/// The heights of the upper layer's vertices in an OBJ frame.
std::vector<double> upperHeights(const std::string& objPath) {
  std::ifstream in(objPath);
  std::vector<double> heights;
  std::string line;
  int vertex = 0;
  while (std::getline(in, line)) {
    if (line.rfind("v ", 0) != 0) continue;
    std::istringstream fields(line.substr(2));
    double x = 0, y = 0, z = 0;
    fields >> x >> y >> z;
    if (vertex++ >= kLowerVertices) heights.push_back(y);
  }
  return heights;
}

TEST(RunLayers, ASceneKeepsItsLayersOneThicknessApartAndSaysSo) {
  const ScratchDir dir("run-layers");
  { std::ofstream(dir / "layers.wrl") << layersScene("selfCollision 0.004"); }
  const CliResult r = runDrape("run '" + (dir / "layers.wrl") + "' --frames 24 --out '" + (dir / "kept") + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("layers: its layers kept 4 mm apart"), std::string::npos) << r.err;
  const nlohmann::json stats = nlohmann::json::parse(slurp(dir / "kept/stats.json"));
  const nlohmann::json& self = stats["garments"][0]["self_collision"];
  EXPECT_NEAR(self["thickness_m"].get<double>(), 0.004, 1e-9);  // an SFFloat
  EXPECT_GT(self["contacts"].get<long>(), 0);
  EXPECT_LT(self["crossings"].get<long>(), self["contacts"].get<long>() / 1000 + 1);  // found through, put back
  EXPECT_GT(self["tests"].get<long>(), 0);
  // The upper layer lies on the lower, 4 mm above it, at the end.
  const std::vector<double> kept = upperHeights(dir / "kept/frames/frame_00024.obj");
  ASSERT_EQ(kept.size(), std::size_t((kUpperCells + 1) * (kUpperCells + 1)));
  EXPECT_NEAR(*std::min_element(kept.begin(), kept.end()), 0.004, 0.0004);
  EXPECT_NEAR(*std::max_element(kept.begin(), kept.end()), 0.004, 0.0004);

  const CliResult inspected = runDrape("inspect '" + (dir / "layers.wrl") + "'", dir);
  ASSERT_EQ(inspected.code, 0) << inspected.err;
  EXPECT_NE(inspected.out.find("its own layers kept 4 mm apart (selfCollision)"), std::string::npos) << inspected.out;
  const CliResult inspectedRun = runDrape("inspect '" + (dir / "kept") + "'", dir);
  ASSERT_EQ(inspectedRun.code, 0) << inspectedRun.err;
  EXPECT_NE(inspectedRun.out.find(fmt::format("its own layers kept apart by 4 mm: {} contacts at {} tests, {} of them "
                                              "crossed through and put back",
                                              self["contacts"].get<long>(), self["tests"].get<long>(),
                                              self["crossings"].get<long>())),
            std::string::npos)
      << inspectedRun.out;

  // --self-collision 0 overrides the scene: the layers pass through each other.
  const CliResult free =
      runDrape("run '" + (dir / "layers.wrl") + "' --frames 24 --self-collision 0 --out '" + (dir / "free") + "'", dir);
  ASSERT_EQ(free.code, 0) << free.err;
  EXPECT_FALSE(nlohmann::json::parse(slurp(dir / "free/stats.json"))["garments"][0].contains("self_collision"));
  const std::vector<double> through = upperHeights(dir / "free/frames/frame_00024.obj");
  ASSERT_FALSE(through.empty());
  EXPECT_LT(*std::max_element(through.begin(), through.end()), -0.1);
}

TEST(RunLayers, TheCommandLineTurnsItOnAndRefusesANegativeThickness) {
  const ScratchDir dir("run-layers-cli");
  { std::ofstream(dir / "layers.wrl") << layersScene(""); }
  const CliResult r = runDrape(
      "run '" + (dir / "layers.wrl") + "' --frames 24 --self-collision 0.004 --out '" + (dir / "on") + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<double> on = upperHeights(dir / "on/frames/frame_00024.obj");
  ASSERT_FALSE(on.empty());
  EXPECT_NEAR(*std::min_element(on.begin(), on.end()), 0.004, 0.0004);

  const CliResult bad = runDrape(
      "run '" + (dir / "layers.wrl") + "' --frames 2 --self-collision -0.004 --out '" + (dir / "bad") + "'", dir);
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("--self-collision"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace drape::testing
