// The wire format: every message comes back as it went, doubles to the bit; damaged,
// truncated or foreign bytes are refused with a message, never read out of bounds.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>

#include "drape/core/error.hpp"
#include "drape/studio/messages.hpp"

namespace drape::studio {
namespace {

RigidTransform randomTransform(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Quat q = Quat(n(rng), n(rng), n(rng), n(rng)).normalized();
  return {q, Vec3(n(rng), n(rng), n(rng))};
}

std::vector<Message> sampleMessages(std::mt19937& rng) {
  std::vector<Message> out;
  PoseStart ps;
  ps.character = "makehuman";
  ps.joints = {"Hips", "LowerBack", "Spine", "LeftUpLeg"};
  ps.driving = {0, 1, -1, 7};
  ps.start = TimeCode{108000, 30.0};
  ps.frames = 141;
  out.push_back({"anim", "T1", ps});
  PoseFrame pf;
  pf.frame = 17;
  for (int j = 0; j < 4; ++j) pf.joints.push_back(randomTransform(rng));
  out.push_back({"anim", "T1", pf});
  pf.wind = Vec3(4.0, 0.0, -0.5);  // an event graph's gust
  out.push_back({"anim", "T1", pf});
  ClothStart cs;
  cs.poses = "anim";
  cs.poseTake = "T1";
  cs.character = "makehuman";
  cs.start = TimeCode{107970, 30.0};
  cs.leadIn_s = 1.0;
  cs.garments = {{"Skirt", 264}, {"Jacket", 3}};
  out.push_back({"cloth", "T1", cs});
  ClothFrame cf;
  cf.frame = 42;
  cf.garment = 1;
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int v = 0; v < 3; ++v) cf.positions.emplace_back(u(rng), u(rng), u(rng));
  cf.states = {0, 1, 6};
  out.push_back({"cloth", "T1", cf});
  out.push_back({"cloth", "T1", End{170, "{\"frames\": 170}\n", "", 0}});
  out.push_back({"cloth", "T1", End{26, "", "garment 'Skirt' went unstable at vertex 12 in frame 26", 3}});
  out.push_back({"inject", "", Inject{"#VRML V2.0 utf8\nPlay { motion \"kick.bvh\" }\n", "/studio/takes", ""}});
  out.push_back({"inject", "", Inject{"", "", "kick"}});
  out.push_back({"anim", "", InjectReply{true, "started the graph at frame 120"}});
  return out;
}

void expectSame(const Message& a, const Message& b) {
  ASSERT_EQ(a.source, b.source);
  ASSERT_EQ(a.take, b.take);
  ASSERT_EQ(a.payload.index(), b.payload.index());
  if (const auto* x = std::get_if<PoseStart>(&a.payload)) {
    const auto& y = std::get<PoseStart>(b.payload);
    EXPECT_EQ(x->character, y.character);
    EXPECT_EQ(x->joints, y.joints);
    EXPECT_EQ(x->driving, y.driving);
    EXPECT_EQ(x->start.frame, y.start.frame);
    EXPECT_EQ(x->start.rate, y.start.rate);
    EXPECT_EQ(x->frames, y.frames);
  } else if (const auto* x = std::get_if<PoseFrame>(&a.payload)) {
    const auto& y = std::get<PoseFrame>(b.payload);
    EXPECT_EQ(x->frame, y.frame);
    EXPECT_EQ(x->wind, y.wind);
    ASSERT_EQ(x->joints.size(), y.joints.size());
    for (std::size_t j = 0; j < x->joints.size(); ++j) {
      EXPECT_EQ(x->joints[j].rotation.coeffs(), y.joints[j].rotation.coeffs());
      EXPECT_EQ(x->joints[j].translation, y.joints[j].translation);
    }
  } else if (const auto* x = std::get_if<ClothStart>(&a.payload)) {
    const auto& y = std::get<ClothStart>(b.payload);
    EXPECT_EQ(x->poses, y.poses);
    EXPECT_EQ(x->poseTake, y.poseTake);
    EXPECT_EQ(x->character, y.character);
    EXPECT_EQ(x->start.frame, y.start.frame);
    EXPECT_EQ(x->leadIn_s, y.leadIn_s);
    ASSERT_EQ(x->garments.size(), y.garments.size());
    for (std::size_t g = 0; g < x->garments.size(); ++g) {
      EXPECT_EQ(x->garments[g].name, y.garments[g].name);
      EXPECT_EQ(x->garments[g].vertices, y.garments[g].vertices);
    }
  } else if (const auto* x = std::get_if<ClothFrame>(&a.payload)) {
    const auto& y = std::get<ClothFrame>(b.payload);
    EXPECT_EQ(x->frame, y.frame);
    EXPECT_EQ(x->garment, y.garment);
    EXPECT_EQ(x->positions, y.positions);
    EXPECT_EQ(x->states, y.states);
  } else if (const auto* x = std::get_if<Inject>(&a.payload)) {
    const auto& y = std::get<Inject>(b.payload);
    EXPECT_EQ(x->graph, y.graph);
    EXPECT_EQ(x->baseDir, y.baseDir);
    EXPECT_EQ(x->event, y.event);
  } else if (const auto* x = std::get_if<InjectReply>(&a.payload)) {
    const auto& y = std::get<InjectReply>(b.payload);
    EXPECT_EQ(x->accepted, y.accepted);
    EXPECT_EQ(x->message, y.message);
  } else {
    const auto& x2 = std::get<End>(a.payload);
    const auto& y = std::get<End>(b.payload);
    EXPECT_EQ(x2.frames, y.frames);
    EXPECT_EQ(x2.stats, y.stats);
    EXPECT_EQ(x2.error, y.error);
    EXPECT_EQ(x2.exitCode, y.exitCode);
  }
}

TEST(StudioMessages, EveryMessageComesBackAsItWentDoublesToTheBit) {
  std::mt19937 rng(11);
  for (int round = 0; round < 50; ++round)
    for (const Message& m : sampleMessages(rng)) {
      const std::vector<std::uint8_t> bytes = encode(m);
      expectSame(m, decode(bytes));
    }
}

std::vector<std::uint8_t> fileBytes(const std::string& name) {
  std::ifstream in(std::string(DRAPE_TEST_DATA_DIR) + "/studio/" + name, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(StudioMessages, MessagesOfWireVersionOneStillRead) {
  // Written once by this wire version and kept (tests/data/studio, also the fuzzer's
  // seeds): a later drape must still read them as they were.
  const Message ps = decode(fileBytes("pose_start.drps"));
  EXPECT_EQ(ps.source, "anim");
  EXPECT_EQ(ps.take, "20261201T120000Z-0001");
  EXPECT_EQ(std::get<PoseStart>(ps.payload).joints, (std::vector<std::string>{"Hips", "LowerBack", "Spine"}));
  EXPECT_EQ(std::get<PoseStart>(ps.payload).start.frame, 108000);
  const auto pf = std::get<PoseFrame>(decode(fileBytes("pose_frame.drps")).payload);
  EXPECT_EQ(pf.frame, 17);
  EXPECT_EQ(pf.joints[0].rotation.coeffs(), Quat(0.5, 0.5, 0.5, 0.5).coeffs());
  EXPECT_EQ(pf.joints[2].translation, Vec3(0.25, 1.25, 0.0));
  const auto cs = std::get<ClothStart>(decode(fileBytes("cloth_start.drps")).payload);
  EXPECT_EQ(cs.garments.size(), 2u);
  EXPECT_EQ(cs.leadIn_s, 1.0);
  for (const char* name : {"cloth_frame.drps", "cloth_frame_float.drps"}) {
    const auto cf = std::get<ClothFrame>(decode(fileBytes(name)).payload);
    EXPECT_EQ(cf.positions[2], Vec3(0.5, 1.0, 0.5)) << name;
    EXPECT_EQ(cf.states, (std::vector<std::uint8_t>{0, 1, 2, 16})) << name;
  }
  EXPECT_EQ(std::get<End>(decode(fileBytes("end.drps")).payload).frames, 170);
}

TEST(StudioMessages, FloatPositionsAreTheDoublesRoundedOnce) {
  ClothFrame cf;
  cf.positions = {Vec3(0.1, -1.0 / 3.0, 2.718281828459045), Vec3(1e-9, 123.456789, -0.5)};
  cf.states = {0, 2};
  const Message back = decode(encode(Message{"cloth", "T", cf}, Precision::Float));
  const auto& got = std::get<ClothFrame>(back.payload);
  ASSERT_EQ(got.positions.size(), 2u);
  for (std::size_t v = 0; v < 2; ++v)
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(got.positions[v][k], static_cast<double>(static_cast<float>(cf.positions[v][k])));
  // Half the bytes of doubles, near enough: 24 -> 12 per vertex.
  ClothFrame big;
  big.positions.assign(1000, Vec3(0.25, 0.5, 0.75));
  EXPECT_LT(encode(Message{"c", "T", big}, Precision::Float).size(),
            encode(Message{"c", "T", big}, Precision::Double).size() * 6 / 10);
}

/// decode's message for `bytes`, or "" when it took them.
std::string refusal(const std::vector<std::uint8_t>& bytes) {
  try {
    (void)decode(bytes);
    return "";
  } catch (const Error& e) {
    return e.what();
  }
}

TEST(StudioMessages, TruncatedMessagesAreRefusedOrLoseNothing) {
  // Cut at every length: refused, unless what was cut is the builder's padding at the end,
  // and then the message is whole.
  std::mt19937 rng(3);
  for (const Message& m : sampleMessages(rng)) {
    const std::vector<std::uint8_t> bytes = encode(m);
    int refused = 0;
    for (std::size_t n = 0; n < bytes.size(); ++n) {
      const std::vector<std::uint8_t> cut(bytes.begin(), bytes.begin() + static_cast<long>(n));
      const std::string why = refusal(cut);
      if (why.empty()) {
        ASSERT_GE(n + 8, bytes.size()) << describe(m.payload) << " cut to " << n << " of " << bytes.size() << " bytes";
        expectSame(m, decode(cut));
        continue;
      }
      ++refused;
      ASSERT_EQ(why.rfind("not a drape studio frame: ", 0), 0u) << why;
    }
    EXPECT_GE(refused + 8, static_cast<int>(bytes.size()));
  }
}

TEST(StudioMessages, DamagedBytesNeverCrashTheReader) {
  // Random bytes, and valid messages with random bytes changed: refused with a message, or
  // read as some message whose numbers are all finite (a change inside a number's bytes is
  // a message too); never a read outside the buffer (the sanitizer build watches).
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> byte(0, 255);
  int refused = 0, read = 0;
  const std::vector<Message> samples = sampleMessages(rng);
  for (int round = 0; round < 4000; ++round) {
    std::vector<std::uint8_t> bytes;
    if (round % 4 == 0) {
      bytes.resize(static_cast<std::size_t>(byte(rng) + 8));
      for (auto& b : bytes) b = static_cast<std::uint8_t>(byte(rng));
      if (round % 8 == 0) std::copy_n("DRPS", 4, bytes.begin() + 4);  // past the identifier check
    } else {
      bytes = encode(samples[static_cast<std::size_t>(round) % samples.size()]);
      const int changes = 1 + round % 5;
      for (int c = 0; c < changes; ++c)
        bytes[std::uniform_int_distribution<std::size_t>(0, bytes.size() - 1)(rng)] = static_cast<std::uint8_t>(byte(rng));
    }
    try {
      const Message m = decode(bytes);
      ++read;
      if (const auto* f = std::get_if<ClothFrame>(&m.payload)) {
        for (const Vec3& p : f->positions) ASSERT_TRUE(p.allFinite());
      }
      if (const auto* f = std::get_if<PoseFrame>(&m.payload)) {
        for (const RigidTransform& t : f->joints) ASSERT_NEAR(t.rotation.norm(), 1.0, 1e-6);
      }
    } catch (const Error& e) {
      ++refused;
      ASSERT_EQ(std::string(e.what()).rfind("not a drape studio frame: ", 0), 0u) << e.what();
    }
  }
  EXPECT_GT(refused, 1000);
  EXPECT_GT(read, 10);
}

TEST(StudioMessages, WhatIsRefusedIsSaid) {
  EXPECT_NE(refusal({1, 2, 3}).find("3 bytes are too few"), std::string::npos);
  EXPECT_NE(refusal(std::vector<std::uint8_t>(64, 0)).find("not the identifier \"DRPS\""), std::string::npos);

  PoseFrame pf;
  pf.frame = 3;
  pf.joints = {RigidTransform{Quat(2.0, 0.0, 0.0, 0.0), Vec3::Zero()}};
  EXPECT_NE(refusal(encode(Message{"a", "T", pf})).find("PoseFrame 3 has a joint rotation of norm 2, not a unit quaternion"),
            std::string::npos)
      << refusal(encode(Message{"a", "T", pf}));
  pf.joints = {RigidTransform{Quat::Identity(), Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0)}};
  EXPECT_NE(refusal(encode(Message{"a", "T", pf})).find("not finite"), std::string::npos);

  ClothFrame cf;
  cf.frame = 9;
  cf.positions = {Vec3(0, 0, 0), Vec3(1, 1, 1)};
  cf.states = {0};
  EXPECT_NE(refusal(encode(Message{"c", "T", cf})).find("ClothFrame 9 of garment 0 has 2 vertices and 1 states"),
            std::string::npos);

  PoseStart ps;
  ps.joints = {"Hips"};
  ps.driving = {0};
  ps.start = TimeCode{0, 0.0};
  EXPECT_NE(refusal(encode(Message{"a", "T", ps})).find("PoseStart has a frame rate of 0"), std::string::npos);
}

}  // namespace
}  // namespace drape::studio
