// BVH, ASF/AMC and MakeHuman rig readers: the real files in data/, and the malformed-file
// corpus in tests/data/bad/motion with the exact message and position each must produce.

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>

#include "drape/core/error.hpp"
#include "drape/core/files.hpp"
#include "drape/formats/asf_amc.hpp"
#include "drape/formats/bvh.hpp"
#include "drape/formats/mhskel.hpp"
#include "drape/testing/errors.hpp"

namespace drape::formats {
namespace {

std::string mocap(const std::string& f) { return std::string(DRAPE_DATA_DIR) + "/mocap/" + f; }
std::string badMotion(const std::string& f) { return std::string(DRAPE_TEST_DATA_DIR) + "/bad/motion/" + f; }

using drape::testing::errorOf;
using drape::testing::expectCorpus;

TEST(Bvh, ReadsTheCmuWalk) {
  const BvhFile f = readBvh(mocap("cmu_walk_delfem2.bvh"));
  EXPECT_EQ(f.joints.size(), 31u);
  EXPECT_EQ(f.channelCount, 96u);
  EXPECT_EQ(f.frameCount, 344u);
  EXPECT_NEAR(f.frameTime, 1.0 / 120.0, 1e-6);
  EXPECT_EQ(f.values.size(), 344u * 96u);
  EXPECT_EQ(f.joints[0].name, "Hips");
  EXPECT_EQ(f.joints[2].name, "LeftUpLeg");
  EXPECT_EQ(f.joints[2].parent, 1);
  EXPECT_NEAR((f.joints[2].offset - Vec3(1.65674, -1.80282, 0.62477)).norm(), 0.0, 1e-12);
  EXPECT_TRUE(f.joints[5].endSite.has_value());  // LeftToeBase
  EXPECT_DOUBLE_EQ(f.values[0], 10.4194);
  EXPECT_EQ(f.firstFrameLine, 188);
}

TEST(Bvh, ReadsTheDazWalkWithTabSeparators) {
  const BvhFile f = readBvh(mocap("cmu_02_02_walk_dazstyle.bvh"));
  EXPECT_EQ(f.joints.size(), 43u);
  EXPECT_EQ(f.channelCount, 132u);
  EXPECT_EQ(f.frameCount, 299u);
}

TEST(Bvh, MalformedCorpus) {
  const std::string dir = std::string(DRAPE_TEST_DATA_DIR) + "/bad/motion";
  expectCorpus(dir, {
      // The 7.7 GB Assimp regression: rejected from the header, nothing allocated.
      {"huge_frames.bvh", "8:9: Frames: 329490295 exceeds the limit of 1000000"},
      {"frames_exceed_file.bvh", "20:1: the file ends after 1 of the 900000 frames declared"},
      {"no_channels.bvh", "8:9: the skeleton has no channels, so frames cannot hold motion"},
      {"zero_frame_time.bvh", "18:13: Frame Time must be > 0 s, found 0"},
      {"wrong_channel_count.bvh", "20: frame 2 has 5 values, expected 6 (one per channel)"},
      {"truncated.bvh", "21:1: the file ends after 2 of the 3 frames declared"},
      {"extra_frames.bvh", "20:1: more values than the 1 frames declared"},
      {"bad_number.bvh", "19:5: expected a number, found 'abc'"},
      {"unknown_channel.bvh", "5:24: unknown channel 'Wrotation' (expected Xposition..Zrotation)"},
      {"missing_brace.bvh", "3:3: expected '{', found 'OFFSET'"},
      {"too_many_channels.bvh", "5:12: channel count 7 exceeds the limit of 6"},
  }, [](const std::string& path) { (void)readBvh(path); });
}

TEST(Bvh, EmptyAndMissing) {
  EXPECT_EQ(errorOf([] { (void)parseBvh("", "e.bvh"); }), "e.bvh:1:1: expected 'HIERARCHY', found end of file");
  EXPECT_EQ(errorOf([] { (void)readBvh("/nonexistent/x.bvh"); }), "/nonexistent/x.bvh: no such file");
}

TEST(Bvh, DeepNestingIsAnErrorNotAStackOverflow) {
  std::string text = "HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n";
  for (int i = 1; i < 400; ++i) text += "JOINT j" + std::to_string(i) + "\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n";
  EXPECT_NE(errorOf([&] { (void)parseBvh(text, "deep.bvh"); }).find("joints nested deeper than 256"), std::string::npos);
}

// A BVH that arrives as it is written: the header alone, then a frame per line, read as the
// whole file is read.
TEST(BvhStream, ReadsTheHeaderAndEachFrameLineAsTheWholeFileIsRead) {
  const std::string text = drape::readFileText(mocap("cmu_walk_delfem2.bvh")).value();
  const BvhFile whole = parseBvh(text, "walk.bvh");
  std::size_t at = 0;
  int line = 0;
  std::string header;
  for (;;) {
    const std::size_t end = text.find('\n', at);
    const std::string_view l(text.data() + at, end - at);
    header.append(l).push_back('\n');
    ++line;
    at = end + 1;
    if (endsBvhHeader(l)) break;
  }
  EXPECT_EQ(line, whole.firstFrameLine - 1);
  EXPECT_EQ(bvhHeaderLength(text), header.size());
  EXPECT_EQ(bvhHeaderLength("HIERARCHY\nROOT Hips\n"), std::nullopt);
  EXPECT_EQ(bvhHeaderLength("MOTION\nFrame Time: 0.01"), 23u) << "a last line without its newline";
  const BvhFile head = parseBvhHeader(header, "walk.bvh");
  EXPECT_EQ(head.joints.size(), whole.joints.size());
  EXPECT_EQ(head.channelCount, whole.channelCount);
  EXPECT_EQ(head.frameTime, whole.frameTime);
  EXPECT_TRUE(head.values.empty());
  std::vector<double> values(head.channelCount);
  for (std::size_t f = 0; f < whole.frameCount; ++f) {
    const std::size_t end = text.find('\n', at);
    parseBvhFrameLine(std::string_view(text.data() + at, (end == std::string::npos ? text.size() : end) - at),
                      "walk.bvh", ++line, values);
    ASSERT_TRUE(std::equal(values.begin(), values.end(), whole.frame(f))) << "frame " << f;
    at = end + 1;
  }
}

TEST(BvhStream, SaysWhereAFrameLineOrHeaderIsWrong) {
  std::vector<double> three(3);
  EXPECT_EQ(errorOf([&] { parseBvhFrameLine("1 2 x", "stdin", 40, three); }), "stdin:40:5: expected a number, found 'x'");
  EXPECT_EQ(errorOf([&] { parseBvhFrameLine("1 2", "stdin", 41, three); }),
            "stdin:41:4: expected 3 values (one per channel), found 2");
  EXPECT_EQ(errorOf([&] { parseBvhFrameLine("1 2 3 4", "stdin", 42, three); }),
            "stdin:42:7: expected 3 values (one per channel), found more");
  EXPECT_EQ(errorOf([&] { parseBvhFrameLine("1 nan 3", "stdin", 43, three); }), "stdin:43:3: expected a number, found 'nan'");
  const std::string header = "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n}\n"
                             "MOTION\nFrames: 0\nFrame Time: 0.01\n";
  EXPECT_EQ(parseBvhHeader(header, "stdin").channelCount, 3u);
  EXPECT_EQ(errorOf([&] { (void)parseBvhHeader(header + "1 2 3\n", "stdin"); }),
            "stdin:10:1: expected the header to end after 'Frame Time:', found '1'");
  EXPECT_EQ(errorOf([&] { (void)parseBvhHeader("HIERARCHY\nROOT Hips\n{\n", "stdin"); }),
            "stdin:4:1: expected 'OFFSET', found end of file");
  EXPECT_TRUE(endsBvhHeader("Frame Time: 0.0083333"));
  EXPECT_TRUE(endsBvhHeader("\tFrame Time:0.01\r"));
  EXPECT_FALSE(endsBvhHeader("Frames: 12"));
}

TEST(AsfAmc, ReadsTheCmuSoccerKick) {
  const AsfSkeleton asf = readAsf(mocap("cmu_11.asf"));
  EXPECT_EQ(asf.bones.size(), 30u);
  EXPECT_DOUBLE_EQ(asf.lengthScale, 0.45);
  EXPECT_TRUE(asf.degrees);
  for (std::size_t b = 0; b < asf.bones.size(); ++b) EXPECT_LT(asf.bones[b].parent, static_cast<int>(b));
  const int tibia = asf.find("ltibia");
  ASSERT_GE(tibia, 0);
  EXPECT_EQ(asf.bones[static_cast<std::size_t>(asf.bones[static_cast<std::size_t>(tibia)].parent)].name, "lfemur");
  EXPECT_EQ(asf.bones[static_cast<std::size_t>(tibia)].dofs.size(), 1u);
  const AmcMotion amc = readAmc(mocap("cmu_11_01.amc"), asf);
  EXPECT_EQ(amc.frameCount, 597u);
  EXPECT_DOUBLE_EQ(amc.frame(0)[0], 12.2047);  // root TX of frame 1
}

TEST(AsfAmc, MalformedCorpus) {
  const AsfSkeleton asf = readAsf(badMotion("small.asf"));
  expectCorpus(std::string(DRAPE_TEST_DATA_DIR) + "/bad/motion", {
      {"amc_unknown_bone.amc", "8:1: unknown bone 'tibia' (not in the ASF skeleton)"},
      {"amc_wrong_count.amc", "5:1: bone 'femur' has 2 values, expected 3 (its degrees of freedom)"},
      {"amc_frame_gap.amc", "6:1: frame 3 follows frame 1"},
      // Frame LONG_MAX, then 1: computing LONG_MAX + 1 overflowed a long (undefined behaviour).
      {"amc_frame_number_overflow.amc", "6:1: frame 1 follows frame 9223372036854775807"},
  }, [&](const std::string& path) { (void)readAmc(path, asf); });
  const std::string asfPath = badMotion("asf_unknown_parent.asf");
  EXPECT_EQ(errorOf([&] { (void)readAsf(asfPath); }), asfPath + ":26:5: unknown bone 'shin' in the hierarchy");
}

TEST(MhSkel, ReadsTheCmuMbRig) {
  const MhSkeleton s = readMhskel(std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_rig_cmu_mb.mhskel");
  EXPECT_EQ(s.bones.size(), 31u);
  EXPECT_EQ(s.bones[0].name, "Hips");
  EXPECT_EQ(s.joints.size(), 62u);
  for (std::size_t b = 1; b < s.bones.size(); ++b) EXPECT_LT(s.find(s.bones[b].parent), static_cast<int>(b));
  const MhSkeleton d = readMhskel(std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_rig_default.mhskel");
  EXPECT_EQ(d.bones.size(), 163u);
  EXPECT_EQ(d.bones[0].name, "root");
}

TEST(MhSkel, ReadsTheDefaultWeights) {
  const MhWeights w = readMhw(std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_rig_default_weights.mhw");
  EXPECT_EQ(w.weights.size(), 139u);
  std::size_t pairs = 0;
  for (const auto& [bone, list] : w.weights) pairs += list.size();
  EXPECT_EQ(pairs, 57107u);
  const auto fold = readMakeHumanWeightFold(std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_to_cmu_joint_map.json");
  EXPECT_EQ(fold.size(), 139u);
  EXPECT_EQ(fold.at("breast.L"), "Spine");
  EXPECT_EQ(readMakeHumanWeightFold(std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_to_cmu_joint_map.json", true).at("neck01"), "Neck");
}

TEST(MhSkel, MalformedCorpus) {
  const std::string badJson = badMotion("mhskel_bad_json.mhskel");
  EXPECT_EQ(errorOf([&] { (void)readMhskel(badJson); }),
            badJson + ":5:3: syntax error while parsing object key - unexpected '}'; expected string literal");
  const std::string twoRoots = badMotion("mhskel_two_roots.mhskel");
  EXPECT_EQ(errorOf([&] { (void)readMhskel(twoRoots); }), twoRoots + ": two root bones ('a' and 'b')");
  // A weight beyond double range: nlohmann reports it without a position; drape finds it.
  const std::string overflow = badMotion("mhw_weight_overflow.mhw");
  EXPECT_EQ(errorOf([&] { (void)readMhw(overflow); }), overflow + ":3:29: expected a finite number, found '2e400'");
  // Deep nesting: the message for a bad [vertex, weight] pair dumped it recursively.
  const std::string deep = badMotion("mhw_deep_nesting.mhw");
  EXPECT_EQ(errorOf([&] { (void)readMhw(deep); }), deep + ":1:533: nesting deeper than 512 levels");
}

}  // namespace
}  // namespace drape::formats
