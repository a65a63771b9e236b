// `drape convert AVATAR --to avatar.wrl` and back through drape's own VRML97 reader: the
// segmented H-Anim humanoid keeps its joints, segments and geometry, and its motion, which
// drape then plays as a motion (`--motion avatar.wrl`) and the humanoid as an avatar.

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <limits>
#include <span>

#include <fmt/format.h>

#include "cli_runner.hpp"
#include "drape/formats/hanim_writer.hpp"
#include "drape/formats/pc2.hpp"
#include "drape/formats/vrml_read.hpp"
#include "drape/formats/vrml_write.hpp"
#include "drape/motion/animation.hpp"
#include "drape/motion/jointmap.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/scene/scene.hpp"

namespace drape {
namespace {

using testing::CliResult;
using testing::runDrape;
using testing::ScratchDir;

struct Expected {
  const char* file;
  std::size_t joints;
  std::size_t segments;
};

class ConvertRoundTrip : public ::testing::TestWithParam<Expected> {};

TEST_P(ConvertRoundTrip, ReadsBackWithTheSameJointsAndSegments) {
  const Expected e = GetParam();
  ScratchDir dir("convert-roundtrip");
  const std::string wrl = dir / "avatar.wrl";
  const CliResult r = runDrape("convert '" + std::string(DRAPE_DATA_DIR) + "/avatars/" + e.file + "' --to '" + wrl + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const scene::Scene back = scene::loadScene(wrl);
  ASSERT_EQ(back.avatars.size(), 1u);
  const scene::Avatar& a = back.avatars[0];
  EXPECT_EQ(a.joints.size(), e.joints);
  EXPECT_EQ(a.segments.size(), e.segments);
  std::size_t triangles = 0;
  for (const scene::Segment& s : a.segments) triangles += s.mesh.triangleCount();
  EXPECT_GT(triangles, 1000u);
  // The body stands on its feet at human height.
  Aabb box;
  for (const scene::Segment& s : a.segments)
    for (const Vec3& p : s.mesh.positions) box.extend(a.joints[static_cast<std::size_t>(s.joint)].restWorld().apply(p));
  EXPECT_GT(box.size().y(), 1.3);
  EXPECT_LT(box.size().y(), 2.0);
}

INSTANTIATE_TEST_SUITE_P(Avatars, ConvertRoundTrip,
                         ::testing::Values(Expected{"CesiumMan.glb", 19, 19},
                                           Expected{"makehuman_rig_cmu_mb.mhskel", 31, 31}),
                         [](const auto& info) { return std::string(info.param.joints == 19 ? "CesiumMan" : "MakeHuman"); });

}  // namespace
}  // namespace drape

namespace drape {
namespace {

using testing::CliResult;
using testing::runDrape;
using testing::ScratchDir;

struct MotionCase {
  const char* name;
  const char* avatar;  // in DRAPE_DATA_DIR/avatars
  const char* motion;  // "": the avatar file's own animation; else a path from the source tree
  std::size_t frames;
};

/// A case's files: the avatar, the motion it is written with, and the humanoid that
/// `drape convert` wrote with that motion into the scratch directory.
struct Converted {
  std::string avatar, motion, wrl;
  CliResult result;
};

Converted convertWithMotion(const MotionCase& c, const ScratchDir& dir) {
  Converted out;
  out.avatar = std::string(DRAPE_DATA_DIR) + "/avatars/" + c.avatar;
  out.motion = *c.motion ? std::string(DRAPE_SOURCE_DIR) + "/" + c.motion : out.avatar;
  out.wrl = dir / "walker.wrl";
  out.result = runDrape("convert '" + out.avatar + "' --to '" + out.wrl + "'" +
                            (*c.motion ? " --motion '" + out.motion + "'" : std::string()),
                        dir);
  return out;
}

/// The MakeHuman body with the bundled CMU walk, which most cases here convert.
const MotionCase kMakeHumanWalk{"MakeHumanWithTheBundledWalk", "makehuman_rig_cmu_mb.mhskel",
                                "examples/walking_skirt/walk.bvh", 141};

/// `text` with its one `from` replaced by `to`; a test failure where `from` is missing.
std::string replacedOnce(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  if (at == std::string::npos) {
    ADD_FAILURE() << "'" << from << "' is not in the text";
    return text;
  }
  return text.replace(at, from.size(), to);
}

/// The largest distance between the same point in the same frame of two caches of one
/// garment (frames and points as many as `a` has).
double largestGap(const formats::Pc2Cache& a, const formats::Pc2Cache& b) {
  double worst = 0.0;
  for (std::size_t f = 0; f < a.frames.size(); ++f)
    for (std::size_t v = 0; v < a.pointCount; ++v) worst = std::max(worst, (a.frames[f][v] - b.frames[f][v]).norm());
  return worst;
}

/// The bundled walking skirt's scene with its avatar from `url` (relative to the scene).
std::string skirtSceneOn(const std::string& url) {
  return replacedOnce(testing::slurp(testing::kSkirtDir + "/scene.wrl"),
                      "url \"../../data/avatars/makehuman_rig_cmu_mb.mhskel\"", "url \"" + url + "\"");
}

class ConvertWithMotion : public ::testing::TestWithParam<MotionCase> {};

// The humanoid written with its motion, read back by drape's VRML97 reader (Coin3D): each
// Joint's interpolated rotation and translation about its centre, composed down the
// hierarchy at the key times, move the segments where the motion puts the avatar's joints
// (AvatarAnimation's frames, from the same files), to 20 micrometres: Coin keeps a
// rotation as a single-precision quaternion, which the reader turns back into an angle
// through atan2 in double (Coin's own float acos of w lost small angles to 3e-4 rad).
TEST_P(ConvertWithMotion, TheJointsInterpolatorsPoseTheBodyAsTheMotionDoes) {
  const MotionCase c = GetParam();
  ScratchDir dir(std::string("convert-motion-") + c.name);
  const auto [avatarPath, motionPath, wrl, r] = convertWithMotion(c, dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find(fmt::format("frames at 30 Hz, written with it (interpolators routed into the joints)")),
            std::string::npos)
      << r.err;

  const scene::Avatar avatar = scene::loadAvatarFile(avatarPath);
  motion::MotionOptions options;
  options.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  const motion::AvatarAnimation animation = motion::loadAnimation(avatar, motionPath, options);
  ASSERT_EQ(animation.frameCount(), c.frames);

  const formats::vrml::Document d = formats::vrml::readFile(wrl);
  std::vector<std::int32_t> joints(avatar.joints.size(), -1);
  for (std::size_t j = 0; j < avatar.joints.size(); ++j)
    for (std::size_t i = 0; i < d.nodes.size(); ++i)
      if (d.nodes[i].type == "Joint" && d.nodes[i].def == "hanim_" + formats::vrmlIdentifier(avatar.joints[j].name))
        joints[j] = static_cast<std::int32_t>(i);
  for (std::size_t j = 0; j < joints.size(); ++j) ASSERT_GE(joints[j], 0) << avatar.joints[j].name;

  // The Joints rest in the default pose: drape reads the file back as the avatar at rest.
  const scene::Scene back = scene::loadScene(wrl);
  ASSERT_EQ(back.avatars.size(), 1u);
  EXPECT_EQ(back.avatars[0].joints.size(), avatar.joints.size());

  const double cycle = static_cast<double>(c.frames - 1) / 30.0;
  double worst = 0.0;
  for (const std::size_t f : {std::size_t{0}, std::size_t{1}, c.frames / 3, c.frames / 2, c.frames - 1}) {
    const double t = cycle * static_cast<double>(f) / static_cast<double>(c.frames - 1);
    std::vector<RigidTransform> world(avatar.joints.size());
    for (std::size_t j = 0; j < avatar.joints.size(); ++j) {
      const formats::vrml::Node& node = d.nodes[static_cast<std::size_t>(joints[j])];
      const std::vector<double> rotation = formats::vrml::sampleAnimatedField(d, joints[j], "rotation", t);
      ASSERT_EQ(rotation.size(), 4u) << avatar.joints[j].name << " has no rotation interpolator";
      std::vector<double> translation = formats::vrml::sampleAnimatedField(d, joints[j], "translation", t);
      if (translation.empty()) translation = node.field("translation")->numbers;  // not animated: 0 0 0
      const std::vector<double>& centre = node.field("center")->numbers;
      const Vec3 cj(centre[0], centre[1], centre[2]);
      const Quat q(Eigen::AngleAxisd(rotation[3], Vec3(rotation[0], rotation[1], rotation[2]).normalized()));
      // T(t) T(c) R T(-c): x -> R x + t + c - R c, under the parent Joint.
      const RigidTransform local{q, Vec3(translation[0], translation[1], translation[2]) + cj - q * cj};
      const int p = avatar.joints[j].parent;
      world[j] = p >= 0 ? world[static_cast<std::size_t>(p)] * local : local;
    }
    const std::span<const RigidTransform> expected = animation.frame(f);
    for (const scene::Segment& s : avatar.segments) {
      const auto j = static_cast<std::size_t>(s.joint);
      const RigidTransform rest = avatar.joints[j].restWorld();
      for (std::size_t v = 0; v < s.mesh.positions.size(); v += 7) {
        const Vec3& p = s.mesh.positions[v];  // in the joint's frame
        worst = std::max(worst, (world[j].apply(rest.apply(p)) - expected[j].apply(p)).norm());
      }
    }
  }
  EXPECT_LT(worst, 2e-5) << "m, the largest distance of a segment point from where the motion puts it";
}

INSTANTIATE_TEST_SUITE_P(
    Avatars, ConvertWithMotion,
    ::testing::Values(MotionCase{"CesiumMansOwnWalk", "CesiumMan.glb", "", 61},
                      kMakeHumanWalk),
    [](const auto& info) { return std::string(info.param.name); });

// Errors name what is wrong: an animation the file does not have, and one asked of a file
// that carries none.
TEST(ConvertWithMotion, AnAnimationTheFileDoesNotHaveIsAClearError) {
  ScratchDir dir("convert-motion-errors");
  const std::string cesium = std::string(DRAPE_DATA_DIR) + "/avatars/CesiumMan.glb";
  CliResult r = runDrape("convert '" + cesium + "' --animation Dance --to '" + (dir / "x.wrl") + "'", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("Dance"), std::string::npos) << r.err;
  const std::string body = std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_rig_cmu_mb.mhskel";
  r = runDrape("convert '" + body + "' --animation 0 --to '" + (dir / "y.wrl") + "'", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--animation 0: " + body + " carries no animations"), std::string::npos) << r.err;
  // Without a motion the humanoid is written at rest, as before.
  r = runDrape("convert '" + body + "' --to '" + (dir / "z.wrl") + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(testing::slurp(dir / "z.wrl").find("Interpolator"), std::string::npos);
}


/// The largest distance between where two animations put the avatar's segment points, over
/// every frame (m); infinity when their frame counts differ.
double largestPoseGap(const scene::Avatar& avatar, const motion::AvatarAnimation& a, const motion::AvatarAnimation& b) {
  if (a.frameCount() != b.frameCount()) return std::numeric_limits<double>::infinity();
  double worst = 0.0;
  for (std::size_t f = 0; f < a.frameCount(); ++f)
    for (const scene::Segment& s : avatar.segments) {
      const auto j = static_cast<std::size_t>(s.joint);
      for (std::size_t v = 0; v < s.mesh.positions.size(); v += 5)
        worst = std::max(worst, (a.frame(f)[j].apply(s.mesh.positions[v]) - b.frame(f)[j].apply(s.mesh.positions[v])).norm());
    }
  return worst;
}

class HanimMotionBack : public ::testing::TestWithParam<MotionCase> {};

// The humanoid written with its motion, given back to drape as a motion: the interpolators
// sampled at the same rate drive the avatar as the motion they were written from does, in
// every frame, to Coin's single precision.
TEST_P(HanimMotionBack, DrapePlaysTheWrittenMotionAsTheOriginal) {
  const MotionCase c = GetParam();
  ScratchDir dir(std::string("hanim-back-") + c.name);
  const auto [avatarPath, motionPath, wrl, r] = convertWithMotion(c, dir);
  ASSERT_EQ(r.code, 0) << r.err;

  const scene::Avatar avatar = scene::loadAvatarFile(avatarPath);
  motion::MotionOptions options;
  options.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  const motion::AvatarAnimation original = motion::loadAnimation(avatar, motionPath, options);
  motion::JointMap map;
  const motion::AvatarAnimation back = motion::loadAnimation(avatar, wrl, options, nullptr, &map);
  EXPECT_EQ(map.name.rfind("its own joints (", 0), 0u) << map.name;
  ASSERT_EQ(back.frameCount(), c.frames);
  EXPECT_LT(largestPoseGap(avatar, original, back), 2e-5) << "m";

  // The humanoid file is an avatar too: the same joints at rest, and its motion its own.
  const scene::Avatar humanoid = scene::loadAvatarFile(wrl);
  ASSERT_EQ(humanoid.joints.size(), avatar.joints.size());
  const motion::AvatarAnimation own = motion::loadAnimation(humanoid, wrl, options, nullptr, &map);
  EXPECT_EQ(map.name.rfind("its own joints (", 0), 0u) << map.name;
  EXPECT_EQ(own.frameCount(), c.frames);
}

INSTANTIATE_TEST_SUITE_P(
    Avatars, HanimMotionBack,
    ::testing::Values(MotionCase{"CesiumMansOwnWalk", "CesiumMan.glb", "", 61},
                      kMakeHumanWalk),
    [](const auto& info) { return std::string(info.param.name); });

// A joint map forces the humanoid's motion through retargeting, as a BVH's: onto the very
// skeleton it moves, the retargeted motion is the motion itself, but for the floor fit.
TEST(HanimMotionBack, RetargetedOntoItsOwnSkeletonItIsTheSameMotion) {
  ScratchDir dir("hanim-retarget");
  const auto [body, unusedMotion, wrl, r] = convertWithMotion(kMakeHumanWalk, dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const scene::Avatar avatar = scene::loadAvatarFile(body);
  motion::MotionOptions options;
  options.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  const motion::AvatarAnimation own = motion::loadAnimation(avatar, wrl, options);
  nlohmann::json identity = {{"name", "identity"}, {"joints", nlohmann::json::object()}};
  for (const scene::Joint& j : avatar.joints) identity["joints"][j.name] = j.name;
  options.jointMapPath = dir / "identity.json";
  std::ofstream(options.jointMapPath) << identity.dump(2);
  motion::JointMap map;
  const motion::AvatarAnimation retargeted = motion::loadAnimation(avatar, wrl, options, nullptr, &map);
  EXPECT_EQ(map.name, "identity");
  // Retargeting fits the feet to the floor again (a smoothed minimum over one-second
  // windows, which is not idempotent): a few millimetres of height.
  EXPECT_LT(largestPoseGap(avatar, own, retargeted), 5e-3) << "m";
  options.retarget.groundFeet = false;
  EXPECT_LT(largestPoseGap(avatar, own, motion::loadAnimation(avatar, wrl, options)), 2e-5) << "m, without the floor fit";
}

// The humanoid file is an avatar `drape inspect` lists the motion of and `drape convert`
// reads: written again as a humanoid it keeps its motion; a skinned format cannot take its
// rigid parts, and says so.
TEST(HanimMotionBack, TheHumanoidConvertsAgainWithItsMotionButNotToASkinnedFormat) {
  ScratchDir dir("hanim-convert-again");
  const Converted walker = convertWithMotion(kMakeHumanWalk, dir);
  ASSERT_EQ(walker.result.code, 0) << walker.result.err;
  const std::string& body = walker.avatar;
  const std::string& wrl = walker.wrl;
  const std::string again = dir / "again.wrl";
  CliResult r = runDrape("inspect '" + wrl + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("makehuman_CMU compliant skeleton moves: 4.667 s of interpolators, 141 frames at 30 Hz; drape "
                       "run ... --motion " + wrl + " plays it"),
            std::string::npos)
      << r.out;
  r = runDrape("convert '" + wrl + "' --to '" + again + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("141 frames at 30 Hz, written with it"), std::string::npos) << r.err;
  const scene::Avatar avatar = scene::loadAvatarFile(body);
  motion::MotionOptions options;
  options.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  EXPECT_LT(largestPoseGap(avatar, motion::loadAnimation(avatar, wrl, options), motion::loadAnimation(avatar, again, options)),
            2e-5);
  r = runDrape("convert '" + wrl + "' --to '" + (dir / "walker.dae") + "'", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("is a segmented avatar (rigid parts, no skin and weights), which Collada and FBX skinned "
                       "models cannot carry; convert it --to .wrl"),
            std::string::npos)
      << r.err;
}

// `drape run` with the humanoid as the scene's avatar (an Avatar node's url, or written into
// the scene) and as the motion: the walking skirt moves as it does on the MakeHuman body
// with the BVH walk.
TEST(HanimMotionRun, TheSkirtWalksTheSameOnTheConvertedHumanoid) {
  ScratchDir dir("hanim-run");
  const Converted converted = convertWithMotion(kMakeHumanWalk, dir);
  ASSERT_EQ(converted.result.code, 0) << converted.result.err;
  const std::string& wrl = converted.wrl;
  std::ofstream(dir / "scene.wrl") << skirtSceneOn("walker.wrl");

  const std::string onHumanoid =
      testing::runInto(dir, "humanoid", fmt::format("'{}' --motion '{}' --frames 12", dir / "scene.wrl", wrl));
  const std::string onBody = testing::runInto(
      dir, "body", "'" + testing::kSkirtDir + "/scene.wrl' --motion '" + testing::kSkirtDir + "/walk.bvh' --frames 12");
  const formats::Pc2Cache a = formats::readPc2(onHumanoid + "/garment.pc2");
  const formats::Pc2Cache b = formats::readPc2(onBody + "/garment.pc2");
  ASSERT_EQ(a.frames.size(), 13u);
  ASSERT_EQ(b.frames.size(), 13u);
  EXPECT_LT(largestGap(a, b), 1e-4) << "m, the largest gap between the two skirts";
  EXPECT_EQ(testing::statsOf(onHumanoid)["vertex_substeps_inside_body"], 0);

  // Without --motion the avatar's own file animates it, as --motion FILE does, and says so.
  const CliResult own =
      runDrape(fmt::format("run '{}' --frames 12 --out '{}'", dir / "scene.wrl", dir / "by-its-file"), dir);
  ASSERT_EQ(own.code, 0) << own.err;
  EXPECT_NE(own.err.find("walker.wrl: the avatar file's interpolators move its Humanoid 'makehuman_CMU compliant "
                         "skeleton', which plays them (4.67 s; --motion none keeps it at rest)"),
            std::string::npos)
      << own.err;
  EXPECT_EQ(largestGap(formats::readPc2(dir / "by-its-file/garment.pc2"), a), 0.0);
  // A skirt made for the humanoid says its scene plays by itself.
  const CliResult made = runDrape(fmt::format("make-skirt '{}' --out '{}'", wrl, dir / "made"), dir);
  ASSERT_EQ(made.code, 0) << made.err;
  EXPECT_NE(made.out.find("run it: drape run " + (dir / "made") + "/scene.wrl (the avatar plays the interpolators its "
                          "file routes into it; --motion FILE plays another)"),
            std::string::npos)
      << made.out;

  // The animated humanoid written into the scene itself, in the Avatar node's place: the
  // scene given as its own motion plays it.
  std::string walker = testing::slurp(wrl);
  walker.erase(0, walker.find('\n') + 1);  // the header line: the scene has its own
  const std::size_t humanoid = walker.find(" Humanoid {");
  ASSERT_NE(humanoid, std::string::npos);
  const std::size_t def = walker.rfind("DEF ", humanoid) + 4;
  const std::string name = walker.substr(def, humanoid - def);
  std::ofstream(dir / "animated.wrl") << replacedOnce(
      replacedOnce(skirtSceneOn("walker.wrl"), "DEF Body Avatar {\n  url \"walker.wrl\"\n}", walker),
      "avatar USE Body", "avatar USE " + name);
  const std::string ownMotion = testing::runInto(
      dir, "own", fmt::format("'{0}' --motion '{0}' --frames 12", dir / "animated.wrl"));
  const formats::Pc2Cache c = formats::readPc2(ownMotion + "/garment.pc2");
  ASSERT_EQ(c.frames.size(), 13u);
  EXPECT_LT(largestGap(c, b), 1e-4) << "m, the largest gap between the skirt on the scene's own humanoid and on the body";

  // Without --motion the scene animates its humanoid by itself, as a VRML97 browser would,
  // and says so, as `drape inspect` does; `--motion none` keeps it at rest.
  CliResult r2 = runDrape("inspect '" + (dir / "animated.wrl") + "'", dir);
  ASSERT_EQ(r2.code, 0) << r2.err;
  EXPECT_NE(r2.out.find("makehuman_CMU compliant skeleton moves: 4.667 s of interpolators, 141 frames at 30 Hz; drape "
                        "run " + (dir / "animated.wrl") + " plays it by itself (--motion none: at rest)"),
            std::string::npos)
      << r2.out;
  r2 = runDrape("run '" + (dir / "animated.wrl") + "' --frames 12 --out '" + (dir / "by-itself") + "'", dir);
  ASSERT_EQ(r2.code, 0) << r2.err;
  EXPECT_NE(r2.err.find("the scene's interpolators move its Humanoid 'makehuman_CMU compliant skeleton', which plays "
                        "them (4.67 s; --motion none keeps it at rest)"),
            std::string::npos)
      << r2.err;
  const formats::Pc2Cache d = formats::readPc2(dir / "by-itself/garment.pc2");
  ASSERT_EQ(d.frames.size(), 13u);
  EXPECT_EQ(largestGap(d, c), 0.0) << "m: the scene by itself plays what --motion scene.wrl plays";
  r2 = runDrape("run '" + (dir / "animated.wrl") + "' --motion none --frames 2 --out '" + (dir / "at-rest") + "'", dir);
  ASSERT_EQ(r2.code, 0) << r2.err;
  EXPECT_EQ(r2.err.find("plays them"), std::string::npos) << r2.err;
  EXPECT_EQ(r2.err.find("joint map"), std::string::npos) << r2.err;
  r2 = runDrape("run '" + (dir / "animated.wrl") + "' --motion none --animation 0 --frames 2 --out '" + (dir / "x") + "'",
                dir);
  EXPECT_EQ(r2.code, 2);
  EXPECT_NE(r2.err.find("--animation 0: it chooses one of a motion file's animations, and --motion none plays none"),
            std::string::npos)
      << r2.err;
}

// A humanoid whose Joints carry H-Anim's standard names (HumanoidRoot, l_hip, l_knee, vl5,
// skullbase, ...: the converted MakeHuman walker, renamed through the shipped map), as
// humanoids from other VRML97 tools name them. Its motion drives the MakeHuman body through
// the shipped 'hanim' map, found by itself, exactly as the walker under drape's names does
// through a map of the same pairs; and the CMU capture drives it as a scene's avatar
// through that map reversed.
TEST(HanimNames, AStandardHumanoidsMotionDrivesTheBodyAndTheCaptureDrivesIt) {
  ScratchDir dir("hanim-names");
  const auto [body, unusedMotion, walker, converted] = convertWithMotion(kMakeHumanWalk, dir);
  ASSERT_EQ(converted.code, 0) << converted.err;
  const std::string maps = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  const std::string standard = dir / "standard.wrl";
  std::string text = testing::slurp(walker);
  const motion::JointMap hanim = motion::readJointMap(maps + "/hanim.json");
  for (const motion::JointMapEntry& e : hanim.entries) {
    const std::string from = "name \"" + e.avatarJoint + "\"", to = "name \"" + e.motionJoint + "\"";
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
      text.replace(at, from.size(), to);
  }
  std::ofstream(standard) << text;

  const scene::Avatar avatar = scene::loadAvatarFile(body);
  motion::MotionOptions options;
  options.jointMapDirectory = maps;
  motion::JointMap chosen;
  const motion::AvatarAnimation viaHanim = motion::loadAnimation(avatar, standard, options, nullptr, &chosen);
  EXPECT_EQ(chosen.name, "hanim");
  EXPECT_EQ(chosen.entries.size(), 29u);
  nlohmann::json same = {{"name", "same pairs"}, {"joints", nlohmann::json::object()}};
  for (const motion::JointMapEntry& e : hanim.entries) same["joints"][e.avatarJoint] = e.avatarJoint;
  options.jointMapPath = dir / "same.json";
  std::ofstream(options.jointMapPath) << same.dump(2);
  const motion::AvatarAnimation viaSamePairs = motion::loadAnimation(avatar, walker, options);
  ASSERT_EQ(viaHanim.frameCount(), 141u);
  EXPECT_LT(largestPoseGap(avatar, viaHanim, viaSamePairs), 1e-9) << "m";

  // The standard humanoid as the walking skirt's avatar, with the capture.
  std::ofstream(dir / "scene.wrl") << replacedOnce(
      skirtSceneOn("standard.wrl"),
      R"(collidesWith [ "LowerBack", "Hips", "LeftUpLeg", "RightUpLeg", "LeftLeg", "RightLeg" ])",
      R"(collidesWith [ "vl5", "HumanoidRoot", "l_hip", "r_hip", "l_knee", "r_knee" ])");
  const CliResult r = runDrape(
      fmt::format("run '{}' --motion '{}/walk.bvh' --frames 12 --out '{}'", dir / "scene.wrl", testing::kSkirtDir, dir / "out"),
      dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("joint map 'motionbuilder + hanim (reversed)' drives 29 of the avatar's 31 joints"), std::string::npos)
      << r.err;
  EXPECT_EQ(testing::statsOf(dir / "out")["vertex_substeps_inside_body"], 0);
}

}  // namespace
}  // namespace drape
