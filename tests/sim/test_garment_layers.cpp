// Which garment is worn over which (sim/garment_layers.hpp): the layers garments step in,
// and the refusals of an unknown name, a garment over itself and names that go round.

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "drape/core/error.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/sim/garment_layers.hpp"
#include "drape/testing/errors.hpp"

namespace drape::sim {
namespace {

using drape::testing::errorOf;

std::vector<GarmentSpec> wardrobe(const std::vector<std::pair<std::string, std::vector<std::string>>>& garments) {
  std::vector<GarmentSpec> specs;
  for (const auto& [name, over] : garments) {
    GarmentSpec g;
    g.name = name;
    g.over = over;
    specs.push_back(g);
  }
  return specs;
}

TEST(GarmentLayers, AGarmentStepsAfterEveryGarmentItIsWornOver) {
  // A coat over a vest and a shirt, the vest over the shirt; socks over nothing.
  const auto garments =
      wardrobe({{"Coat", {"Vest", "Shirt"}}, {"Vest", {"Shirt"}}, {"Shirt", {}}, {"Socks", {}}, {"Cape", {"Coat"}}});
  const std::vector<std::vector<std::size_t>> below = garmentsBelow(garments);
  EXPECT_EQ(below[0], (std::vector<std::size_t>{1, 2}));
  EXPECT_EQ(below[1], (std::vector<std::size_t>{2}));
  EXPECT_TRUE(below[2].empty());
  EXPECT_EQ(layersOf(below), (std::vector<int>{2, 1, 0, 0, 3}));
  // Named twice: kept once.
  EXPECT_EQ(garmentsBelow(wardrobe({{"Vest", {"Shirt", "Shirt"}}, {"Shirt", {}}}))[0], std::vector<std::size_t>{1});
}

TEST(GarmentLayers, RefusesWhatCannotBeStepped) {
  EXPECT_NE(errorOf([] { (void)garmentsBelow(wardrobe({{"Vest", {"Shrit"}}, {"Shirt", {}}})); })
                .find("garment 'Vest' is worn over 'Shrit', which is not among the garments simulated with it (Vest, "
                      "Shirt)"),
            std::string::npos);
  EXPECT_NE(errorOf([] { (void)garmentsBelow(wardrobe({{"Vest", {"Vest"}}})); }).find("garment 'Vest' is worn over itself"),
            std::string::npos);
  const std::string round = errorOf([] { (void)garmentsBelow(wardrobe({{"A", {"B"}}, {"B", {"C"}}, {"C", {"A"}}, {"D", {}}})); });
  EXPECT_NE(round.find("garment 'A' is worn, through the garments it is worn over, over itself"), std::string::npos)
      << round;
}

TEST(GarmentLayers, TheBodysPointsCoverItsTrianglesAsCloseAsAsked) {
  // GR001's hips and legs are CAD boxes of a few large triangles: their vertices alone put
  // the body's nearest point centimetres off to the side of a skirt 3 mm out, and which side
  // of the skirt below is over came out wrong. With a spacing, every point of their
  // triangles has one of the body's points within it (random points, against every point).
  const scene::Avatar avatar = scene::loadAvatarFile(std::string(DRAPE_DATA_DIR) + "/vrml/choreonoid_GR001/GR001.wrl");
  const std::vector<std::string> parts{"WAIST_LINK", "L_HIP_P_LINK", "R_KNEE_P_LINK"};
  const std::vector<Vec3> vertices = restBodyPoints(avatar, parts);
  const double spacing = 0.002;
  const std::vector<Vec3> sampled = restBodyPoints(avatar, parts, spacing);
  ASSERT_GT(sampled.size(), 4 * vertices.size());
  for (const Vec3& v : vertices)  // the vertices too, as they were
    EXPECT_TRUE(std::find(sampled.begin(), sampled.end(), v) != sampled.end()) << v.transpose();
  std::mt19937 random(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double farthest = 0.0, farthestByVertices = 0.0;
  for (const scene::Segment& segment : avatar.segments) {
    if (std::find(parts.begin(), parts.end(), segment.name) == parts.end()) continue;
    const RigidTransform rest = avatar.joints[static_cast<std::size_t>(segment.joint)].restWorld();
    for (int k = 0; k < 300; ++k) {
      const mesh::Triangle& t = segment.mesh.triangles[random() % segment.mesh.triangles.size()];
      double u = unit(random), v = unit(random);
      if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
      const Vec3 a = segment.mesh.positions[t[0]], b = segment.mesh.positions[t[1]], c = segment.mesh.positions[t[2]];
      const Vec3 p = rest.apply(a + u * (b - a) + v * (c - a));
      const auto nearest = [&](const std::vector<Vec3>& points) {
        double best = std::numeric_limits<double>::infinity();
        for (const Vec3& q : points) best = std::min(best, (p - q).norm());
        return best;
      };
      farthest = std::max(farthest, nearest(sampled));
      farthestByVertices = std::max(farthestByVertices, nearest(vertices));
    }
  }
  EXPECT_LE(farthest, spacing);
  EXPECT_GT(farthestByVertices, 5 * spacing);  // what the vertices alone left
}

}  // namespace
}  // namespace drape::sim
