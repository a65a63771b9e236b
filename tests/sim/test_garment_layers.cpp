// Which garment is worn over which (sim/garment_layers.hpp): the layers garments step in,
// and the refusals of an unknown name, a garment over itself and names that go round.

#include <gtest/gtest.h>

#include "drape/core/error.hpp"
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

}  // namespace
}  // namespace drape::sim
