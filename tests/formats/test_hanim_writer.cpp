// The H-Anim VRML97 writer with a motion: interpolators routed into the Joints, read back
// through drape's VRML97 reader at the key times; unique DEF names; motions that do not fit.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "drape/core/error.hpp"
#include "drape/formats/hanim_writer.hpp"
#include "drape/formats/vrml_read.hpp"
#include "drape/formats/vrml_write.hpp"
#include "drape/testing/errors.hpp"
#include "drape/testing/temp_dir.hpp"
#include "hanim_walker.hpp"

namespace drape::formats {
namespace {

// Two joints, the child named "clock" (its DEF takes hanim_clock before the motion's
// TimeSensor asks for it).
HanimHumanoidData clockWalker(std::size_t frames) { return testing::twoJointWalker(frames, "clock"); }

TEST(HanimWriter, AMotionIsInterpolatorsRoutedIntoTheJoints) {
  const std::size_t frames = 9;
  const HanimHumanoidData h = clockWalker(frames);
  const std::string path = drape::testing::processTempDir("hanim").string() + "/walker.wrl";
  writeHanim(path, h);
  const std::string text = hanimText(h);
  EXPECT_NE(text.find("DEF hanim_clock Joint"), std::string::npos);
  EXPECT_NE(text.find("DEF hanim_clock_2 TimeSensor { cycleInterval 0.32 loop TRUE }"), std::string::npos) << text;
  EXPECT_NE(text.find("ROUTE hanim_root_translation.value_changed TO hanim_root.set_translation"), std::string::npos);
  // The child never leaves its place: no PositionInterpolator for it.
  EXPECT_EQ(text.find("hanim_clock_translation"), std::string::npos);

  const vrml::Document d = vrml::readFile(path);
  std::int32_t root = -1, child = -1;
  for (std::size_t i = 0; i < d.nodes.size(); ++i) {
    if (d.nodes[i].def == "hanim_root") root = static_cast<std::int32_t>(i);
    if (d.nodes[i].def == "hanim_clock") child = static_cast<std::int32_t>(i);
  }
  ASSERT_GE(root, 0);
  ASSERT_GE(child, 0);
  // The Joints' own fields keep the default pose.
  EXPECT_EQ(d.nodes[static_cast<std::size_t>(root)].field("rotation")->numbers[3], 0.0);
  for (std::size_t f = 0; f < frames; ++f) {
    const double t = static_cast<double>(f) / 25.0;
    const std::vector<double> move = vrml::sampleAnimatedField(d, root, "translation", t);
    ASSERT_EQ(move.size(), 3u);
    EXPECT_NEAR(move[2], 0.04 * static_cast<double>(f), 1e-6) << f;
    const std::vector<double> turn = vrml::sampleAnimatedField(d, root, "rotation", t);
    const std::vector<double> swing = vrml::sampleAnimatedField(d, child, "rotation", t);
    ASSERT_EQ(turn.size(), 4u);
    ASSERT_EQ(swing.size(), 4u);
    // Angles about their axes (a zero rotation comes back about z; Coin's quaternions are
    // single precision, their angles taken back through atan2 good to about 1e-7 rad).
    EXPECT_NEAR(turn[3] * turn[1], 0.05 * static_cast<double>(f), 1e-6) << f;
    EXPECT_NEAR(swing[3] * swing[0], -0.1 * static_cast<double>(f), 1e-6) << f;
  }
}

TEST(HanimWriter, AMotionThatDoesNotFitIsRefused) {
  HanimHumanoidData h = clockWalker(3);
  h.motion->frames[1].pop_back();
  EXPECT_NE(drape::testing::errorOf([&] { (void)hanimText(h); }).find("H-Anim motion 'walk': frame 1 has 1 joints, the humanoid 2"),
            std::string::npos);
  h = clockWalker(0);
  EXPECT_NE(drape::testing::errorOf([&] { (void)hanimText(h); }).find("H-Anim motion 'walk': no frames"), std::string::npos);
  h = clockWalker(2);
  h.motion->frameRate = 0.0;
  EXPECT_NE(drape::testing::errorOf([&] { (void)hanimText(h); }).find("frame rate 0 must be positive"), std::string::npos);
}

}  // namespace
}  // namespace drape::formats
