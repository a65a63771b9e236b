#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "drape/core/error.hpp"
#include "drape/formats/run_manifest.hpp"
#include "drape/testing/errors.hpp"
#include "drape/testing/temp_dir.hpp"

namespace drape::formats {
namespace {

std::string tempDir(const std::string& name) {
  return testing::processTempDir("manifest/" + name).string();
}

TEST(RunManifest, RoundTrips) {
  const std::string dir = tempDir("ok");
  RunManifest m;
  m.frameRate = 25;
  m.frames = 12;
  m.startFrame = 3;
  m.meshes = {{"skirt", "garment", "skirt.obj", "skirt.pc2", "skirt.states", "", std::nullopt},
              {"hips", "segment", "segments/hips.obj", "segments/hips.pc2", "", "", std::nullopt},
              {"hips", "segment", "segments/Bea/hips.obj", "segments/Bea/hips.pc2", "", "Bea", std::nullopt}};
  m.meshes[0].colour = Vec3(0.15, 0.25, 0.5);
  writeRunManifest(dir, m);
  const RunManifest r = readRunManifest(dir);
  EXPECT_EQ(r.frameRate, 25);
  EXPECT_EQ(r.frames, 12);
  EXPECT_EQ(r.startFrame, 3);
  ASSERT_EQ(r.meshes.size(), 3u);
  EXPECT_EQ(r.meshes[1].cache, "segments/hips.pc2");
  EXPECT_EQ(r.meshes[1].character, "");  // the run's only character: no key
  EXPECT_EQ(r.meshes[2].character, "Bea");
  EXPECT_EQ(r.meshes[0].colour, std::optional<Vec3>(Vec3(0.15, 0.25, 0.5)));
  EXPECT_FALSE(r.meshes[1].colour.has_value());
  EXPECT_EQ(r.meshes[1].role, "segment");
  EXPECT_EQ(r.meshes[0].states, "skirt.states");
  EXPECT_EQ(r.meshes[1].states, "");  // no key written, none read
  std::ifstream written(dir + "/manifest.json");
  const std::string text((std::istreambuf_iterator<char>(written)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.find("\"states\": \"\""), std::string::npos) << text;
  EXPECT_EQ(text.find("\"character\": \"\""), std::string::npos) << text;
}

TEST(RunManifest, AColourIsThreeNumbersFromZeroToOne) {
  const std::string dir = tempDir("colour");
  for (const char* colour : {"[0.5, 0.5]", "\"red\"", "[0.5, \"x\", 0.5]", "[0.5, 1.5, 0.5]"}) {
    std::ofstream(dir + "/manifest.json") << R"({"format": "drape-run", "version": 1, "frame_rate": 30, "frames": 1,
      "meshes": [{"name": "a", "role": "garment", "topology": "a.obj", "cache": "a.pc2", "colour": )"
                                          << colour << "}]}";
    try {
      (void)readRunManifest(dir);
      ADD_FAILURE() << colour;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("key 'colour'"), std::string::npos) << e.what();
    }
  }
}

TEST(RunManifest, StatesMustBeAString) {
  const std::string dir = tempDir("states");
  std::ofstream(dir + "/manifest.json") << R"({"format": "drape-run", "version": 1, "frame_rate": 30, "frames": 1,
    "meshes": [{"name": "a", "role": "garment", "topology": "a.obj", "cache": "a.pc2", "states": 3}]})";
  try {
    (void)readRunManifest(dir);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("key 'states' has the wrong type"), std::string::npos) << e.what();
  }
}

TEST(RunManifest, ClearErrors) {
  const std::string dir = tempDir("bad");
  EXPECT_THROW((void)readRunManifest(dir), Error);
  std::ofstream(dir + "/manifest.json") << "{\"format\": \"drape-run\", \"version\": 1, \"frames\": 3}";
  try {
    (void)readRunManifest(dir);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing key 'frame_rate'"), std::string::npos) << e.what();
  }
  std::ofstream(dir + "/manifest.json") << "{not json";
  EXPECT_THROW((void)readRunManifest(dir), Error);
}

// Each case is a run directory of its own: tests/data/bad/cache/<case>/manifest.json.
TEST(RunManifest, MalformedCorpus) {
  drape::testing::expectCorpus(std::string(DRAPE_TEST_DATA_DIR) + "/bad/cache", {
      // nlohmann's out_of_range used to escape as a non-drape exception.
      {"run_number_overflow", "2:16: expected a finite number, found '1e999'"},
      // json::value() threw type_error on a non-string "format".
      {"run_format_not_string", " not a drape run manifest"},
      // 1e300 converted to long was undefined behaviour.
      {"run_frames_not_whole", " key 'frames' has the wrong type"},
      {"run_meshes_not_list", " key 'meshes' has the wrong type"},
      // Copying 600 nested arrays recursed once per level.
      {"run_deep_nesting", "2:523: nesting deeper than 512 levels"},
  }, [](const std::string& dir) { (void)readRunManifest(dir); }, "/manifest.json");
}

}  // namespace
}  // namespace drape::formats
