// EGML scripts as read: every kind of event, and what a script it cannot use is told.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "drape/events/graph.hpp"
#include "drape/testing/errors.hpp"
#include "drape/testing/temp_dir.hpp"

namespace drape::events {
namespace {

const std::string kWalk = std::string(DRAPE_DATA_DIR) + "/mocap/cmu_12_03_walk.bvh";

/// `text` written as NAME.egml in a directory of its own; its path.
std::string script(const std::string& name, const std::string& text) {
  const std::filesystem::path dir = testing::processTempDir("egml-" + name);
  const std::string path = (dir / (name + ".egml")).string();
  std::ofstream(path) << "#VRML V2.0 utf8\n" << text;
  return path;
}

TEST(EgmlGraph, ReadsEveryKindOfEvent) {
  const std::string path = script("every", R"(
EventGraph {
  name "day" character "Body"
  children [
    Sequence { name "walk and kick" speed 1.5 duration 20 children [
      Play { motion ")" + kWalk + R"(" from 1 to 3.5 speed 2 blend 0.4 anchor FALSE }
      Wait { duration 0.5 }
      Wind { velocity 3 0 -1 duration 2 }
    ] }
    Loop { count 3 children [ Wait { duration 0.25 } ] }
    Parameters { names [ "mood" ] values [ "calm" ] children [
      Condition { parameter "mood" equals [ "calm" "slow" ] then Wait { duration 1 } }
    ] }
    StateMachine { initial "Idle" states [
      State { name "Idle" children [ Wait { duration 2 } ] on [ "kick" ] to [ "Kick" ] next "Idle" }
      State { name "Kick" children [ Wait { duration 1 } ] next "Idle" }
    ] }
  ]
}
)");
  const Graph g = readGraph(path);
  EXPECT_EQ(g.name, "day");
  EXPECT_EQ(g.root.kind, Kind::Parallel);
  EXPECT_EQ(g.root.character, "Body");
  ASSERT_EQ(g.root.children.size(), 4u);
  const Event& seq = g.root.children[0];
  EXPECT_EQ(seq.kind, Kind::Sequence);
  EXPECT_EQ(seq.speed, 1.5);
  EXPECT_EQ(seq.duration_s, 20.0);
  EXPECT_EQ(seq.where.line, 6);
  const Event& play = seq.children[0];
  EXPECT_EQ(play.kind, Kind::Play);
  EXPECT_EQ(play.motion, std::filesystem::path(kWalk).lexically_normal().string());
  EXPECT_EQ(play.from_s, 1.0);
  EXPECT_EQ(play.to_s, 3.5);
  EXPECT_EQ(play.speed, 2.0);
  EXPECT_FLOAT_EQ(static_cast<float>(play.blend_s), 0.4f);
  EXPECT_FALSE(play.anchor);
  EXPECT_EQ(seq.children[2].velocity, Vec3(3, 0, -1));
  EXPECT_EQ(g.root.children[1].count, 3);
  const Event& params = g.root.children[2];
  ASSERT_EQ(params.parameters.size(), 1u);
  EXPECT_EQ(params.parameters[0], (std::pair<std::string, std::string>{"mood", "calm"}));
  const Event& cond = params.children[0];
  EXPECT_EQ(cond.parameter, "mood");
  EXPECT_EQ(cond.equals, (std::vector<std::string>{"calm", "slow"}));
  ASSERT_EQ(cond.children.size(), 2u);
  EXPECT_EQ(cond.children[1].kind, Kind::Wait);  // no otherwise: nothing, at once
  EXPECT_EQ(cond.children[1].duration_s, 0.0);
  const Event& machine = g.root.children[3];
  ASSERT_EQ(machine.children.size(), 2u);
  EXPECT_EQ(machine.initial, 0u);
  EXPECT_EQ(machine.children[0].on, (std::vector<std::string>{"kick"}));
  EXPECT_EQ(machine.children[0].to, (std::vector<std::size_t>{1}));
  EXPECT_EQ(machine.children[0].next, 0);
  EXPECT_EQ(machine.children[1].next, 0);
  EXPECT_EQ(g.motions().size(), 1u);
  EXPECT_EQ(g.characters(), (std::vector<std::string>{"Body"}));
}

TEST(EgmlGraph, ReadsAPath) {
  const Graph g = readGraph(script("path", R"(
Parallel { children [
  Path { points [ 0 0 0, 2 0 0, 2 0.5 3 ] speed 1.2 ease 0.25 corner 0.4 }
  Path { points [ 0 0 0, 0 0 1 ] turn FALSE }
] }
)"));
  const Event& carried = g.root.children[0].children[0];
  EXPECT_EQ(carried.kind, Kind::Path);
  EXPECT_EQ(carried.where.line, 4);
  EXPECT_EQ(carried.points, (std::vector<Vec3>{Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(2, 0.5, 3)}));
  EXPECT_FLOAT_EQ(static_cast<float>(carried.pathSpeed_mps), 1.2f);
  EXPECT_EQ(carried.ease_s, 0.25);
  EXPECT_FLOAT_EQ(static_cast<float>(carried.corner_m), 0.4f);
  EXPECT_TRUE(carried.turn);
  const Event& steering = g.root.children[0].children[1];
  EXPECT_EQ(steering.pathSpeed_mps, 0.0);  // steers the character's own travel
  EXPECT_EQ(steering.ease_s, 0.5);
  EXPECT_FALSE(steering.turn);
}

TEST(EgmlGraph, WhatItCannotUseIsSaidWithItsLine) {
  const auto refused = [](const std::string& name, const std::string& text) {
    const std::string path = script(name, text);
    return std::make_pair(path, testing::errorOf([&] { (void)readGraph(path); }));
  };
  auto [p1, e1] = refused("field", "Sequence { children [ Wait { duratoin 2 } ] }\n");
  EXPECT_EQ(e1.rfind(p1 + ":2:", 0), 0u) << e1;
  EXPECT_NE(e1.find("unknown field 'duratoin' in Wait"), std::string::npos) << e1;
  auto [p2, e2] = refused("duration", "Sequence { children [\n  Wait { duration -3 }\n] }\n");
  EXPECT_EQ(e2, p2 + ":3: Wait: duration -3 must be >= 0 seconds, or -1") << e2;
  auto [p3, e3] = refused("motion", "Play { motion \"nowhere.bvh\" }\n");
  EXPECT_EQ(e3.rfind(p3 + ":2: Play: motion nowhere.bvh is not there (looked in ", 0), 0u) << e3;
  auto [p4, e4] = refused("state", "StateMachine { states [ State { name \"A\" next \"B\" } ] }\n");
  EXPECT_EQ(e4, p4 + ":2: State: 'B' is no state of the machine (it has: A)") << e4;
  auto [p5, e5] = refused("on", "StateMachine { states [ State { name \"A\" on [ \"x\" \"y\" ] to [ \"A\" ] } ] }\n");
  EXPECT_NE(e5.find("2 events in 'on' and 1 states in 'to'"), std::string::npos) << e5;
  auto [p6, e6] = refused("loop", "Loop { }\n");
  EXPECT_EQ(e6, p6 + ":2: Loop: repeats no events (its children are empty)") << e6;
  auto [p7, e7] = refused("kind", "Sequence { children [ Transform { } ] }\n");
  EXPECT_NE(e7.find("Transform is not an event (an EGML event is one of: EventGraph, Condition, Loop"),
            std::string::npos)
      << e7;
  auto [p8, e8] = refused("empty", "WorldInfo { }\n");
  EXPECT_NE(e8.find("no events: an EGML script holds an EventGraph"), std::string::npos) << e8;
  auto [p9, e9] = refused("to", "Play { motion \"" + kWalk + "\" from 2 to 1 }\n");
  EXPECT_NE(e9.find("Play: to 1 must be after from 2"), std::string::npos) << e9;
  auto [p10, e10] = refused("speed", "Parallel { speed 0 }\n");
  EXPECT_NE(e10.find("Parallel: speed 0 must be > 0"), std::string::npos) << e10;
  auto [p11, e11] = refused("path1", "Path { points [ 1 0 1 ] }\n");
  EXPECT_EQ(e11, p11 + ":2: Path: 1 points: a path goes through 2 or more") << e11;
  auto [p12, e12] = refused("path2", "Path {\n  points [ 0 0 0, 1 0 0, 1 2 0 ] }\n");
  EXPECT_EQ(e12, p12 + ":3: Path: points 1 and 2 are one place on the floor: a path goes somewhere") << e12;
  auto [p13, e13] = refused("path3", "Path { points [ 0 0 0, 1 0 0 ] speed -1 }\n");
  EXPECT_NE(e13.find("Path: speed -1 must be >= 0 m/s (0: as the character's motion travels)"), std::string::npos) << e13;
  auto [p14, e14] = refused("path4", "Path { points [ 0 0 0, 1 0 0 ] ease -0.5 }\n");
  EXPECT_NE(e14.find("Path: ease -0.5 must be >= 0 s"), std::string::npos) << e14;
}

}  // namespace
}  // namespace drape::events
