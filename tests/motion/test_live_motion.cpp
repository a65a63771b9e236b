// A BVH that arrives frame by frame (LiveMotion) against the same file loaded whole
// (loadAnimation): the same frames to the bit, wherever a live source can know what a file
// knows; grounding over trailing windows against a brute-force reference; frames ready as
// soon as the source frames they interpolate have come.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <deque>

#include "drape/core/error.hpp"
#include "drape/formats/bvh.hpp"
#include "drape/motion/animation.hpp"
#include "drape/motion/live_motion.hpp"
#include "makehuman.hpp"

namespace drape::motion {
namespace {

std::string mocap(const std::string& file) { return std::string(DRAPE_DATA_DIR) + "/mocap/" + file; }

MotionOptions liveComparable(double rate, bool ground) {
  MotionOptions o;
  o.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  o.clip.rate = rate;
  o.clip.skipRestUnfold = false;  // measured against a whole clip: a live motion cannot
  o.retarget.groundFeet = ground;
  return o;
}

/// Feeds every frame of `bvh` to a LiveMotion and collects its frames, noting after how many
/// source frames each became ready.
struct LiveRun {
  std::vector<std::vector<RigidTransform>> frames;
  std::vector<std::size_t> readyAfter;
  bool tposeSkipped = false;
};

LiveRun runLive(const formats::BvhFile& bvh, const MotionOptions& options) {
  LiveMotion live(makeHuman(), bvh, options);
  LiveRun run;
  std::vector<RigidTransform> joints(live.jointCount());
  for (std::size_t f = 0; f < bvh.frameCount; ++f) {
    live.push({bvh.frame(f), bvh.channelCount});
    while (live.next(joints)) {
      run.frames.push_back(joints);
      run.readyAfter.push_back(f + 1);
    }
  }
  live.finish();
  while (live.next(joints)) {
    run.frames.push_back(joints);
    run.readyAfter.push_back(bvh.frameCount);
  }
  run.tposeSkipped = live.referenceTPoseSkipped();
  return run;
}

bool sameBits(const RigidTransform& a, const RigidTransform& b) {
  return a.rotation.coeffs() == b.rotation.coeffs() && a.translation == b.translation;
}

void expectSameFrames(const LiveRun& live, const AvatarAnimation& whole) {
  ASSERT_EQ(live.frames.size(), whole.frameCount());
  std::size_t differing = 0;
  for (std::size_t f = 0; f < whole.frameCount(); ++f)
    for (std::size_t j = 0; j < whole.jointCount(); ++j)
      if (!sameBits(live.frames[f][j], whole.frame(f)[j])) ++differing;
  EXPECT_EQ(differing, 0u) << "joint transforms that differ from the whole file's";
}

TEST(LiveMotion, MakesTheFramesLoadingTheWholeFileMakesResampledOrNot) {
  for (const char* file : {"cmu_12_03_walk.bvh", "cmu_walk_delfem2.bvh", "cmu_02_02_walk_dazstyle.bvh"})
    for (const double rate : {30.0, 24.0, 0.0}) {
      SCOPED_TRACE(std::string(file) + " at " + std::to_string(rate) + " Hz");
      const formats::BvhFile bvh = formats::readBvh(mocap(file));
      const MotionOptions options = liveComparable(rate, false);
      const AvatarAnimation whole = loadAnimation(makeHuman(), mocap(file), options);
      const LiveRun live = runLive(bvh, options);
      expectSameFrames(live, whole);
    }
}

TEST(LiveMotion, DropsAReferenceTPoseAsTheFileLoaderDoes) {
  const formats::BvhFile bvh = formats::readBvh(mocap("cmu_12_03_walk.bvh"));
  ClipLoadReport report;
  (void)loadClip(mocap("cmu_12_03_walk.bvh"), liveComparable(30.0, false).clip, &report);
  ASSERT_TRUE(report.referenceTPoseSkipped) << "the CMU walk opens with a reference T-pose";
  const LiveRun live = runLive(bvh, liveComparable(30.0, false));
  EXPECT_EQ(live.tposeSkipped, report.referenceTPoseSkipped);
}

TEST(LiveMotion, AFrameIsReadyOnceTheSourceFramesItInterpolatesHaveCome) {
  const formats::BvhFile bvh = formats::readBvh(mocap("cmu_walk_delfem2.bvh"));
  const double sourceRate = 1.0 / bvh.frameTime;
  for (const double rate : {30.0, 0.0}) {
    SCOPED_TRACE(rate);
    const LiveRun live = runLive(bvh, liveComparable(rate, false));
    const std::size_t skipped = live.tposeSkipped ? 1 : 0;
    ASSERT_GT(live.frames.size(), 80u);
    for (std::size_t k = 0; k < live.frames.size(); ++k) {
      // Source frames i and i + 1 (after the T-pose) at u = k * source rate / rate; at the
      // source's own rate, frame k alone; the first frames wait for the T-pose test's three.
      const double u = rate > 0 ? static_cast<double>(k) * sourceRate / rate : static_cast<double>(k);
      const std::size_t needed = std::min<std::size_t>(
          bvh.frameCount, std::max<std::size_t>(3, skipped + static_cast<std::size_t>(std::floor(u)) + (rate > 0 ? 2 : 1)));
      EXPECT_EQ(live.readyAfter[k], needed) << "frame " << k;
    }
  }
}

TEST(LiveMotion, GroundsOverTrailingWindowsOfTheLowestPoint) {
  const scene::Avatar& avatar = makeHuman();
  const formats::BvhFile bvh = formats::readBvh(mocap("cmu_12_03_walk.bvh"));
  const AvatarAnimation ungrounded = loadAnimation(avatar, mocap("cmu_12_03_walk.bvh"), liveComparable(30.0, false));
  const AvatarAnimation centred = loadAnimation(avatar, mocap("cmu_12_03_walk.bvh"), liveComparable(30.0, true));
  const LiveRun live = runLive(bvh, liveComparable(30.0, true));
  ASSERT_EQ(live.frames.size(), ungrounded.frameCount());

  // The reference, written out plainly: per frame the lowest point above the floor, its
  // minimum over the last second, that minimum's mean over the last second.
  const Clip clip = loadClip(mocap("cmu_12_03_walk.bvh"));
  const Retargeter probe(avatar, clip.skeleton, jointMapFor(clip, avatar, liveComparable(30.0, false)), {}, "probe");
  const std::size_t width = 2 * groundHalfWindow(30.0) + 1;
  std::vector<double> lowest, window;
  double largestGap = 0.0;
  for (std::size_t f = 0; f < ungrounded.frameCount(); ++f) {
    lowest.push_back(probe.lowestAboveFloor(ungrounded.frame(f)));
    const std::size_t lo = f + 1 > width ? f + 1 - width : 0;
    window.push_back(*std::min_element(lowest.begin() + static_cast<std::ptrdiff_t>(lo), lowest.end()));
    double sum = 0.0;
    for (std::size_t k = lo; k <= f; ++k) sum += window[k];
    const double correction = sum / static_cast<double>(f - lo + 1);
    for (std::size_t j = 0; j < ungrounded.jointCount(); ++j) {
      RigidTransform expected = ungrounded.frame(f)[j];
      expected.translation.y() -= correction;
      ASSERT_TRUE(sameBits(live.frames[f][j], expected)) << "frame " << f << " joint " << j;
    }
    largestGap = std::max(largestGap, std::abs(live.frames[f][0].translation.y() - centred.frame(f)[0].translation.y()));
  }
  // Trailing a second behind, the floor a walk rises on (about 2 cm/s here) is followed
  // within a couple of centimetres of where the centred windows of a whole file put it (1.0
  // cm on this walk).
  EXPECT_LT(largestGap, 0.02);
  RecordProperty("largest_gap_to_centred_m", std::to_string(largestGap));
}

TEST(LiveMotion, ASourceOfOneFrameOrNoneMakesThatMany) {
  const formats::BvhFile bvh = formats::readBvh(mocap("cmu_walk_delfem2.bvh"));
  for (const std::size_t frames : {0u, 1u, 2u}) {
    LiveMotion live(makeHuman(), bvh, liveComparable(30.0, true));
    for (std::size_t f = 0; f < frames; ++f) live.push({bvh.frame(f), bvh.channelCount});
    live.finish();
    std::vector<RigidTransform> joints(live.jointCount());
    std::size_t made = 0;
    while (live.next(joints)) ++made;
    // 120 Hz to 30 Hz: source frames 0 and 1 span a quarter of a frame, so one frame.
    EXPECT_EQ(made, frames == 0 ? 0u : 1u) << frames << " source frames";
  }
}

TEST(LiveMotion, RefusesAFrameOfAnotherSize) {
  const formats::BvhFile bvh = formats::readBvh(mocap("cmu_walk_delfem2.bvh"));
  LiveMotion live(makeHuman(), bvh, liveComparable(30.0, true));
  const std::vector<double> shortFrame(bvh.channelCount - 1, 0.0);
  EXPECT_THROW(live.push(shortFrame), Error);
}

}  // namespace
}  // namespace drape::motion
