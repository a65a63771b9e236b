// The real drape executable: `drape inspect` on motion and avatar files, `drape convert`
// to H-Anim VRML97, and exit code 2 with a file:line message on a bad file.

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>

#include "drape/testing/temp_dir.hpp"

namespace {

struct Result {
  int code = -1;
  std::string out;
};

Result run(const std::string& args) {
  Result r;
  const std::string command = std::string(DRAPE_EXE) + " " + args + " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe)) r.out += buffer.data();
  const int status = ::pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

std::string data(const std::string& f) { return std::string(DRAPE_DATA_DIR) + "/" + f; }

TEST(CliMotion, InspectBvh) {
  const Result r = run("inspect " + data("mocap/cmu_walk_delfem2.bvh"));
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("31 joints"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("344 at 120 Hz"), std::string::npos) << r.out;
  // In the words `drape run` logs.
  EXPECT_NE(r.out.find("T-pose     frame 1 is a reference T-pose, not played"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("CMU units (0.0564 m)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("86 frames at 30 Hz"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("unfolding  none"), std::string::npos) << r.out;
}

TEST(CliMotion, InspectNamesTheUnfoldingFromTheRestPose) {
  const Result r = run("inspect " + data("mocap/cmu_02_02_walk_dazstyle.bvh"));
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("frames 1-4 unfold from the rest pose (not played; the lead-in blends into frame 5)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("74 frames at 30 Hz"), std::string::npos) << r.out;
}

TEST(CliMotion, InspectAmcAndAvatars) {
  Result r = run("inspect " + data("mocap/cmu_11_01.amc"));
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("597 at 120 Hz"), std::string::npos) << r.out;
  r = run("inspect " + data("avatars/CesiumMan.glb"));
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("joints     19"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("segments   19"), std::string::npos) << r.out;
}

TEST(CliMotion, InspectShowsTheHumanoidTheShapeFinds) {
  // What joint maps by shape pair: CesiumMan's numbered joints, bone by bone, facing +x;
  // the Acclaim kick's bones; and the refusal for a skeleton that is no humanoid.
  Result r = run("inspect " + data("avatars/CesiumMan.glb"));
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("  humanoid   by the skeleton's shape, facing +x\n    pelvis     joint0\n    spine      joint1 + "
                       "joint2 (chest joint2)\n    neck       joint3 + joint4 (head joint4)\n    left  leg  hip bone -, "
                       "thigh joint11, shin joint13, foot joint15, toe joint17\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("    left  arm  clavicle -, upper arm joint5, forearm joint7, hand joint9\n"), std::string::npos)
      << r.out;
  r = run("inspect " + data("mocap/cmu_11_01.amc"));
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("    right leg  hip bone rhipjoint, thigh rfemur, shin rtibia, foot rfoot, toe rtoes\n"),
            std::string::npos)
      << r.out;
  // Choreonoid's GR001: its arms end at the elbows, whose parts carry the forearms and grippers.
  r = run("inspect " + data("vrml/choreonoid_GR001/GR001.wrl"));
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("    left  arm  clavicle L_SHOULDER_P, upper arm L_SHOULDER_R, forearm L_ELBOW_P, hand - (the arm "
                       "ends at its elbow, whose part is the forearm and hand)\n"),
            std::string::npos)
      << r.out;
  r = run("inspect " + data("avatars/RiggedSimple.glb"));
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("  humanoid   none by the skeleton's shape: 2 joints are too few for legs, a spine and arms\n"),
            std::string::npos)
      << r.out;
}

TEST(CliMotion, InspectGltfAvatarsNameTheirAnimation) {
  Result r = run("inspect " + data("avatars/CesiumMan.glb"));
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("motion     1 animation; drape run plays it on this avatar by itself (--motion none: at rest), "
                       "and --motion " + data("avatars/CesiumMan.glb") +
                       " on another, retargeted\n    0 'animation 0': 2.000 s (0.000 to 2.000 s of key times), 61 frames "
                       "at 30 Hz\n"),
            std::string::npos)
      << r.out;
}

TEST(CliMotion, BadBvhIsExitCode2WithItsLine) {
  const std::string path = std::string(DRAPE_TEST_DATA_DIR) + "/bad/motion/huge_frames.bvh";
  const Result r = run("inspect " + path);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find(path + ":8:9: Frames: 329490295 exceeds the limit of 1000000"), std::string::npos) << r.out;
}

TEST(CliMotion, ConvertCesiumManToHanim) {
  const std::filesystem::path dir = drape::testing::processTempDir("convert");
  const std::string out = (dir / "cesium.wrl").string();
  const Result r = run("convert " + data("avatars/CesiumMan.glb") + " --to " + out);
  ASSERT_EQ(r.code, 0) << r.out;
  std::ifstream in(out);
  std::stringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  EXPECT_EQ(s.rfind("#VRML V2.0 utf8\n", 0), 0u);
  auto count = [&](const std::string& what) {
    std::size_t n = 0;
    for (std::size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count(" Joint {"), 19u);
  EXPECT_EQ(count(" Segment {"), 19u);
  EXPECT_EQ(count("Humanoid {"), 1u);
  EXPECT_EQ(count("version \"1.1\""), 2u);  // the PROTO default and the instance
  // Balanced braces and brackets (strings hold none here).
  EXPECT_EQ(count("{"), count("}"));
  EXPECT_EQ(count("["), count("]"));
  EXPECT_EQ(run("convert " + data("avatars/CesiumMan.glb") + " --to " + (dir / "x.obj").string()).code, 2);
  std::filesystem::remove_all(dir);
}

}  // namespace
