// glTF animations as the motion of a skin's joints (formats/gltf_avatar): LINEAR rotations
// are SLERPed, STEP holds the earlier key, CUBICSPLINE is the Hermite curve of its
// tangents, every joint's world position follows from its ancestors' motion as computed
// by hand, CesiumMan's walk keeps its bones' lengths, and bad animations are refused with
// what is wrong.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "drape/formats/gltf_avatar.hpp"
#include "drape/testing/errors.hpp"
#include "drape/testing/temp_dir.hpp"

namespace drape::formats {
namespace {

using drape::testing::errorOf;

std::string base64(const std::string& bytes) {
  static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    std::uint32_t v = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 2]);
    out += digits[(v >> 18) & 63];
    out += digits[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? digits[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? digits[v & 63] : '=';
  }
  return out;
}

/// A two-joint skeleton: "hip" at (0, 1, 0), its child "knee" 0.5 m below it, one skin, and
/// one animation whose samplers are given as float arrays.
struct Doc {
  std::string buffer;  ///< float32 data of every accessor
  std::vector<std::string> accessors, samplers, channels;
  std::string hipExtra;  ///< more JSON members of the hip node
  std::string animationExtra, moreAnimations;  ///< more members of the animation, more animations

  int floats(const std::vector<float>& v, const char* type) {
    const std::size_t offset = buffer.size();
    buffer.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(float));
    const int components = std::string(type) == "SCALAR" ? 1 : std::string(type) == "VEC3" ? 3 : 4;
    accessors.push_back(fmt::format(R"({{"bufferView": 0, "byteOffset": {}, "componentType": 5126, "count": {}, "type": "{}"}})",
                                    offset, v.size() / static_cast<std::size_t>(components), type));
    return static_cast<int>(accessors.size()) - 1;
  }
  void channel(int node, const char* path, const std::vector<float>& times, const std::vector<float>& values,
               const char* interpolation = "LINEAR") {
    const int in = floats(times, "SCALAR");
    const int out = floats(values, std::string(path) == "rotation" ? "VEC4" : "VEC3");
    samplers.push_back(fmt::format(R"({{"input": {}, "output": {}, "interpolation": "{}"}})", in, out, interpolation));
    channels.push_back(fmt::format(R"({{"sampler": {}, "target": {{"node": {}, "path": "{}"}}}})", samplers.size() - 1,
                                   node, path));
  }
  [[nodiscard]] std::string text() const {
    const std::string animations =
        channels.empty() ? "" : fmt::format(R"(, "animations": [{{"channels": [{}], "samplers": [{}]{}}}{}])",
                                            fmt::join(channels, ", "), fmt::join(samplers, ", "), animationExtra,
                                            moreAnimations);
    return fmt::format(R"({{"asset": {{"version": "2.0"}},
 "nodes": [{{"name": "hip", "translation": [0, 1, 0], "children": [1]{}}}, {{"name": "knee", "translation": [0, -0.5, 0]}}],
 "skins": [{{"joints": [0, 1]}}],
 "buffers": [{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{}"}}],
 "bufferViews": [{{"buffer": 0, "byteLength": {}}}],
 "accessors": [{}]{}}})",
                       hipExtra, buffer.size(), base64(buffer), buffer.size(), fmt::join(accessors, ", "), animations);
  }
  [[nodiscard]] GltfJointMotion motion(double rate) const { return parseGltfJointMotion(text(), "t.gltf", "", rate); }
};

const float kHalf = static_cast<float>(std::sqrt(0.5));  // cos 45 degrees

Quat aboutZ(double degrees) { return Quat(Eigen::AngleAxisd(degrees * std::numbers::pi / 180.0, Vec3::UnitZ())); }

double angleBetween(const Quat& a, const Quat& b) { return a.angularDistance(b); }

TEST(GltfMotion, LinearRotationsAreSlerpedAndCarryTheChild) {
  Doc doc;
  doc.channel(0, "rotation", {0.0f, 1.0f}, {0, 0, 0, 1, 0, 0, kHalf, kHalf});  // 0 -> 90 degrees about z
  const GltfJointMotion m = doc.motion(4.0);
  ASSERT_EQ(m.joints, (std::vector<std::string>{"hip", "knee"}));
  ASSERT_EQ(m.frameCount(), 5u);  // 0, 0.25, 0.5, 0.75, 1 s
  EXPECT_EQ(m.animation, "animation 0");
  EXPECT_EQ(m.animationNames, (std::vector<std::string>{"animation 0"}));
  EXPECT_NEAR(m.restCenters[1].y(), 0.5, 1e-12);
  for (std::size_t f = 0; f < 5; ++f) {
    const double degrees = 22.5 * static_cast<double>(f);
    const RigidTransform& hip = m.frames[f * 2];
    const RigidTransform& knee = m.frames[f * 2 + 1];
    EXPECT_LT(angleBetween(hip.rotation, aboutZ(degrees)), 1e-6) << f;
    EXPECT_LT(angleBetween(knee.rotation, aboutZ(degrees)), 1e-6) << f;
    EXPECT_LT((hip.translation - Vec3(0, 1, 0)).norm(), 1e-7) << f;
    // The knee swings about the hip: (0, 1) + 0.5 (sin a, -cos a).
    const double a = degrees * std::numbers::pi / 180.0;
    EXPECT_LT((knee.translation - Vec3(0.5 * std::sin(a), 1.0 - 0.5 * std::cos(a), 0.0)).norm(), 1e-6) << f;
  }
}

TEST(GltfMotion, StepHoldsTheEarlierKey) {
  Doc doc;
  doc.channel(0, "rotation", {0.0f, 1.0f}, {0, 0, 0, 1, 0, 0, kHalf, kHalf}, "STEP");
  const GltfJointMotion m = doc.motion(4.0);
  ASSERT_EQ(m.frameCount(), 5u);
  for (std::size_t f = 0; f < 4; ++f) EXPECT_LT(angleBetween(m.frames[f * 2].rotation, Quat::Identity()), 1e-7) << f;
  EXPECT_LT(angleBetween(m.frames[8].rotation, aboutZ(90)), 1e-6);
}

TEST(GltfMotion, CubicSplinesFollowTheirTangents) {
  Doc doc;
  // x from 0 to 1 m in 1 s: with zero tangents the Hermite curve 3u^2 - 2u^3, with both
  // tangents 1 m/s the straight line.
  doc.channel(0, "translation", {0.0f, 1.0f}, {0, 0, 0, 0, 1, 0, 0, 0, 0, /**/ 0, 0, 0, 1, 1, 0, 0, 0, 0},
              "CUBICSPLINE");
  const GltfJointMotion eased = doc.motion(4.0);
  ASSERT_EQ(eased.frameCount(), 5u);
  for (std::size_t f = 0; f < 5; ++f) {
    const double u = 0.25 * static_cast<double>(f);
    EXPECT_NEAR(eased.frames[f * 2].translation.x(), 3 * u * u - 2 * u * u * u, 1e-7) << f;
    EXPECT_NEAR(eased.frames[f * 2 + 1].translation.x(), 3 * u * u - 2 * u * u * u, 1e-7) << f;  // the knee goes along
  }
  Doc straight;
  straight.channel(0, "translation", {0.0f, 1.0f}, {0, 0, 0, 0, 1, 0, 1, 0, 0, /**/ 1, 0, 0, 1, 1, 0, 0, 0, 0},
                   "CUBICSPLINE");
  const GltfJointMotion line = straight.motion(4.0);
  for (std::size_t f = 0; f < 5; ++f) EXPECT_NEAR(line.frames[f * 2].translation.x(), 0.25 * static_cast<double>(f), 1e-7);
}

TEST(GltfMotion, ChannelsSpanTheAnimationAndHoldTheirEnds) {
  Doc doc;
  doc.channel(1, "rotation", {0.5f, 1.0f}, {0, 0, 0, 1, 0, 0, kHalf, kHalf});  // the knee, from 0.5 s
  doc.channel(0, "translation", {1.0f, 2.0f}, {0, 1, 0, 1, 1, 0});               // the hip, from 1 s
  const GltfJointMotion m = doc.motion(2.0);
  EXPECT_DOUBLE_EQ(m.start_s, 0.5);
  EXPECT_DOUBLE_EQ(m.end_s, 2.0);
  ASSERT_EQ(m.frameCount(), 4u);  // 0.5, 1, 1.5, 2 s
  // At 0.5 s the knee has not turned and the hip has not moved; after 1 s the knee holds 90.
  EXPECT_LT(angleBetween(m.frames[1].rotation, Quat::Identity()), 1e-7);
  EXPECT_LT(angleBetween(m.frames[3].rotation, aboutZ(90)), 1e-6);
  EXPECT_LT(angleBetween(m.frames[7].rotation, aboutZ(90)), 1e-6);
  EXPECT_NEAR(m.frames[4].translation.x(), 0.5, 1e-7);  // the hip halfway at 1.5 s
  EXPECT_NEAR(m.frames[6].translation.x(), 1.0, 1e-7);
}

TEST(GltfMotion, TheChildProcessReturnsWhatTheParserFinds) {
  Doc doc;
  doc.channel(0, "rotation", {0.0f, 1.0f}, {0, 0, 0, 1, 0, 0, kHalf, kHalf});
  const auto path = drape::testing::processTempDir("gltf_motion") / "two_joints.gltf";
  std::ofstream(path) << doc.text();
  const GltfJointMotion read = readGltfJointMotion(path.string(), 4.0);
  const GltfJointMotion parsed = doc.motion(4.0);
  EXPECT_EQ(read.joints, parsed.joints);
  EXPECT_EQ(read.animation, parsed.animation);
  EXPECT_EQ(read.animationNames, parsed.animationNames);
  EXPECT_EQ(read.restCenters, parsed.restCenters);
  ASSERT_EQ(read.frames.size(), parsed.frames.size());
  for (std::size_t i = 0; i < read.frames.size(); ++i) {
    EXPECT_EQ(read.frames[i].rotation.coeffs(), parsed.frames[i].rotation.coeffs());
    EXPECT_EQ(read.frames[i].translation, parsed.frames[i].translation);
  }
}

TEST(GltfMotion, BadAnimationsAreRefused) {
  Doc none;
  EXPECT_EQ(errorOf([&] { (void)none.motion(30); }), "t.gltf: has no animation");

  Doc backwards;
  backwards.channel(0, "rotation", {1.0f, 0.5f}, {0, 0, 0, 1, 0, 0, 0, 1});
  EXPECT_EQ(errorOf([&] { (void)backwards.motion(30); }),
            "t.gltf: animation 0 channel 0: key times go back, from 1 s to 0.5 s at key 1");

  Doc shortOutput;
  shortOutput.channel(0, "translation", {0.0f, 1.0f, 2.0f}, {0, 0, 0, 1, 0, 0});
  EXPECT_EQ(errorOf([&] { (void)shortOutput.motion(30); }),
            "t.gltf: animation 0 channel 0: 2 output values for 3 key times (expected 3)");

  Doc interpolation;
  interpolation.channel(0, "scale", {0.0f}, {1, 1, 1}, "BEZIER");
  EXPECT_EQ(errorOf([&] { (void)interpolation.motion(30); }),
            "t.gltf: animation 0 channel 0: interpolation 'BEZIER' (expected LINEAR, STEP or CUBICSPLINE)");

  Doc path;
  path.channel(0, "rotation", {0.0f}, {0, 0, 0, 1});
  path.channels.back() = R"({"sampler": 0, "target": {"node": 0, "path": "position"}})";
  EXPECT_EQ(errorOf([&] { (void)path.motion(30); }),
            "t.gltf: animation 0 channel 0: target path 'position' (expected translation, rotation, scale or weights)");

  Doc sampler;
  sampler.channel(0, "rotation", {0.0f}, {0, 0, 0, 1});
  sampler.channels.back() = R"({"sampler": 3, "target": {"node": 0, "path": "rotation"}})";
  EXPECT_EQ(errorOf([&] { (void)sampler.motion(30); }), "t.gltf: animation 0 channel 0: sampler 3 does not exist");

  Doc matrix;
  matrix.hipExtra = R"(, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,1,0,1])";
  matrix.channel(0, "rotation", {0.0f}, {0, 0, 0, 1});
  EXPECT_EQ(errorOf([&] { (void)matrix.motion(30); }),
            "t.gltf: animation 0 channel 0: node 0 has a matrix, and a node an animation targets must not");

  Doc endless;
  endless.channel(0, "rotation", {0.0f, 90000.0f}, {0, 0, 0, 1, 0, 0, 0, 1});
  EXPECT_EQ(errorOf([&] { (void)endless.motion(30); }),
            "t.gltf: animation 0 channel 0: key time 1 is 90000 (expected seconds from 0 to 86400)");
  Doc long_;
  long_.channel(0, "rotation", {0.0f, 86000.0f}, {0, 0, 0, 1, 0, 0, 0, 1});
  EXPECT_EQ(errorOf([&] { (void)long_.motion(60); }),
            "t.gltf: animation 'animation 0' lasts 86000 s: 5.16e+06 frames of 2 joints at 60 Hz are more than drape samples "
            "(10000000)");

  Doc rate;
  rate.channel(0, "rotation", {0.0f}, {0, 0, 0, 1});
  EXPECT_EQ(errorOf([&] { (void)rate.motion(0); }), "t.gltf: a motion rate of 0 frames per second");
  EXPECT_EQ(errorOf([&] { (void)parseGltfJointMotion(rate.text(), "t.gltf", "", 30, "1"); }),
            "t.gltf: has no animation '1' (it has 1: 0 'animation 0')");
}

TEST(GltfMotion, AnAnimationIsChosenByNameOrIndex) {
  Doc doc;
  doc.channel(0, "rotation", {0.0f, 1.0f}, {0, 0, 0, 1, 0, 0, kHalf, kHalf});
  doc.animationExtra = R"(, "name": "walk")";
  // "run" turns the knee with the same sampler.
  doc.moreAnimations = R"(, {"name": "run", "channels": [{"sampler": 0, "target": {"node": 1, "path": "rotation"}}],
    "samplers": [)" + doc.samplers[0] + "]}";
  const auto turned = [&](const std::string& which, std::size_t joint) {
    const GltfJointMotion m = parseGltfJointMotion(doc.text(), "t.gltf", "", 1.0, which);
    EXPECT_EQ(m.animationNames, (std::vector<std::string>{"walk", "run"}));
    return angleBetween(m.frames[2 + joint].rotation, aboutZ(90)) < 1e-6;  // frame 1 (1 s)
  };
  EXPECT_TRUE(turned("", 0));
  EXPECT_TRUE(turned("walk", 0));
  EXPECT_TRUE(turned("0", 0));
  EXPECT_FALSE(turned("run", 0));
  EXPECT_TRUE(turned("run", 1));
  EXPECT_TRUE(turned("1", 1));
  EXPECT_EQ(parseGltfJointMotion(doc.text(), "t.gltf", "", 1.0, "run").animation, "run");
  EXPECT_EQ(errorOf([&] { (void)parseGltfJointMotion(doc.text(), "t.gltf", "", 1.0, "jog"); }),
            "t.gltf: has no animation 'jog' (it has 2: 0 'walk', 1 'run')");
  EXPECT_EQ(errorOf([&] { (void)parseGltfJointMotion(doc.text(), "t.gltf", "", 1.0, "2"); }),
            "t.gltf: has no animation '2' (it has 2: 0 'walk', 1 'run')");
}

TEST(GltfMotion, CesiumManWalksWithBonesOfConstantLength) {
  const std::string path = std::string(DRAPE_DATA_DIR) + "/avatars/CesiumMan.glb";
  const GltfJointMotion m = readGltfJointMotion(path, 30.0);
  const GltfSkinnedModel model = readGltfSkinnedModel(path);
  ASSERT_EQ(m.joints.size(), 19u);
  // The skin's reader names the animation an avatar loaded from the file plays by itself.
  EXPECT_EQ(model.animations, (std::vector<std::string>{"animation 0"}));
  EXPECT_EQ(model.animations, m.animationNames);
  EXPECT_EQ(m.frameCount(), 61u);  // 2 s at 30 Hz
  EXPECT_NEAR(m.end_s - m.start_s, 2.0, 1e-6);
  double largestTurn = 0.0;
  for (std::size_t j = 0; j < m.joints.size(); ++j) {
    EXPECT_EQ(m.joints[j], model.joints[j].name);  // the avatar's order and names
    EXPECT_LT((m.restCenters[j] - Vec3(model.joints[j].restWorld.block<3, 1>(0, 3))).norm(), 1e-12);
    const int parent = model.joints[j].parent;
    for (std::size_t f = 0; f < m.frameCount(); ++f) {
      const RigidTransform& joint = m.frames[f * m.joints.size() + j];
      EXPECT_NEAR(joint.rotation.norm(), 1.0, 1e-12);
      largestTurn = std::max(largestTurn, angleBetween(joint.rotation, Quat::Identity()));
      if (parent < 0) continue;
      // A joint stays where its parent's motion carries its offset from the parent (its
      // offset in the first frame: CesiumMan's walk keys translations a few mm from the
      // nodes' own).
      const auto p = static_cast<std::size_t>(parent);
      const RigidTransform& up = m.frames[f * m.joints.size() + p];
      const Vec3 offset = m.frames[p].rotation.conjugate() * (m.frames[j].translation - m.frames[p].translation);
      EXPECT_LT((joint.translation - (up.translation + up.rotation * offset)).norm(), 1e-5) << m.joints[j] << " frame " << f;
    }
  }
  EXPECT_GT(largestTurn, 20.0 * std::numbers::pi / 180.0);  // it does walk
}

}  // namespace
}  // namespace drape::formats
