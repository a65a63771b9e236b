// A MakeHuman garment refitted through its .mhclo onto the body drape builds: the dress's
// OBJ was exported on a different body shape (its sleeves hang steeper than the hm08
// arms); after the fit it lies on drape's body.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "drape/core/error.hpp"
#include "drape/scene/avatar_makehuman.hpp"
#include "drape/scene/garment_fit.hpp"

namespace drape::scene {
namespace {

const std::string kData = DRAPE_DATA_DIR;
const std::string kRig = kData + "/avatars/makehuman_rig_cmu_mb.mhskel";
const std::string kDress = kData + "/garments/makehuman_female_elegantsuit01_dress.mhclo";

double nearest(const Vec3& p, const std::vector<Vec3>& body) {
  double best = std::numeric_limits<double>::infinity();
  for (const Vec3& b : body) best = std::min(best, (b - p).squaredNorm());
  return std::sqrt(best);
}

TEST(MakeHumanGarment, TheDressFitsTheBodyDrapeBuilds) {
  const MakeHumanGarment g = fitMakeHumanGarment(kDress, kRig);
  ASSERT_EQ(g.fitted.vertexCount(), 2205u);
  ASSERT_EQ(g.fitted.triangleCount(), g.modelled.triangleCount());
  const Avatar avatar = loadMakeHumanAvatar(kRig);
  ASSERT_TRUE(avatar.skin.has_value());
  const std::vector<Vec3>& body = avatar.skin->mesh.positions;

  // Sleeves (|x| > 0.25 m as modelled): far from drape's arms before the fit, on them after.
  double before = 0, after = 0;
  int sleeve = 0;
  for (std::size_t i = 0; i < g.modelled.vertexCount(); i += 3) {
    if (std::abs(g.modelled.positions[i].x()) < 0.25) continue;
    before += nearest(g.modelled.positions[i], body);
    after += nearest(g.fitted.positions[i], body);
    ++sleeve;
  }
  ASSERT_GT(sleeve, 50);
  before /= sleeve;
  after /= sleeve;
  EXPECT_LT(after, 0.02) << "mean sleeve-to-body distance after the fit, m";
  EXPECT_GT(before, 3 * after) << "the OBJ as exported does not sit on this body";

  // The fit moves vertices by centimetres, not metres: same garment, other body.
  double largest = 0;
  for (std::size_t i = 0; i < g.fitted.vertexCount(); ++i)
    largest = std::max(largest, (g.fitted.positions[i] - g.modelled.positions[i]).norm());
  EXPECT_GT(largest, 0.02);
  EXPECT_LT(largest, 0.15);
}

TEST(MakeHumanGarment, AMeshThatIsNotTheFilesIsAnError) {
  // The .mhclo and an OBJ with another vertex count: the skirt OBJ of the walking example.
  const std::string dir = ::testing::TempDir() + "/mhclo-mismatch";
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(kDress, dir + "/dress.mhclo", std::filesystem::copy_options::overwrite_existing);
  std::filesystem::copy_file(std::string(DRAPE_SOURCE_DIR) + "/examples/walking_skirt/skirt.obj", dir + "/dress.obj",
                             std::filesystem::copy_options::overwrite_existing);
  try {
    (void)fitMakeHumanGarment(dir + "/dress.mhclo", kRig);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("fits 2205 vertices, but its mesh has 264"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace drape::scene
