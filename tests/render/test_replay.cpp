// RunReplay: what it reads from a run directory and what it refuses; contact sheet spacing.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "../formats/test_run_fixture.hpp"
#include "drape/core/error.hpp"
#include "drape/formats/run_manifest.hpp"
#include "drape/render/headless.hpp"
#include "drape/render/outputs.hpp"
#include "drape/render/run_replay.hpp"

namespace drape::render {
namespace {

TEST(RunReplay, ReadsFramesTimeCodesAndStageTimes) {
  const std::string dir = testrun::writeTestRun(testrun::freshDir("replay"), 30);
  // A stage that never ran (0 ms) is not shown.
  std::ofstream(dir + "/stats.json")
      << R"({"frames": 30, "ms_per_stage": {"forces": 1.5, "collide": 0.25, "strain_limit": 0}})";
  RunReplay replay(dir);
  ASSERT_EQ(replay.meshes().size(), 2u);
  EXPECT_EQ(replay.meshes()[0].role, MeshRole::Segment);
  EXPECT_EQ(replay.meshes()[1].role, MeshRole::Garment);
  EXPECT_EQ(replay.meshes()[1].vertexCount, static_cast<std::size_t>(testrun::kFlagColumns * testrun::kFlagRows));
  EXPECT_EQ(replay.frameCount(), 30);
  Frame f;
  ASSERT_TRUE(replay.read(29, f));
  EXPECT_EQ(f.time.smpte(), "00:00:01:05");  // 29 frames at 24 fps
  const std::vector<Vec3> expected = testrun::flagPositions(29);
  for (std::size_t v = 0; v < expected.size(); ++v) ASSERT_LT((f.positions[1][v] - expected[v]).norm(), 1e-6);
  // A run made before drape wrote each frame's stage times shows the run's means, named so.
  ASSERT_EQ(f.stages.size(), 2u);
  EXPECT_EQ(f.stages[0].stage, "mean collide");  // JSON objects come back in key order
  EXPECT_DOUBLE_EQ(f.stages[1].ms, 1.5);
  EXPECT_FALSE(replay.read(30, f));
  EXPECT_FALSE(replay.read(-1, f));
  // The run's bounds hold every frame: the flag's wave reaches 12 cm in z.
  EXPECT_GT(replay.bounds().max.z(), 0.1);
  EXPECT_NEAR(replay.bounds().min.y(), 0.35, 1e-6);
}

// In a run of several characters, each mesh says whose it is, and a character's segments
// are drawn unless that character's skinned body is in the run.
TEST(RunReplay, SaysWhoseEachMeshIs) {
  const std::string dir = testrun::writeTestRun(testrun::freshDir("replay-characters"), 3);
  formats::RunManifest manifest = formats::readRunManifest(dir);
  for (formats::RunMesh& m : manifest.meshes) m.character = "Bea";
  manifest.meshes[1].colour = Vec3(0.15, 0.25, 0.55);
  formats::writeRunManifest(dir, manifest);
  const RunReplay replay(dir);
  ASSERT_EQ(replay.meshes().size(), 2u);
  EXPECT_EQ(replay.meshes()[0].character, "Bea");
  EXPECT_EQ(replay.meshes()[1].character, "Bea");
  EXPECT_EQ(replay.meshes()[1].colour, std::optional<Vec3>(Vec3(0.15, 0.25, 0.55)));  // the garment's
  EXPECT_FALSE(replay.meshes()[0].colour.has_value());
  std::vector<MeshInfo> meshes = replay.meshes();
  EXPECT_FALSE(hasSkin(meshes, "Bea"));
  meshes.push_back({"body", MeshRole::Skin, 3, {{0, 1, 2}}, "Ada"});
  EXPECT_TRUE(hasSkin(meshes));
  EXPECT_TRUE(hasSkin(meshes, "Ada"));
  EXPECT_FALSE(hasSkin(meshes, "Bea"));
}

// Each frame shows its own stage times: frame 0 (the initial state) none, a frame computed
// again its greater cost, a stage that took no time that frame nothing.
TEST(RunReplay, EachFrameShowsItsOwnStageTimes) {
  const std::string dir = testrun::writeTestRun(testrun::freshDir("replay_frame_stages"), 4);
  std::ofstream(dir + "/stats.json") << R"({"ms_per_stage": {"forces": 2.0},
    "frame_ms_per_stage": {"forces": [0, 1.0, 4.5, 0.5], "strain_limit": [0, 0, 0.25, 0], "output": [0.1, 0.2, 0.3, 0.4]}})";
  RunReplay replay(dir);
  Frame f;
  const auto shown = [&](std::int64_t index) {
    EXPECT_TRUE(replay.read(index, f));
    std::string text;
    for (const StageTime& s : f.stages) text += fmt::format("{}={} ", s.stage, s.ms);
    return text;
  };
  EXPECT_EQ(shown(0), "output=0.1 ");
  EXPECT_EQ(shown(1), "forces=1 output=0.2 ");
  EXPECT_EQ(shown(2), "forces=4.5 output=0.3 strain_limit=0.25 ");
  EXPECT_EQ(shown(3), "forces=0.5 output=0.4 ");
  // Columns that do not hold a number per frame are refused, naming the file and the column.
  const std::pair<const char*, const char*> cases[] = {
      {R"({"frame_ms_per_stage": {"forces": [0, 1, 2]}})",
       "stats.json: frame_ms_per_stage.forces should be an array of a number per frame (4), got 3 values"},
      {R"({"frame_ms_per_stage": {"collide": 1.5}})",
       "stats.json: frame_ms_per_stage.collide should be an array of a number per frame (4), got number"},
      {R"({"frame_ms_per_stage": {"collide": [0, 1, "2", 3]}})",
       "stats.json: frame_ms_per_stage.collide[2] should be a number, got string"},
  };
  for (const auto& [text, expected] : cases) {
    std::ofstream(dir + "/stats.json", std::ios::trunc) << text;
    try {
      RunReplay bad(dir);
      ADD_FAILURE() << "accepted " << text;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }
}

TEST(RunReplay, ReadsTheGarmentsVertexStates) {
  const std::string dir = testrun::writeTestRun(testrun::freshDir("replay_states"), 6);
  RunReplay replay(dir);
  EXPECT_TRUE(replay.hasStates());
  Frame f;
  for (std::int64_t i : {0, 3, 5}) {
    ASSERT_TRUE(replay.read(i, f));
    ASSERT_EQ(f.states.size(), 2u);
    EXPECT_TRUE(f.states[0].empty()) << "the torso has no state cache";
    EXPECT_EQ(f.states[1], testrun::flagStates(i)) << "frame " << i;
  }
  // A run without state caches (made before drape wrote them) replays without states.
  formats::RunManifest m = formats::readRunManifest(dir);
  m.meshes[1].states.clear();
  formats::writeRunManifest(dir, m);
  RunReplay old(dir);
  EXPECT_FALSE(old.hasStates());
  ASSERT_TRUE(old.read(2, f));
  EXPECT_TRUE(f.states[1].empty());
  // A state cache that does not fit its mesh or is too short is refused, naming the file.
  {
    formats::StateCacheWriter w(dir + "/short.states", static_cast<std::size_t>(testrun::kFlagColumns * testrun::kFlagRows));
    w.writeFrame(testrun::flagStates(0));
  }
  {
    formats::StateCacheWriter w(dir + "/narrow.states", 5);
    for (int i = 0; i < 6; ++i) w.writeFrame(std::vector<std::uint8_t>(5, 0));
  }
  for (const auto& [file, expected] : std::vector<std::pair<std::string, std::string>>{
           {"short.states", "short.states: 1 frames, the manifest says 6"},
           {"narrow.states", "narrow.states: 5 vertices per frame, but"}}) {
    m.meshes[1].states = file;
    formats::writeRunManifest(dir, m);
    try {
      RunReplay replay(dir);
      ADD_FAILURE() << "accepted " << file;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }
}

TEST(RunReplay, RefusesInconsistentRuns) {
  const std::string dir = testrun::writeTestRun(testrun::freshDir("replay_bad"), 4);
  // The manifest claims more frames than the caches hold.
  formats::RunManifest m = formats::readRunManifest(dir);
  m.frames = 5;
  formats::writeRunManifest(dir, m);
  try {
    RunReplay replay(dir);
    FAIL() << "accepted a cache that is too short";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("torso.pc2: 4 samples"), std::string::npos) << e.what();
  }
  // A cache whose point count does not match its topology.
  m.frames = 4;
  m.meshes[1].cache = "torso.pc2";
  formats::writeRunManifest(dir, m);
  EXPECT_THROW(RunReplay{dir}, Error);
  // An unknown role.
  m.meshes[1].cache = "flag.pc2";
  m.meshes[1].role = "hat";
  formats::writeRunManifest(dir, m);
  try {
    RunReplay replay(dir);
    FAIL() << "accepted role 'hat'";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("hat"), std::string::npos) << e.what();
  }
}

// stats.json is read for its stage times only, but a broken one is a drape error with its
// line and column, whatever nlohmann stops on (a number beyond a double escaped before).
TEST(RunReplay, ABrokenStatsFileIsAnErrorWithItsPosition) {
  const std::string dir = testrun::writeTestRun(testrun::freshDir("replay_stats"), 4);
  const std::string stats = dir + "/stats.json";
  const std::pair<const char*, const char*> cases[] = {
      {"{\n  \"frames\": 1e999\n}", "stats.json:2:13: expected a finite number, found '1e999'"},
      {"{\n  \"frames\": 4,\n", "stats.json:3:1: "},
  };
  for (const auto& [text, expected] : cases) {
    std::ofstream(stats, std::ios::trunc) << text;
    try {
      RunReplay replay(dir);
      FAIL() << "accepted " << text;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }
}

TEST(ContactSheet, SixteenEvenlySpacedFramesFromFirstToLast) {
  const std::vector<std::int64_t> f = contactSheetFrames(91);
  ASSERT_EQ(f.size(), 16u);
  EXPECT_EQ(f.front(), 0);
  EXPECT_EQ(f.back(), 90);
  for (std::size_t i = 1; i < f.size(); ++i) EXPECT_EQ(f[i] - f[i - 1], 6);
  const std::vector<std::int64_t> few = contactSheetFrames(3);
  ASSERT_EQ(few.size(), 16u);
  EXPECT_EQ(few.front(), 0);
  EXPECT_EQ(few.back(), 2);
  EXPECT_TRUE(contactSheetFrames(0).empty());
}

TEST(Hud, DrawsTextInTheTopLeftCornerOnly) {
  RunReplay replay(testrun::writeTestRun(testrun::freshDir("hud"), 3));
  HeadlessRenderer renderer(replay.meshes(), 320, 240);
  Frame f;
  replay.read(2, f);
  ViewSettings view;
  view.bounds = replay.bounds();
  const Image bare = renderer.render(f, view, OverlaySettings{});
  HudInfo hud;
  hud.time = f.time;
  hud.frame = 2;
  hud.frames = 3;
  const Image text = renderer.render(f, view, OverlaySettings{}, hud);
  long changed = 0;
  for (int y = 0; y < 240; ++y)
    for (int x = 0; x < 320; ++x) {
      const bool c = !std::equal(bare.pixel(x, y), bare.pixel(x, y) + 3, text.pixel(x, y));
      if (x > 160 || y > 120) {
        ASSERT_FALSE(c) << "HUD pixel outside the top-left quarter at " << x << "," << y;
      }
      changed += c;
    }
  EXPECT_GT(changed, 400);
}

}  // namespace
}  // namespace drape::render

namespace drape::render {
namespace {

TEST(Preview, ContactSheetAndVideoInTheRunDirectory) {
  const std::string dir = testrun::writeTestRun(testrun::freshDir("preview"), 4);
  const PreviewFiles files = renderPreview(dir);
  EXPECT_EQ(files.contactSheet, dir + "/preview.png");
  const Image sheet = readPng(files.contactSheet);
  EXPECT_EQ(sheet.width, 1920);
  EXPECT_EQ(sheet.height, 1080);
  if (ffmpegAvailable()) {
    EXPECT_EQ(files.video, dir + "/preview.mp4");
    EXPECT_GT(std::filesystem::file_size(files.video), 1000u);
  } else {
    EXPECT_TRUE(files.video.empty());
  }
}

}  // namespace
}  // namespace drape::render
