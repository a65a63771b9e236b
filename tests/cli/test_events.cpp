// drape run --events: an EGML event graph drives the avatar (docs/EVENTS.md). A graph of one
// Play is the motion it plays, to the byte; the bundled day's gust moves the skirt from the
// frame it starts and not before; the bundled stroll's Path turns the walk round its bend;
// parameters and events reach the graph; errors say what to do.

#include <gtest/gtest.h>

#include <fstream>

#include "cli_runner.hpp"
#include "drape/formats/pc2.hpp"

namespace drape::testing {
namespace {

const std::string kScene = kSkirtDir + "/scene.wrl";
const std::string kDay = std::string(DRAPE_SOURCE_DIR) + "/examples/event_graph/day.egml";

std::string writeScript(const ScratchDir& dir, const std::string& name, const std::string& body) {
  const std::string path = dir / name;
  std::ofstream(path) << "#VRML V2.0 utf8\n" << body;
  return path;
}

TEST(EventGraphRun, OnePlayIsTheMotionItPlaysToTheByte) {
  ScratchDir dir("events-one-play");
  const std::string script =
      writeScript(dir, "walk.egml", "Play { motion \"" + kSkirtDir + "/walk.bvh\" blend 0 anchor FALSE }\n");
  const std::string played = runInto(dir, "events", "'" + kScene + "' --events '" + script + "'");
  const std::string motion = runInto(dir, "motion", "'" + kScene + "' --motion '" + kSkirtDir + "/walk.bvh'");
  for (const char* file : {"garment.pc2", "garment.states", "body.pc2"})
    EXPECT_TRUE(slurp(played + "/" + file) == slurp(motion + "/" + file)) << file;
  EXPECT_EQ(statsOf(played)["frames"], statsOf(motion)["frames"]);
}

TEST(EventGraphRun, TheDaysGustMovesTheSkirtFromItsFrameOn) {
  ScratchDir dir("events-day");
  // The bundled day, and the same without its gust: the same to the bit up to the frame the
  // gust starts in (script time 2 s, after the 1 s lead-in: frame 90), other after it.
  std::string still = slurp(kDay);
  const std::string gust = "velocity 4 0 0";
  still.replace(still.find(gust), gust.size(), "velocity 0 0 0");
  // Written elsewhere: the motions' paths relative to the example made whole.
  const auto whole = [](std::string text) {
    for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
             {"../walking_skirt/", kSkirtDir + "/"}, {"../../data/mocap/", std::string(DRAPE_DATA_DIR) + "/mocap/"}})
      for (std::size_t at; (at = text.find(from)) != std::string::npos;) text.replace(at, from.size(), to);
    return text;
  };
  std::ofstream(dir / "day.egml") << whole(slurp(kDay));
  std::ofstream(dir / "calm.egml") << whole(still);
  const std::string windy = runInto(dir, "windy", "'" + kScene + "' --events '" + (dir / "day.egml") + "' --frames 120");
  const std::string quiet = runInto(dir, "quiet", "'" + kScene + "' --events '" + (dir / "calm.egml") + "' --frames 120");
  const formats::Pc2Cache a = formats::readPc2(windy + "/garment.pc2"), b = formats::readPc2(quiet + "/garment.pc2");
  ASSERT_EQ(a.frames.size(), 121u);
  ASSERT_EQ(b.frames.size(), 121u);
  for (std::size_t f = 0; f < 90; ++f) ASSERT_EQ(a.frames[f], b.frames[f]) << "frame " << f << ": before the gust";
  double moved = 0.0;
  for (std::size_t v = 0; v < a.frames[119].size(); ++v) moved = std::max(moved, (a.frames[119][v] - b.frames[119][v]).norm());
  EXPECT_GT(moved, 0.01) << "the gust blew the skirt by " << moved << " m";
  EXPECT_EQ(statsOf(windy)["vertex_substeps_inside_body"], 0);
}

TEST(EventGraphRun, ParametersAndEventsReachTheGraph) {
  ScratchDir dir("events-parameters");
  const std::string script = writeScript(dir, "choice.egml", R"(
EventGraph { children [
  Condition { parameter "weather" equals [ "storm" ]
    then Wind { velocity 6 0 0 }
    otherwise Wind { velocity 0 0 0 } }
  StateMachine { states [
    State { name "Stand" children [ Wait { duration 10 } ] on [ "go" ] to [ "Walk" ] }
    State { name "Walk" children [ Play { motion ")" + kSkirtDir + R"(/walk.bvh" to 1 } ] }
  ] }
] }
)");
  const std::string base = "'" + kScene + "' --events '" + script + "' --frames 50";
  const std::string plain = runInto(dir, "plain", base);
  const std::string storm = runInto(dir, "storm", base + " --set weather=storm");
  const std::string going = runInto(dir, "going", base + " --send go@0.2");
  EXPECT_FALSE(slurp(plain + "/garment.pc2") == slurp(storm + "/garment.pc2")) << "--set weather=storm blows nothing";
  EXPECT_TRUE(slurp(plain + "/segments/Hips.pc2") == slurp(storm + "/segments/Hips.pc2")) << "the body is the same";
  EXPECT_FALSE(slurp(plain + "/segments/Hips.pc2") == slurp(going + "/segments/Hips.pc2")) << "--send go moved nothing";
}

/// The mean of a point cache's frame: where the body is.
Vec3 centroid(const formats::Pc2Cache& cache, std::size_t frame) {
  Vec3 sum = Vec3::Zero();
  for (const Vec3& p : cache.frames.at(frame)) sum += p;
  return sum / static_cast<double>(cache.frames.at(frame).size());
}

TEST(EventGraphRun, TheBundledStrollTurnsTheWalkRoundItsBend) {
  // The bundled stroll, and the same walk with its steering Path taken out: the steered
  // walk ends up about 43 degrees to the left of the straight one (its 3 m of path: 0.25 m
  // ahead, 1.5 m of bend, the rest at 60 degrees; then half a metre more of walk at 60), the
  // skirt on the body throughout.
  ScratchDir dir("events-stroll");
  const std::string stroll = std::string(DRAPE_SOURCE_DIR) + "/examples/event_graph/stroll.egml";
  std::string text = slurp(stroll);
  for (std::size_t at; (at = text.find("../walking_skirt/")) != std::string::npos;)
    text.replace(at, 17, kSkirtDir + "/");
  std::ofstream(dir / "stroll.egml") << text;
  const std::string steer = "Path { points [ 0 0 0, 0 0 1, 1.732 0 2 ] corner 1.5 }";
  ASSERT_NE(text.find(steer), std::string::npos);
  text.replace(text.find(steer), steer.size(), "");
  std::ofstream(dir / "straight.egml") << text;
  const std::string steered = runInto(dir, "steered", "'" + kScene + "' --events '" + (dir / "stroll.egml") + "'");
  const std::string straight = runInto(dir, "straight", "'" + kScene + "' --events '" + (dir / "straight.egml") + "'");
  const formats::Pc2Cache a = formats::readPc2(steered + "/body.pc2"), b = formats::readPc2(straight + "/body.pc2");
  ASSERT_EQ(a.frames.size(), b.frames.size());
  const std::size_t start = 30, walked = 30 + 126;  // after the lead-in; 4.2 s of walk later
  const Vec3 da = centroid(a, walked) - centroid(a, start), db = centroid(b, walked) - centroid(b, start);
  const double turned = std::atan2(db.z() * da.x() - db.x() * da.z(), db.x() * da.x() + db.z() * da.z()) * 180.0 / M_PI;
  EXPECT_GT(turned, 33.0) << da.transpose() << " against " << db.transpose();
  EXPECT_LT(turned, 53.0) << da.transpose() << " against " << db.transpose();
  // Then both are carried the same 0.8 m, standing.
  const Vec3 ca = centroid(a, a.frames.size() - 1) - centroid(a, walked), cb = centroid(b, b.frames.size() - 1) - centroid(b, walked);
  EXPECT_NEAR((ca - cb).norm(), 0.0, 0.05) << ca.transpose() << " against " << cb.transpose();
  EXPECT_NEAR(Vec3(ca.x(), 0, ca.z()).norm(), 0.806, 0.05);
  for (const std::string& run : {steered, straight}) {
    EXPECT_EQ(statsOf(run)["vertex_substeps_inside_body"], 0) << run;
    EXPECT_EQ(statsOf(run)["vertex_substeps_below_T0"], 0) << run;
  }
}

TEST(EventGraphRun, ErrorsSayWhatToDo) {
  ScratchDir dir("events-errors");
  const std::string endless = writeScript(dir, "endless.egml", "Loop { children [ Wait { duration 1 } ] }\n");
  CliResult r = runDrape("run '" + kScene + "' --events '" + endless + "' --out '" + (dir / "a") + "'", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("runs on past an hour"), std::string::npos) << r.err;
  r = runDrape("run '" + kScene + "' --events '" + endless + "' --frames 3 --out '" + (dir / "b") + "'", dir);
  EXPECT_EQ(r.code, 0) << r.err;
  r = runDrape("run '" + kScene + "' --events '" + endless + "' --motion '" + kSkirtDir + "/walk.bvh' --out '" +
                   (dir / "c") + "'",
               dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("give it or --motion, not both"), std::string::npos) << r.err;
  r = runDrape("run '" + kScene + "' --set a=b --out '" + (dir / "d") + "'", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--set: it is for an event graph"), std::string::npos) << r.err;
  r = runDrape("run '" + kScene + "' --events '" + endless + "' --send go --frames 3 --out '" + (dir / "e") + "'", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--send go: expected EVENT@SECONDS"), std::string::npos) << r.err;
  const std::string bad = writeScript(dir, "bad.egml", "Sequence { children [\n  Play { }\n] }\n");
  r = runDrape("run '" + kScene + "' --events '" + bad + "' --out '" + (dir / "f") + "'", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(bad + ":3: Play: names no motion to play"), std::string::npos) << r.err;
  r = runDrape("inspect '" + kDay + "'", dir);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("EGML event graph 'walk, kick, walk', 2 events at its top, 2 motions, 7.4 s"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("Wind  (line 23): 4 0 0 m/s for 1.5 s"), std::string::npos) << r.out;
  r = runDrape("inspect '" + std::string(DRAPE_SOURCE_DIR) + "/examples/event_graph/stroll.egml'", dir);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("Path  (line 19): 3 points, 3 m, steering the character's own travel, turning 60 degrees"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("Path  (line 23): 2 points, 0.806 m, carried at 0.5 m/s, not turning, 2.21245 s"),
            std::string::npos)
      << r.out;
}

}  // namespace
}  // namespace drape::testing
