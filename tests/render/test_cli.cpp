// The real drape command: render (PNG, video, contact sheet), play (a window under Xvfb
// that closes by itself) and export, on the test run, plus their errors.

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <set>

#include "../formats/test_run_fixture.hpp"
#include "drape/formats/run_manifest.hpp"
#include "drape/render/image.hpp"

namespace drape::render {
namespace {

namespace fs = std::filesystem;

struct Result {
  int status = -1;
  std::string output;  ///< standard output and error
};

Result run(const std::string& command) {
  Result r;
  std::FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return r;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) r.output += buffer.data();
  const int status = ::pclose(pipe);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

bool have(const std::string& tool) { return std::system(("command -v " + tool + " >/dev/null 2>&1").c_str()) == 0; }

std::string drape() { return std::string(DRAPE_EXE); }

TEST(RenderCli, PngFramesAtTheAskedSize) {
  const std::string dir = testrun::writeTestRun(testrun::freshDir("cli_png"), 6);
  const Result r = run(drape() + " render " + dir + " --png " + dir + "/png --size 200x150");
  ASSERT_EQ(r.status, 0) << r.output;
  for (int i = 0; i < 6; ++i) {
    const Image image = readPng(dir + "/png/frame_0000" + std::to_string(i) + ".png");
    EXPECT_EQ(image.width, 200);
    EXPECT_EQ(image.height, 150);
  }
  EXPECT_FALSE(fs::exists(dir + "/png/frame_00006.png"));
}

/// Pixels of `image` that are plainly red (red above green and blue by `margin` of 255), and
/// plainly blue.
std::pair<int, int> redAndBluePixels(const Image& image, int margin = 60) {
  int red = 0, blue = 0;
  for (std::size_t p = 0; p + 2 < image.rgb.size(); p += 3) {
    const int r = image.rgb[p], g = image.rgb[p + 1], b = image.rgb[p + 2];
    red += r > g + margin && r > b + margin;
    blue += b > r + margin && b > g + margin;
  }
  return {red, blue};
}

TEST(RenderCli, AGarmentIsDrawnInItsScenesColour) {
  // The test run's flag in the renderer's cloth red; given a blue in the manifest (as a scene's
  // Material gives it), blue, and no red left.
  const std::string dir = testrun::writeTestRun(testrun::freshDir("cli_colour"), 2);
  Result r = run(drape() + " render " + dir + " --png " + dir + "/red --size 200x150 --range 0:0");
  ASSERT_EQ(r.status, 0) << r.output;
  const auto [red, noBlue] = redAndBluePixels(readPng(dir + "/red/frame_00000.png"));
  EXPECT_GT(red, 500);
  EXPECT_EQ(noBlue, 0);
  formats::RunManifest manifest = formats::readRunManifest(dir);
  for (formats::RunMesh& m : manifest.meshes)
    if (m.role == "garment") m.colour = Vec3(0.15, 0.25, 0.55);
  formats::writeRunManifest(dir, manifest);
  r = run(drape() + " render " + dir + " --png " + dir + "/blue --size 200x150 --range 0:0");
  ASSERT_EQ(r.status, 0) << r.output;
  const auto [noRed, blue] = redAndBluePixels(readPng(dir + "/blue/frame_00000.png"));
  EXPECT_EQ(noRed, 0);
  EXPECT_GT(blue, 100);  // shaded darker than the red: fewer pixels clear the margin
}

TEST(RenderCli, ARangeRendersThoseFramesAsTheWholeRunDoes) {
  const std::string dir = testrun::writeTestRun(testrun::freshDir("cli_range"), 8);
  Result r = run(drape() + " render " + dir + " --png " + dir + "/all --size 160x120 --follow");
  ASSERT_EQ(r.status, 0) << r.output;
  r = run(drape() + " render " + dir + " --png " + dir + "/part --size 160x120 --follow --range 3:5");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("wrote 3 frames"), std::string::npos) << r.output;
  for (int i = 0; i < 8; ++i) {
    const std::string name = "/frame_0000" + std::to_string(i) + ".png";
    ASSERT_EQ(fs::exists(dir + "/part" + name), i >= 3 && i <= 5) << name;
    if (i < 3 || i > 5) continue;
    // The camera frames the whole run: the same picture as in the whole run's render.
    EXPECT_EQ(readPng(dir + "/part" + name).rgb, readPng(dir + "/all" + name).rgb) << name;
  }
  // To the end, on a contact sheet: its tiles come from the range only.
  r = run(drape() + " render " + dir + " --contact-sheet " + dir + "/sheet.png --range 6:");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("(frames 6 6 6 6 6 6 6 6 7 7 7 7 7 7 7 7)"), std::string::npos) << r.output;
  // One frame.
  r = run(drape() + " render " + dir + " --png " + dir + "/one --size 160x120 --follow --range 4");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("wrote 1 frame"), std::string::npos) << r.output;
  for (int i = 0; i < 8; ++i) EXPECT_EQ(fs::exists(dir + "/one/frame_0000" + std::to_string(i) + ".png"), i == 4) << i;
  EXPECT_EQ(readPng(dir + "/one/frame_00004.png").rgb, readPng(dir + "/all/frame_00004.png").rgb);
  // Ranges that are not in the run, or not ranges, and --frames without a scene.
  for (const std::string bad : {"5:3", "0:8", "9:", "9", "3x", "a:4", "-1:2"}) {
    r = run(drape() + " render " + dir + " --png " + dir + "/bad --range " + bad);
    EXPECT_EQ(r.status, 2) << bad;
    EXPECT_NE(r.output.find("--range " + bad), std::string::npos) << r.output;
  }
  r = run(drape() + " render " + dir + " --png " + dir + "/bad --frames 3");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("--range FIRST:LAST"), std::string::npos) << r.output;
  // A run is drawn as it was simulated: no motion, nor one of an avatar's animations.
  for (const std::string option : {"--motion walk.bvh", "--animation 0"}) {
    r = run(drape() + " render " + dir + " --png " + dir + "/bad " + option);
    EXPECT_EQ(r.status, 2) << option;
    EXPECT_NE(r.output.find(option.substr(0, option.find(' ')) +
                            ": drape render takes a motion only with a scene file, not a run directory"),
              std::string::npos)
        << r.output;
  }
}

TEST(RenderCli, VideoHasEveryFrame) {
  if (!have("ffmpeg") || !have("ffprobe")) GTEST_SKIP() << "ffmpeg is not installed (scripts/install-deps installs it)";
  const std::string dir = testrun::writeTestRun(testrun::freshDir("cli_video"), 17);
  const Result r = run(drape() + " render " + dir + " --video " + dir + "/out.mp4 --size 161x121");  // odd: padded
  ASSERT_EQ(r.status, 0) << r.output;
  const Result probe =
      run("ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames,r_frame_rate "
          "-of csv=p=0 " +
          dir + "/out.mp4");
  ASSERT_EQ(probe.status, 0) << probe.output;
  EXPECT_NE(probe.output.find("24/1,17"), std::string::npos) << probe.output;
}

TEST(RenderCli, ContactSheetHas16TilesWithTimeCodes) {
  const std::string dir = testrun::writeTestRun(testrun::freshDir("cli_sheet"), 40);
  const Result r = run(drape() + " render " + dir + " --contact-sheet " + dir + "/sheet.png --sheet-size 960x540");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("frames 0 3 5 8 10 13 16 18 21 23 26 29 31 34 36 39"), std::string::npos) << r.output;
  const Image sheet = readPng(dir + "/sheet.png");
  ASSERT_EQ(sheet.width, 960);
  ASSERT_EQ(sheet.height, 540);
  // Layout: a gap of max(2, width / 320) pixels around 4x4 equal tiles, in the sheet colour.
  const int gap = 3, tileW = (960 - 5 * gap) / 4, tileH = (540 - 5 * gap) / 4;
  const auto isGap = [&](int x, int y) {
    const std::uint8_t* p = sheet.pixel(x, y);
    return p[0] == 18 && p[1] == 20 && p[2] == 26;
  };
  for (int k = 0; k <= 4; ++k) {
    for (int y = 0; y < 540; y += 7) EXPECT_TRUE(isGap(k * (tileW + gap) + 1, y)) << "column gap " << k;
    for (int x = 0; x < 960; x += 7) EXPECT_TRUE(isGap(x, k * (tileH + gap) + 1)) << "row gap " << k;
  }
  // Each tile carries a label of near-white text in its lower-left quarter, and no two
  // labels are the same (16 different time codes).
  std::set<std::vector<bool>> labels;
  for (int t = 0; t < 16; ++t) {
    const int x0 = gap + (t % 4) * (tileW + gap), y0 = gap + (t / 4) * (tileH + gap);
    std::vector<bool> mask;
    long white = 0;
    for (int y = y0 + tileH * 3 / 4; y < y0 + tileH; ++y)
      for (int x = x0; x < x0 + tileW / 2; ++x) {
        const std::uint8_t* p = sheet.pixel(x, y);
        const bool w = p[0] > 225 && p[1] > 225 && p[2] > 225;
        mask.push_back(w);
        white += w;
      }
    EXPECT_GT(white, 60) << "tile " << t << " has no time code";
    labels.insert(mask);
  }
  EXPECT_EQ(labels.size(), 16u);
}

TEST(RenderCli, FollowCameraFramesEachFrameNotTheWholeRun) {
  const std::string dir = testrun::writeTestRun(testrun::freshDir("cli_follow"), 8);
  const Result fixed = run(drape() + " render " + dir + " --png " + dir + "/fixed --size 160x120 --no-hud");
  ASSERT_EQ(fixed.status, 0) << fixed.output;
  const Result follow = run(drape() + " render " + dir + " --png " + dir + "/follow --size 160x120 --no-hud --follow");
  ASSERT_EQ(follow.status, 0) << follow.output;
  // The follow camera frames a square box around each frame: another picture of the same frame.
  const Image a = readPng(dir + "/fixed/frame_00003.png"), b = readPng(dir + "/follow/frame_00003.png");
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  EXPECT_NE(a.rgb, b.rgb);
}

TEST(RenderCli, AimingAtTheTopWithAZoomIsAnotherPicture) {
  const std::string dir = testrun::writeTestRun(testrun::freshDir("cli_aim"), 2);
  const Result centre = run(drape() + " render " + dir + " --png " + dir + "/centre --size 160x120 --no-hud --range 1:1");
  ASSERT_EQ(centre.status, 0) << centre.output;
  EXPECT_NE(centre.output.find("wrote 1 frame to"), std::string::npos) << centre.output;
  const Result top =
      run(drape() + " render " + dir + " --png " + dir + "/top --size 160x120 --no-hud --range 1:1 --aim 1 --zoom 2");
  ASSERT_EQ(top.status, 0) << top.output;
  const Image a = readPng(dir + "/centre/frame_00001.png"), b = readPng(dir + "/top/frame_00001.png");
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  EXPECT_NE(a.rgb, b.rgb);
}

TEST(RenderCli, CollisionStatesComeFromTheRunsStateCache) {
  const std::string dir = testrun::writeTestRun(testrun::freshDir("cli_states"), 4);
  const auto greenPixels = [](const Image& image) {
    long n = 0;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) {
        const std::uint8_t* p = image.pixel(x, y);
        n += p[1] > p[0] + 40 && p[1] > p[2] + 40;
      }
    return n;
  };
  const Result plain = run(drape() + " render " + dir + " --png " + dir + "/plain --size 200x150 --no-hud");
  ASSERT_EQ(plain.status, 0) << plain.output;
  const Result states =
      run(drape() + " render " + dir + " --png " + dir + "/states --size 200x150 --no-hud --collision-states");
  ASSERT_EQ(states.status, 0) << states.output;
  // Frame 3: the flag's right half is on a collision surface, drawn green.
  EXPECT_EQ(greenPixels(readPng(dir + "/plain/frame_00003.png")), 0);
  EXPECT_GT(greenPixels(readPng(dir + "/states/frame_00003.png")), 200);
  EXPECT_EQ(states.output.find("no vertex states"), std::string::npos) << states.output;
  // A run without state caches says the overlay has nothing to show.
  formats::RunManifest m = formats::readRunManifest(dir);
  m.meshes[1].states.clear();
  formats::writeRunManifest(dir, m);
  const Result old =
      run(drape() + " render " + dir + " --png " + dir + "/old --size 200x150 --no-hud --collision-states");
  ASSERT_EQ(old.status, 0) << old.output;
  EXPECT_NE(old.output.find("the run has no vertex states"), std::string::npos) << old.output;
}

TEST(PlayCli, WindowUnderXvfbClosesByItselfAfterNFrames) {
  if (!have("xvfb-run")) GTEST_SKIP() << "xvfb-run is not installed (scripts/install-deps installs xvfb)";
  const std::string dir = testrun::writeTestRun(testrun::freshDir("cli_play"), 24);
  // Leak checking is off for this child only: the X and GLX stack leaks a few bytes at exit
  // from a driver that is already unloaded, which LeakSanitizer cannot attribute.
  const Result r = run("ASAN_OPTIONS=detect_leaks=0 timeout 300 xvfb-run -a " + drape() + " play " + dir +
                       " --frames 8 --fast --size 320x240 --screenshot " + dir + "/shot.png");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("showed 8 frames"), std::string::npos) << r.output;
  const Image shot = readPng(dir + "/shot.png");
  EXPECT_EQ(shot.width, 320);
  long red = 0;
  for (int y = 0; y < shot.height; ++y)
    for (int x = 0; x < shot.width; ++x) red += shot.pixel(x, y)[0] > shot.pixel(x, y)[1] + 40;
  EXPECT_GT(red, 500) << "the window showed the garment";

  // The same with the camera following the characters.
  const Result followed = run("ASAN_OPTIONS=detect_leaks=0 timeout 300 xvfb-run -a " + drape() + " play " + dir +
                              " --frames 8 --fast --size 320x240 --follow --screenshot " + dir + "/follow.png");
  ASSERT_EQ(followed.status, 0) << followed.output;
  const Image followShot = readPng(dir + "/follow.png");
  long followRed = 0;
  for (int y = 0; y < followShot.height; ++y)
    for (int x = 0; x < followShot.width; ++x) followRed += followShot.pixel(x, y)[0] > followShot.pixel(x, y)[1] + 40;
  EXPECT_GT(followRed, 500) << "the following window showed the garment";
  // Its square framing is wider than the run's bounds in depth: the camera stands further off.
  EXPECT_LT(followRed, red * 9 / 10) << "the same framing as without --follow";
}

TEST(PlayCli, NoDisplayIsAClearError) {
  const std::string dir = testrun::writeTestRun(testrun::freshDir("cli_nodisplay"), 2);
  const Result r =
      run("env -u DISPLAY -u WAYLAND_DISPLAY ASAN_OPTIONS=detect_leaks=0 " + drape() + " play " + dir + " --frames 1");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("needs a display"), std::string::npos) << r.output;
}

TEST(PlayCli, ARunTakesNoMotion) {
  const std::string dir = testrun::writeTestRun(testrun::freshDir("cli_play_motion"), 2);
  for (const std::string option : {"--motion walk.bvh", "--animation 0"}) {
    const Result r = run("env -u DISPLAY -u WAYLAND_DISPLAY ASAN_OPTIONS=detect_leaks=0 " + drape() + " play " + dir +
                         " --frames 1 " + option);
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find(option.substr(0, option.find(' ')) +
                            ": drape play takes a motion only with a scene file, not a run directory"),
              std::string::npos)
        << r.output;
  }
}

TEST(RenderCli, SubdividedGarmentsCoverAboutWhatTheSimulatedTrianglesCover) {
  // The same frame drawn as simulated and as a surface of two refinements: other pictures,
  // with about as many cloth-coloured pixels (the surface passes near the simulated points).
  const std::string dir = testrun::writeTestRun(testrun::freshDir("cli_subdivide"), 3);
  for (const char* levels : {"0", "2"}) {
    const Result r = run(drape() + " render " + dir + " --png " + dir + "/png" + levels + " --size 320x240 --no-hud" +
                         " --range 1 --subdivide " + levels);
    ASSERT_EQ(r.status, 0) << r.output;
  }
  const Image flat = readPng(dir + "/png0/frame_00001.png"), smooth = readPng(dir + "/png2/frame_00001.png");
  const auto clothPixels = [](const Image& image) {
    std::size_t n = 0;
    for (std::size_t p = 0; p + 2 < image.rgb.size(); p += 3)
      n += image.rgb[p] > 120 && image.rgb[p + 1] < 110 && image.rgb[p + 2] < 110;  // the garments' red
    return n;
  };
  EXPECT_NE(flat.rgb, smooth.rgb);
  const double a = static_cast<double>(clothPixels(flat)), b = static_cast<double>(clothPixels(smooth));
  ASSERT_GT(a, 500);
  EXPECT_NEAR(b / a, 1.0, 0.1) << a << " and " << b << " cloth pixels";
}

TEST(RenderCli, BadInputsExitWithTwoAndSayWhat) {
  const std::string dir = testrun::writeTestRun(testrun::freshDir("cli_bad"), 2);
  Result r = run(drape() + " render " + dir + "/nowhere --png " + dir + "/png");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("nowhere"), std::string::npos) << r.output;
  r = run(drape() + " render " + dir + " --png " + dir + "/png --size 12x800");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("--size"), std::string::npos) << r.output;
  r = run(drape() + " render " + dir + " --png " + dir + "/png --size big");
  EXPECT_EQ(r.status, 2);
  r = run(drape() + " render " + dir + " --png " + dir + "/png --aim 1.5");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("--aim"), std::string::npos) << r.output;
  r = run(drape() + " render " + dir + " --png " + dir + "/png --subdivide 5");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("--subdivide"), std::string::npos) << r.output;
  r = run(drape() + " render " + dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("nothing to write"), std::string::npos) << r.output;
  r = run(drape() + " export " + dir + "/nowhere");
  EXPECT_EQ(r.status, 2);
}

TEST(ExportCli, WritesResultGlbIntoTheRun) {
  const std::string dir = testrun::writeTestRun(testrun::freshDir("cli_export"), 5);
  const Result r = run(drape() + " export " + dir);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir + "/result.glb"));
  EXPECT_NE(r.output.find("1 morph-target meshes, 1 rigid nodes"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace drape::render
