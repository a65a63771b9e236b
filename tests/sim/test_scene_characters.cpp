// The characters of a scene (sim::sceneCharacters): each avatar the garments are worn by,
// placed where the scene puts it, with its garments and the motion its Avatar node names;
// a garment among several avatars that does not say which wears it, two characters of one
// name, and a motion that is not there are refused where the file says so.

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <optional>
#include <regex>
#include <string>

#include <fmt/format.h>

#include "drape/scene/scene.hpp"
#include "drape/sim/scene_setup.hpp"
#include "drape/testing/errors.hpp"
#include "drape/testing/temp_dir.hpp"

namespace drape::sim {
namespace {

const std::string kTwoCharacters = std::string(DRAPE_SOURCE_DIR) + "/examples/two_characters/scene.wrl";
const std::string kDressedAvatar = std::string(DRAPE_SOURCE_DIR) + "/examples/dressed_avatar/scene.wrl";

std::string fileText(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// The dressed avatar's scene with a second humanoid, its DEF names and its name ending in
/// `suffix` (the same name when empty), 2 m along x; `secondGarment` is appended as it is.
std::string twoHumanoids(const std::string& name, const std::string& suffix, const std::string& secondGarment) {
  const std::string text = fileText(kDressedAvatar);
  const std::size_t from = text.find("DEF Body Humanoid"), to = text.find("DEF Skirt ClothSet");
  std::string second = text.substr(from, to - from);
  second = std::regex_replace(second, std::regex(R"((DEF|USE) (\w+))"), "$01 $02" + suffix);
  second = std::regex_replace(second, std::regex(R"(name "body")"), "name \"body" + suffix + "\"");
  const std::string path = testing::processTempDir("scene-characters").string() + "/" + name;
  std::ofstream(path) << text << "\nTransform { translation 2 0 0 children [\n" << second << "] }\n" << secondGarment;
  return path;
}

TEST(SceneCharacters, TheTwoCharactersExampleHasEachAvatarWithItsGarmentMotionAndPlace) {
  const scene::Scene scene = scene::loadScene(kTwoCharacters);
  const std::vector<SceneCharacter> characters = sceneCharacters(scene);
  ASSERT_EQ(characters.size(), 2u);
  EXPECT_EQ(characters[0].name, "Ada");
  EXPECT_EQ(characters[1].name, "Bea");
  EXPECT_EQ(characters[0].garments, (std::vector<std::size_t>{0}));
  EXPECT_EQ(characters[1].garments, (std::vector<std::size_t>{1}));
  EXPECT_TRUE(characters[0].external && characters[1].external);
  EXPECT_EQ(characters[0].motion, std::string(DRAPE_SOURCE_DIR) + "/examples/walking_skirt/walk.bvh");
  EXPECT_EQ(characters[1].motion, std::string(DRAPE_SOURCE_DIR) + "/data/mocap/cmu_walk_delfem2.bvh");
  // Bea is Ada 1.2 m along x, joint for joint (the VRML97 reader holds numbers as floats).
  const scene::Avatar& ada = *characters[0].avatar;
  const scene::Avatar& bea = *characters[1].avatar;
  ASSERT_EQ(ada.joints.size(), bea.joints.size());
  for (std::size_t j = 0; j < ada.joints.size(); ++j)
    EXPECT_LT((bea.joints[j].restCenter - ada.joints[j].restCenter - Vec3(1.2, 0, 0)).norm(), 1e-6) << j;
  // Each garment collides with its own avatar's parts, bound where the other's is.
  const std::vector<GarmentSpec> specs = garmentSpecs(scene, characters);
  ASSERT_EQ(specs.size(), 2u);
  EXPECT_EQ(specs[0].bound, specs[1].bound);
  EXPECT_EQ(specs[0].bound.size(), 24u);
  EXPECT_EQ(specs[1].collidesWith, specs[0].collidesWith);
  EXPECT_LT((specs[1].mesh.positions[0] - specs[0].mesh.positions[0] - Vec3(1.2, 0, 0)).norm(), 1e-6);
  // Each skirt in the colour its Shape's Material gives it.
  EXPECT_EQ(specs[0].colour, std::optional<Vec3>(Vec3(0.7, 0.15, 0.2)));
  EXPECT_EQ(specs[1].colour, std::optional<Vec3>(Vec3(0.15, 0.25, 0.55)));
  // What takes one avatar says there are two.
  EXPECT_NE(testing::errorOf([&] { (void)sceneAvatar(scene); })
                .find("garments are worn by 2 characters (Ada, Bea); this takes one"),
            std::string::npos);
}

TEST(SceneCharacters, AnAvatarThatWearsNothingIsLeftOut) {
  // The second humanoid wears nothing: the scene has one character, the first, in its skirt
  // and a shawl.
  const std::string shawl = "DEF Shawl ClothSet {\n  name \"shawl\"\n  avatar USE Body\n  cloth IndexedFaceSet { coord "
                            "Coordinate { point [ 0 1 0, 0.2 1 0, 0 1.2 0 ] } coordIndex [ 0 1 2 -1 ] }\n}\n";
  const scene::Scene scene = scene::loadScene(twoHumanoids("bare.wrl", "2", shawl));
  ASSERT_EQ(scene.avatars.size(), 2u);
  const std::vector<SceneCharacter> characters = sceneCharacters(scene);
  ASSERT_EQ(characters.size(), 1u);
  EXPECT_EQ(characters[0].name, "body");
  EXPECT_EQ(characters[0].garments, (std::vector<std::size_t>{0, 1}));
  // The skirt's Shape has a Material; the shawl, a bare IndexedFaceSet, no colour of its own.
  ASSERT_EQ(scene.garments.size(), 2u);
  EXPECT_FALSE(scene.garments[1].colour.has_value());
  EXPECT_FALSE(characters[0].external);
  EXPECT_EQ(characters[0].motion, "");
  EXPECT_EQ(scene.garments[0].colour, std::optional<Vec3>(Vec3(0.7, 0.2, 0.2)));
}

TEST(SceneCharacters, RefusesWhatItCannotTellApart) {
  // A second garment that names no avatar, among two.
  const std::string unsaid = "DEF Shawl ClothSet {\n  name \"shawl\"\n  cloth IndexedFaceSet { coord Coordinate { point [ "
                             "2 1 0, 2.2 1 0, 2 1.2 0 ] } coordIndex [ 0 1 2 -1 ] }\n}\n";
  const std::string path = twoHumanoids("unsaid.wrl", "2", unsaid);
  const int line = [&] {
    const std::string text = fileText(path);
    return static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(text.find("DEF Shawl")), '\n')) + 1;
  }();
  EXPECT_EQ(testing::errorOf([&] { (void)sceneCharacters(scene::loadScene(path)); }),
            path + ":" + std::to_string(line) +
                ": ClothSet 'shawl': the scene has 2 avatars (body, body2); say which wears it (avatar USE NAME)");

  // Two characters of one name.
  const std::string worn = "DEF Shawl ClothSet {\n  name \"shawl\"\n  avatar USE Body\n  cloth IndexedFaceSet { coord "
                           "Coordinate { point [ 2 1 0, 2.2 1 0, 2 1.2 0 ] } coordIndex [ 0 1 2 -1 ] }\n}\n";
  std::string twin = worn;
  twin.replace(twin.find("USE Body"), 8, "USE BodyB");
  twin.replace(twin.find("DEF Shawl"), 9, "DEF ShawlB");
  const std::string same = twoHumanoids("same.wrl", "B", "");
  {
    std::string text = fileText(same);
    text = std::regex_replace(text, std::regex(R"(name "bodyB")"), "name \"body\"");
    std::ofstream(same) << text << twin;
  }
  EXPECT_NE(testing::errorOf([&] { (void)sceneCharacters(scene::loadScene(same)); })
                .find(": two characters are called 'body'; give their Avatar or Humanoid nodes different names (DEF)"),
            std::string::npos);

  // An Avatar node whose motion is not there.
  std::string text = fileText(kTwoCharacters);
  text.replace(text.find("../walking_skirt/walk.bvh"), 25, "no-such-walk.bvh");
  text = std::regex_replace(text, std::regex(R"(url "\.\./\.\./data/)"), "url \"" + std::string(DRAPE_SOURCE_DIR) + "/data/");
  const std::string noMotion = testing::processTempDir("scene-characters").string() + "/no-motion.wrl";
  std::ofstream(noMotion) << text;
  const auto ada = static_cast<long>(text.find("DEF Ada Avatar"));
  const std::string at = fmt::format(":{}: ", std::count(text.begin(), text.begin() + ada, '\n') + 1);
  EXPECT_EQ(testing::errorOf([&] { (void)sceneCharacters(scene::loadScene(noMotion)); }),
            noMotion + at + "Avatar Ada: motion: no such file (no-such-walk.bvh)");
}

TEST(SceneCharacters, ARobotLyingAcrossGravityIsToldFromOneStandingOrUnderItsOwnUp) {
  // Choreonoid's SR1 stands along +z, as its file does: lying where gravity pulls along -y,
  // standing once its Avatar node turns it, or where the scene's gravity pulls along -z.
  const std::string dir = testing::processTempDir("scene-characters").string();
  const auto robotIn = [&](const std::string& name, const std::string& avatarFields, const std::string& more) {
    const std::string path = dir + "/" + name;
    std::ofstream(path) << "#VRML V2.0 utf8\nDEF Robot Avatar { url \"" << DRAPE_DATA_DIR << "/vrml/choreonoid_SR1.wrl\" "
                        << avatarFields << " }\n" << more;
    const scene::Scene scene = scene::loadScene(path);
    std::vector<SceneCharacter> characters = sceneCharacters(scene, Undressed::included);
    EXPECT_EQ(characters.size(), 1u);
    return lyingAcrossGravity(scene, *characters.at(0).avatar);
  };
  const std::optional<scene::Upright> lying = robotIn("lying.wrl", "", "");
  ASSERT_TRUE(lying.has_value());
  EXPECT_EQ(lying->axis, "+z");
  EXPECT_EQ(lying->rotationText(), "1 0 0 -1.5708");
  EXPECT_FALSE(robotIn("stood.wrl", "rotation 1 0 0 -1.5708", "").has_value());
  EXPECT_FALSE(robotIn("own-up.wrl", "", "Simulation { gravity 0 0 -9.81 }\n").has_value());
}

}  // namespace
}  // namespace drape::sim
