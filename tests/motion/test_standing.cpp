// Captures standing along +z, as robotics and CAD tools write them, stood up as they load
// (motion/standing.hpp): the CMU walks laid along +z by relabelling their channels are, once
// loaded, the same walks to rounding, whole, retargeted onto the MakeHuman body, and live;
// `drape inspect` says how the file stands.

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <sstream>
#include <sys/wait.h>

#include <fmt/format.h>

#include "drape/formats/avatar_motion.hpp"
#include "drape/formats/bvh.hpp"
#include "drape/motion/animation.hpp"
#include "drape/motion/clip_io.hpp"
#include "drape/motion/live_motion.hpp"
#include "drape/motion/standing.hpp"
#include "drape/testing/temp_dir.hpp"
#include "makehuman.hpp"

namespace drape::motion {
namespace {

using formats::BvhChannel;

std::string capture(const std::string& file) { return std::string(DRAPE_DATA_DIR) + "/mocap/" + file; }

/// The BVH laid along +z by a quarter turn about x that takes +y onto +z: offsets (x, y, z)
/// become (x, -z, y); a Yrotation becomes a Zrotation of the same angle and a Zrotation a
/// Yrotation of the opposite one (the turn conjugates each axis' rotation onto the turned
/// axis); the position channels alike.
formats::BvhFile laidAlongZ(formats::BvhFile bvh) {
  const auto lay = [](const Vec3& v) { return Vec3(v.x(), -v.z(), v.y()); };
  for (formats::BvhJoint& j : bvh.joints) {
    j.offset = lay(j.offset);
    if (j.endSite) *j.endSite = lay(*j.endSite);
    for (std::size_t c = 0; c < j.channels.size(); ++c) {
      BvhChannel& ch = j.channels[c];
      const bool negated = ch == BvhChannel::Zrotation || ch == BvhChannel::Zposition;
      if (ch == BvhChannel::Yrotation) ch = BvhChannel::Zrotation;
      else if (ch == BvhChannel::Zrotation) ch = BvhChannel::Yrotation;
      else if (ch == BvhChannel::Yposition) ch = BvhChannel::Zposition;
      else if (ch == BvhChannel::Zposition) ch = BvhChannel::Yposition;
      if (negated)
        for (std::size_t f = 0; f < bvh.frameCount; ++f) bvh.values[f * bvh.channelCount + j.firstChannel + c] *= -1.0;
    }
  }
  return bvh;
}

/// BVH text of `bvh` (its joints are in file order, each after its parent, depth first).
void writeJoint(std::ostream& os, const formats::BvhFile& bvh, std::size_t j, int depth) {
  const std::string pad(static_cast<std::size_t>(2 * depth), ' ');
  const formats::BvhJoint& joint = bvh.joints[j];
  os << pad << (joint.parent < 0 ? "ROOT " : "JOINT ") << joint.name << "\n" << pad << "{\n";
  os << pad << fmt::format("  OFFSET {:.17g} {:.17g} {:.17g}\n", joint.offset.x(), joint.offset.y(), joint.offset.z());
  os << pad << "  CHANNELS " << joint.channels.size();
  for (BvhChannel c : joint.channels) os << " " << formats::bvhChannelName(c);
  os << "\n";
  for (std::size_t k = j + 1; k < bvh.joints.size(); ++k)
    if (bvh.joints[k].parent == static_cast<int>(j)) writeJoint(os, bvh, k, depth + 1);
  if (joint.endSite)
    os << pad << fmt::format("  End Site\n{0}  {{\n{0}    OFFSET {1:.17g} {2:.17g} {3:.17g}\n{0}  }}\n", pad,
                             joint.endSite->x(), joint.endSite->y(), joint.endSite->z());
  os << pad << "}\n";
}

std::string bvhText(const formats::BvhFile& bvh) {
  std::ostringstream os;
  os << "HIERARCHY\n";
  writeJoint(os, bvh, 0, 0);
  os << fmt::format("MOTION\nFrames: {}\nFrame Time: {:.17g}\n", bvh.frameCount, bvh.frameTime);
  for (std::size_t f = 0; f < bvh.frameCount; ++f) {
    for (std::size_t c = 0; c < bvh.channelCount; ++c) os << (c ? " " : "") << fmt::format("{:.17g}", bvh.frame(f)[c]);
    os << "\n";
  }
  return os.str();
}

/// Every joint's world position in every frame of the clip.
std::vector<Vec3> worldPoints(const Clip& clip) {
  std::vector<Vec3> points;
  std::vector<RigidTransform> world(clip.skeleton.size());
  for (std::size_t f = 0; f < clip.frameCount(); ++f) {
    forwardKinematics(clip.skeleton, clip.frameRotations(f), clip.rootTranslations[f], world);
    for (const RigidTransform& w : world) points.push_back(w.translation);
  }
  return points;
}

const std::array<const char*, 3> kWalks{"cmu_12_03_walk.bvh", "cmu_walk_delfem2.bvh", "cmu_02_02_walk_dazstyle.bvh"};

TEST(Standing, ACaptureLaidAlongZLoadsAsTheSameMotionStanding) {
  for (const char* file : kWalks) {
    SCOPED_TRACE(file);
    const formats::BvhFile bvh = formats::readBvh(capture(file));
    ClipLoadReport asIs, laid;
    const Clip standing = clipFromBvh(bvh, {}, &asIs);
    const Clip stood = clipFromBvh(laidAlongZ(bvh), {}, &laid);
    EXPECT_EQ(asIs.standingAxis, "+y");
    EXPECT_EQ(asIs.stoodUp(), "");
    EXPECT_EQ(laid.standingAxis, "+z");
    EXPECT_EQ(laid.stoodUp(), "it stands along +z: turned to stand along +y, as drape's scenes do");
    // The T-pose test and the unfolding test see the stood-up frames: the same frames drop.
    EXPECT_EQ(laid.referenceTPoseSkipped, asIs.referenceTPoseSkipped);
    EXPECT_EQ(laid.restUnfoldFramesSkipped, asIs.restUnfoldFramesSkipped);
    ASSERT_EQ(stood.frameCount(), standing.frameCount());
    const std::vector<Vec3> a = worldPoints(standing), b = worldPoints(stood);
    double farthest = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) farthest = std::max(farthest, (a[i] - b[i]).norm());
    EXPECT_LT(farthest, 1e-9) << "m, the farthest a joint stands from where the file standing puts it";
  }
}

TEST(Standing, TheStoodUpCaptureMovesTheBodyAsTheCaptureStandingDoes) {
  const std::filesystem::path dir = testing::processTempDir("standing");
  MotionOptions options;
  options.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  for (const char* file : kWalks) {
    SCOPED_TRACE(file);
    const std::string laidPath = (dir / (std::string("z_") + file)).string();
    std::ofstream(laidPath) << bvhText(laidAlongZ(formats::readBvh(capture(file))));
    const AvatarAnimation standing = loadAnimation(makeHuman(), capture(file), options);
    const AvatarAnimation stood = loadAnimation(makeHuman(), laidPath, options);
    ASSERT_EQ(stood.frameCount(), standing.frameCount());
    double farthest = 0.0, turned = 0.0;
    for (std::size_t f = 0; f < standing.frameCount(); ++f)
      for (std::size_t j = 0; j < standing.jointCount(); ++j) {
        farthest = std::max(farthest, (standing.frame(f)[j].translation - stood.frame(f)[j].translation).norm());
        turned = std::max(turned, standing.frame(f)[j].rotation.angularDistance(stood.frame(f)[j].rotation));
      }
    EXPECT_LT(farthest, 1e-6) << "m";
    EXPECT_LT(turned, 1e-6) << "rad";

    // Live, frame by frame from the laid file's header: the same frames.
    const formats::BvhFile laid = formats::readBvh(laidPath);
    MotionOptions live = options;
    live.clip.skipRestUnfold = false;  // a live motion cannot look ahead for an unfolding
    live.retarget.groundFeet = false;  // nor ground over windows centred on each frame
    LiveMotion streamed(makeHuman(), laid, live);
    const AvatarAnimation whole = loadAnimation(makeHuman(), capture(file), live);
    std::vector<RigidTransform> joints(streamed.jointCount());
    std::size_t frames = 0;
    double liveFarthest = 0.0;
    const auto compare = [&] {
      while (streamed.next(joints)) {
        ASSERT_LT(frames, whole.frameCount());
        for (std::size_t j = 0; j < joints.size(); ++j)
          liveFarthest = std::max(liveFarthest, (joints[j].translation - whole.frame(frames)[j].translation).norm());
        ++frames;
      }
    };
    for (std::size_t f = 0; f < laid.frameCount; ++f) {
      streamed.push({laid.frame(f), laid.channelCount});
      compare();
    }
    streamed.finish();
    compare();
    EXPECT_EQ(frames, whole.frameCount());
    EXPECT_LT(liveFarthest, 1e-6) << "m";
  }
}

TEST(Standing, AnAvatarFilesAnimationStandingAlongZIsStoodUpAsItIsRetargeted) {
  // CesiumMan's own walk with his skeleton laid along +z, as a file from a Z-up tool holds
  // it, retargeted onto the MakeHuman body: the body moves as the walk standing moves it.
  const std::string file = std::string(DRAPE_DATA_DIR) + "/avatars/CesiumMan.glb";
  const formats::SkinnedJointMotion walk = formats::readAvatarMotion(file, 30.0);
  formats::SkinnedJointMotion laid = walk;
  const Quat lay(Eigen::AngleAxisd(0.5 * std::numbers::pi, Vec3::UnitX()));  // +y onto +z
  for (Vec3& c : laid.restCenters) c = lay * c;
  for (RigidTransform& f : laid.frames) {
    f.rotation = (lay * f.rotation * lay.conjugate()).normalized();
    f.translation = lay * f.translation;
  }
  MotionOptions options;
  options.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  options.sampled = &walk;
  ClipLoadReport standingReport, laidReport;
  const AvatarAnimation standing = loadAnimation(makeHuman(), file, options, &standingReport);
  options.sampled = &laid;
  const AvatarAnimation stoodUp = loadAnimation(makeHuman(), file, options, &laidReport);
  EXPECT_EQ(standingReport.standingAxis, "+y");
  EXPECT_EQ(laidReport.standingAxis, "+z");
  EXPECT_EQ(laidReport.stoodUp(), "it stands along +z: turned to stand along +y, as drape's scenes do");
  ASSERT_EQ(standing.frameCount(), stoodUp.frameCount());
  ASSERT_GT(standing.frameCount(), 10u);
  double worst = 0.0, worstTurn = 0.0;
  for (std::size_t f = 0; f < standing.frameCount(); ++f) {
    const auto a = standing.frame(f), b = stoodUp.frame(f);
    for (std::size_t j = 0; j < a.size(); ++j) {
      worst = std::max(worst, (a[j].translation - b[j].translation).norm());
      worstTurn = std::max(worstTurn, a[j].rotation.angularDistance(b[j].rotation));
    }
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_LT(worstTurn, 1e-6);
}

TEST(Standing, InspectSaysHowTheFileStands) {
  const std::filesystem::path dir = testing::processTempDir("standing-inspect");
  const std::string laidPath = (dir / "walk_z_up.bvh").string();
  std::ofstream(laidPath) << bvhText(laidAlongZ(formats::readBvh(capture("cmu_12_03_walk.bvh"))));
  const std::string command = std::string(DRAPE_EXE) + " inspect '" + laidPath + "' 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string out;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe)) out += buffer.data();
  const int status = ::pclose(pipe);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << out;
  EXPECT_NE(out.find("  standing   it stands along +z: turned to stand along +y, as drape's scenes do\n"), std::string::npos)
      << out;
  EXPECT_NE(out.find("  humanoid   by the skeleton's shape, facing +z\n"), std::string::npos) << out;
}

}  // namespace
}  // namespace drape::motion
