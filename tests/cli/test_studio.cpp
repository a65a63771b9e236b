// The studio's three roles as separate processes on a real nats-server: what the player
// records is what drape run writes, to the byte, also when a cloth-server is killed in the
// middle of the take and started again, when junk arrives on the pose stream, when two
// cloth-servers split the garments, when one garment is worn over another, and when the take
// goes unstable; a window shows a take live or from a time code; errors say what to do.

#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <cctype>
#include <filesystem>
#include <functional>
#include <sstream>
#include <fstream>
#include <thread>

#include <fmt/format.h>

#include "cli_runner.hpp"
#include "drape/core/timecode.hpp"
#include "drape/studio/bus.hpp"
#include "drape/studio/messages.hpp"
#include "drape/testing/nats_server.hpp"

namespace drape::testing {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

const std::string kScene = kSkirtDir + "/scene.wrl";
const std::string kWalk = kSkirtDir + "/walk.bvh";

/// stats.json without what the clocks say.
nlohmann::json untimed(nlohmann::json stats) {
  for (const char* key : {"ms_per_frame", "loop_wall_ms_per_frame", "ms_per_stage", "frame_ms_per_stage",
                          "collision_time_share", "penetration_measure_ms_per_frame", "animation_ms_per_frame",
                          "distance_field_build_s", "distance_fields", "settle"})
    stats.erase(key);
  return stats;
}

/// Every file of run directory `got` is the one of `want`, byte for byte (stats.json but
/// its timings).
void expectSameRun(const std::string& got, const std::string& want) {
  std::size_t files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(want)) {
    if (!entry.is_regular_file()) continue;
    const fs::path relative = fs::relative(entry.path(), want);
    const fs::path mine = fs::path(got) / relative;
    ASSERT_TRUE(fs::exists(mine)) << relative << " was not recorded";
    ++files;
    if (relative == "stats.json") {
      EXPECT_EQ(untimed(statsOf(got)), untimed(statsOf(want)));
      continue;
    }
    ASSERT_EQ(slurp(mine.string()) == slurp(entry.path().string()), true) << relative << " differs";
  }
  EXPECT_GT(files, 40u);
}

std::string roles(const NatsServer& server) { return " --server " + server.url() + " --give-up 120"; }

/// One take through the studio on `server`: a cloth-server of `scene` for one take, the
/// anim-server sending `motion` (its --motion or --events arguments) as fast as it can, and
/// a player recording the take into dir/recorded. What each said, for the test to look at.
struct StudioTake {
  CliResult sent, served, recorded;
};
StudioTake takeThroughTheStudio(const ScratchDir& dir, const NatsServer& server, const std::string& scene,
                                const std::string& motion) {
  DrapeProcess cloth("cloth-server '" + scene + "' --takes 1" + roles(server), dir, "cloth");
  StudioTake take;
  take.sent = runDrape("anim-server '" + scene + "' " + motion + " --fast" + roles(server), dir);
  take.served = cloth.wait();
  take.recorded = runDrape("player '" + scene + "' --record '" + (dir / "recorded") + "'" + roles(server), dir);
  return take;
}

TEST(Studio, ThePlayerRecordsWhatDrapeRunWritesThroughAKilledClothServerAndJunk) {
  ScratchDir dir("studio-roles");
  NatsServer server;
  // The take at ten in the morning: the recording keeps its time code, as drape run numbers it.
  const std::string reference =
      runInto(dir, "reference", "'" + kScene + "' --motion '" + kWalk + "' --timecode 10:00:00:00");

  // The player first: it waits for the cloth. Then a cloth-server, then the anim-server at
  // the frame rate, so that the take is under way when the cloth-server is killed.
  DrapeProcess player("player '" + kScene + "' --record '" + (dir / "recorded") + "'" + roles(server), dir, "player");
  auto cloth = std::make_unique<DrapeProcess>("cloth-server '" + kScene + "' --takes 1" + roles(server), dir, "cloth1");
  DrapeProcess anim("anim-server '" + kScene + "' --motion '" + kWalk + "' --take walk-1 --timecode 10:00:00:00" +
                        roles(server),
                    dir, "anim");

  studio::Bus bus = studio::Bus::connect(server.url(), "test");
  bus.ensureStream("anim");
  // Junk on the pose stream while the take runs: a server survives bad frames.
  for (int i = 0; i < 50 && bus.range("anim").messages < 10; ++i) std::this_thread::sleep_for(100ms);
  (void)bus.publish("anim", std::vector<std::uint8_t>{'n', 'o', 't', ' ', 'a', ' ', 'f', 'r', 'a', 'm', 'e', '!'}, "junk");
  bus.ensureStream("cloth");
  for (int i = 0; i < 600 && bus.range("cloth").messages < 60; ++i) std::this_thread::sleep_for(50ms);
  const CliResult killed = cloth->kill();
  const std::uint64_t held = bus.range("cloth").messages;
  EXPECT_GE(held, 60u);
  EXPECT_LT(held, 170u) << "the cloth-server was to be killed in the middle of the take";
  EXPECT_NE(killed.err.find("not a drape studio frame"), std::string::npos) << killed.err;

  // Started again, it computes the take from its start and sends only what is missing.
  cloth = std::make_unique<DrapeProcess>("cloth-server '" + kScene + "' --takes 1" + roles(server), dir, "cloth2");
  const CliResult sent = anim.wait();
  ASSERT_EQ(sent.code, 0) << sent.err;
  EXPECT_NE(sent.out.find("sent take walk-1: 141 pose frames"), std::string::npos) << sent.out;
  const CliResult again = cloth->wait();
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_NE(again.err.find("drape.cloth: the stream already holds"), std::string::npos) << again.err;
  EXPECT_NE(again.out.find("take walk-1: 170 cloth frames of Skirt sent to drape.cloth"), std::string::npos) << again.out;
  const CliResult recorded = player.wait();
  ASSERT_EQ(recorded.code, 0) << recorded.err;
  EXPECT_NE(recorded.out.find("recorded take walk-1: 171 frames"), std::string::npos) << recorded.out;
  EXPECT_EQ(bus.range("cloth").messages, 173u) << "the take's start, 171 frames and its end, each once";
  expectSameRun(dir / "recorded", reference);
  EXPECT_EQ(formats::readRunManifest(dir / "recorded").startFrame, 10 * 3600 * 30 - 30) << "the lead-in before 10:00";
  const CliResult inspected = runDrape("inspect '" + (dir / "recorded") + "'", dir);
  EXPECT_NE(inspected.out.find("171 frames at 30 fps (09:59:59:00 to 10:00:04:20)"), std::string::npos) << inspected.out;
}

TEST(Studio, TheRolesRideOutARestartOfTheServer) {
  ScratchDir dir("studio-server-restart");
  NatsServer server;
  DrapeProcess cloth("cloth-server '" + kScene + "' --takes 1" + roles(server), dir, "cloth");
  DrapeProcess anim("anim-server '" + kScene + "' --motion '" + kWalk + "' --take restart" + roles(server), dir, "anim");
  {
    studio::Bus bus = studio::Bus::connect(server.url(), "test");
    bus.ensureStream("cloth");
    for (int i = 0; i < 600 && bus.range("cloth").messages < 50; ++i) std::this_thread::sleep_for(50ms);
    ASSERT_LT(bus.range("cloth").messages, 173u) << "the take was to be under way when the server stopped";
  }
  // In the middle of the take the server goes for a second and a half and comes back on
  // its store: the roles wait, reconnect and go on where they were.
  server.stop();
  std::this_thread::sleep_for(1500ms);
  server.start();
  const CliResult sent = anim.wait();
  ASSERT_EQ(sent.code, 0) << sent.err;
  const CliResult served = cloth.wait();
  ASSERT_EQ(served.code, 0) << served.err;
  const CliResult recorded = runDrape("player '" + kScene + "' --record '" + (dir / "recorded") + "'" + roles(server), dir);
  ASSERT_EQ(recorded.code, 0) << recorded.err;
  const std::string reference = runInto(dir, "reference", "'" + kScene + "' --motion '" + kWalk + "'");
  for (const char* file : {"garment.pc2", "garment.states", "body.pc2"})
    EXPECT_TRUE(slurp(dir / ("recorded/" + std::string(file))) == slurp(reference + "/" + file)) << file;
}

TEST(Studio, TwoClothServersSplitTheGarmentsAndThePlayerCollatesThem) {
  ScratchDir dir("studio-split");
  NatsServer server;
  const std::string scene = twoSkirtScene(dir);
  const std::string reference = runInto(dir, "reference", "'" + scene + "' --motion '" + kWalk + "'");
  DrapeProcess first("cloth-server '" + scene + "' --name front --garments Skirt --takes 1" + roles(server), dir, "front");
  DrapeProcess second("cloth-server '" + scene + "' --name back --garments Skirt2 --takes 1" + roles(server), dir, "back");
  const CliResult sent = runDrape("anim-server '" + scene + "' --motion '" + kWalk + "' --fast" + roles(server), dir);
  ASSERT_EQ(sent.code, 0) << sent.err;
  for (DrapeProcess* p : {&first, &second}) {
    const CliResult r = p->wait();
    ASSERT_EQ(r.code, 0) << r.err;
  }
  // The player joins after both are done: the streams hold the take.
  const CliResult recorded = runDrape(
      "player '" + scene + "' --cloth back,front --record '" + (dir / "recorded") + "'" + roles(server), dir);
  ASSERT_EQ(recorded.code, 0) << recorded.err;
  for (const char* file : {"garment-Skirt.pc2", "garment-Skirt2.pc2", "garment-Skirt.states", "body.pc2",
                           "manifest.json", "result.wrl"})
    EXPECT_TRUE(slurp(dir / ("recorded/" + std::string(file))) == slurp(reference + "/" + file)) << file;
  const nlohmann::json stats = statsOf(dir / "recorded");
  ASSERT_TRUE(stats.contains("cloth_servers")) << stats.dump();
  // What the server holds, as drape inspect tells it.
  const CliResult held = runDrape("inspect " + server.url(), dir);
  ASSERT_EQ(held.code, 0) << held.err;
  EXPECT_NE(held.out.find(": 3 drape streams"), std::string::npos) << held.out;
  EXPECT_NE(held.out.find("  back (drape.back, stream DRAPE_back): 173 messages"), std::string::npos) << held.out;
  EXPECT_NE(held.out.find("cloth of Skirt2 (264 vertices)"), std::string::npos) << held.out;
  EXPECT_NE(held.out.find("frames 0 to 170 (-00:00:01:00 to 00:00:04:20)"), std::string::npos) << held.out;
  EXPECT_NE(held.out.find("0 vertex-substeps inside the body"), std::string::npos) << held.out;
  EXPECT_EQ(stats["cloth_servers"]["front"]["garments"][0]["name"], "Skirt");
  EXPECT_EQ(stats["cloth_servers"]["back"]["garments"][0]["name"], "Skirt2");
}


TEST(Studio, AGarmentWornOverAnotherIsSimulatedThroughTheStudioAsInDrapeRun) {
  // The skirt over its petticoat: one cloth-server steps the petticoat first each frame and
  // keeps the skirt over it, as drape run does.
  ScratchDir dir("studio-layers");
  NatsServer server;
  const std::string scene = std::string(DRAPE_SOURCE_DIR) + "/examples/layered_skirts/scene.wrl";
  const std::string reference = runInto(dir, "reference", "'" + scene + "' --motion '" + kWalk + "'");
  const StudioTake take = takeThroughTheStudio(dir, server, scene, "--motion '" + kWalk + "'");
  ASSERT_EQ(take.sent.code, 0) << take.sent.err;
  ASSERT_EQ(take.served.code, 0) << take.served.err;
  EXPECT_NE(take.served.err.find("Skirt: kept 4 mm over Petticoat"), std::string::npos) << take.served.err;
  ASSERT_EQ(take.recorded.code, 0) << take.recorded.err;
  expectSameRun(dir / "recorded", reference);
  EXPECT_GT(statsOf(dir / "recorded")["garments"][1]["worn_over"]["contacts"].get<long>(), 1000);
}

/// A character's name as its roles' streams are named: "Ada" -> "ada".
std::string streamNameOf(std::string name) {
  for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return name;
}

/// A cloth-server of one character of the two characters' scene (`which`: --character NAME,
/// or --garments of one character's), following the poses `poses`, publishing as `name`.
DrapeProcess characterCloth(const std::string& which, const std::string& poses, const std::string& name,
                            const NatsServer& server, const ScratchDir& dir) {
  return DrapeProcess("cloth-server '" + kTwoCharacters + "' " + which + " --poses " + poses + " --name " + name +
                          " --takes 1" + roles(server),
                      dir, name);
}

TEST(Studio, TwoCharactersEachOnServersOfItsOwnAreDrapeRunsToTheByte) {
  // Ada and Bea of the two characters' scene, each moved by an anim-server of her own and
  // dressed by a cloth-server of her own (Bea's told by the garments it simulates); the
  // player collates the four streams into what drape run writes of the scene.
  ScratchDir dir("studio-characters");
  NatsServer server;
  const std::string& scene = kTwoCharacters;
  const std::string reference = runInto(dir, "reference", "'" + scene + "' --frames 45");
  DrapeProcess adaCloth = characterCloth("--character Ada", "ada", "ada-cloth", server, dir);
  DrapeProcess beaCloth = characterCloth("--garments 'Bea skirt'", "bea", "bea-cloth", server, dir);
  for (const char* who : {"Ada", "Bea"}) {
    std::string name = who;
    name[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(name[0])));
    const CliResult sent = runDrape("anim-server '" + scene + "' --character " + who + " --name " + name +
                                        " --take scene1 --fast" + roles(server),
                                    dir);
    ASSERT_EQ(sent.code, 0) << sent.err;
    EXPECT_NE(sent.out.find(std::string("pose frames of ") + who), std::string::npos) << sent.out;
  }
  const CliResult ada = adaCloth.wait(), bea = beaCloth.wait();
  ASSERT_EQ(ada.code, 0) << ada.err;
  ASSERT_EQ(bea.code, 0) << bea.err;
  EXPECT_NE(bea.out.find("take scene1: 115 cloth frames of Bea skirt"), std::string::npos) << bea.out;
  const CliResult recorded = runDrape("player '" + scene + "' --cloth ada-cloth,bea-cloth --frames 45 --record '" +
                                          (dir / "recorded") + "'" + roles(server),
                                      dir);
  ASSERT_EQ(recorded.code, 0) << recorded.err;
  for (const char* file :
       {"garment-Ada_skirt.pc2", "garment-Bea_skirt.pc2", "garment-Bea_skirt.states", "body-Ada.pc2", "body-Bea.pc2",
        "segments/Ada/Hips.pc2", "segments/Bea/LeftUpLeg.pc2", "manifest.json"})
    EXPECT_TRUE(slurp(dir / ("recorded/" + std::string(file))) == slurp(reference + "/" + file)) << file;

  // A cloth-server given another character's poses says so.
  const CliResult wrong =
      runDrape("cloth-server '" + scene + "' --character Ada --poses bea --name wrong --takes 1" + roles(server), dir);
  EXPECT_EQ(wrong.code, 2) << wrong.err;
  EXPECT_NE(wrong.err.find("pose take scene1 of 'bea' moves Bea, and this cloth-server simulates Ada's garments: give it "
                           "the --poses of Ada's anim-server"),
            std::string::npos)
      << wrong.err;
  const CliResult which = runDrape("cloth-server '" + scene + "' --name which --takes 1" + roles(server), dir);
  EXPECT_EQ(which.code, 2) << which.err;
  EXPECT_NE(which.err.find("the scene has 2 characters (Ada, Bea), and a studio role plays one: give --character NAME"),
            std::string::npos)
      << which.err;
}

TEST(Studio, CharactersThatTouchCollideThroughTheStudioAsInDrapeRun) {
  // Ada and Bea set off side by side, close, each on her own walk (Ada's 170 frames long,
  // Bea's 115): each cloth-server follows the other character's poses too (--guest), so
  // that each skirt collides with the other's legs, and each take runs as long as the
  // longest walk, Bea standing at her last pose after hers, as in drape run.
  ScratchDir dir("studio-touch");
  NatsServer server;
  // Bea 35 cm to Ada's side: walking side by side, each skirt brushes the other's legs.
  const std::string scene = twoCharactersWithBeaAt(dir, "0.35 0 0");
  const std::string reference = runInto(dir, "reference", "'" + scene + "'");
  EXPECT_EQ(statsOf(reference)["frames"].get<int>(), 170);
  // Ada's skirt alone, on the same walk: the skirts' runs must differ where they touch.
  const std::string alone = runInto(dir, "alone", "'" + kScene + "' --motion '" + kWalk + "' --frames 170");
  ASSERT_TRUE(slurp(alone + "/garment.pc2") != slurp(reference + "/garment-Ada_skirt.pc2"))
      << "the skirts were to touch the other's legs";

  const auto cloth = [&](const std::string& who, const std::string& guest) {
    return DrapeProcess("cloth-server '" + scene + "' --character " + who + " --poses " + streamNameOf(who) + " --guest " +
                            guest + "=" + streamNameOf(guest) + " --name " + streamNameOf(who) + "-cloth --takes 1" + roles(server),
                        dir, streamNameOf(who) + "-cloth");
  };
  DrapeProcess adaCloth = cloth("Ada", "Bea"), beaCloth = cloth("Bea", "Ada");
  for (const std::string who : {"Ada", "Bea"}) {
    const CliResult sent = runDrape("anim-server '" + scene + "' --character " + who + " --name " + streamNameOf(who) +
                                        " --take close --fast" + roles(server),
                                    dir);
    ASSERT_EQ(sent.code, 0) << sent.err;
  }
  const CliResult ada = adaCloth.wait(), bea = beaCloth.wait();
  ASSERT_EQ(ada.code, 0) << ada.err;
  ASSERT_EQ(bea.code, 0) << bea.err;
  EXPECT_NE(ada.err.find("its garments collide with Bea's body too, as the poses of 'bea' move it"), std::string::npos)
      << ada.err;
  EXPECT_NE(bea.out.find("take close: 170 cloth frames of Bea skirt"), std::string::npos) << bea.out;
  const CliResult recorded = runDrape("player '" + scene + "' --cloth ada-cloth,bea-cloth --record '" +
                                          (dir / "recorded") + "'" + roles(server),
                                      dir);
  ASSERT_EQ(recorded.code, 0) << recorded.err;
  EXPECT_NE(recorded.out.find("recorded take close: 171 frames of Ada, Bea in"), std::string::npos) << recorded.out;
  for (const char* file : {"garment-Ada_skirt.pc2", "garment-Bea_skirt.pc2", "garment-Ada_skirt.states", "body-Bea.pc2"})
    EXPECT_TRUE(slurp(dir / ("recorded/" + std::string(file))) == slurp(reference + "/" + file)) << file;

  // Refused: a guest the scene lacks, the character dressed, a guest twice.
  for (const auto& [guests, message] : std::vector<std::pair<std::string, std::string>>{
           {"--guest Carl=carl", "--guest Carl=carl: the scene has no character called 'Carl' (it has: Ada, Bea)"},
           {"--guest Ada=bea", "--guest Ada=bea: Ada is the character this cloth-server dresses"},
           {"--guest Bea=bea --guest Bea=bea2", "--guest Bea=bea2: Bea is a guest twice"},
           {"--guest Bea", "--guest Bea: expected NAME=POSES"}}) {
    const CliResult refused = runDrape(
        "cloth-server '" + scene + "' --character Ada --poses ada " + guests + " --takes 1" + roles(server), dir);
    EXPECT_EQ(refused.code, 2) << refused.err;
    EXPECT_NE(refused.err.find(message), std::string::npos) << refused.err;
  }
}

TEST(Studio, AnEventGraphOfTwoCharactersThroughTheStudioIsDrapeRunsToTheByte) {
  // The bundled duet (Ada walks; Bea waits, walks after her and kicks): each anim-server runs
  // the whole graph, so that Bea's wait takes the time it takes in drape run, and sends its
  // character's poses.
  ScratchDir dir("studio-duet");
  NatsServer server;
  const std::string& scene = kTwoCharacters;
  const std::string duet = std::string(DRAPE_SOURCE_DIR) + "/examples/event_graph/duet.egml";
  const std::string reference = runInto(dir, "reference", "'" + scene + "' --events '" + duet + "'");
  DrapeProcess adaCloth = characterCloth("--character Ada", "ada", "ada-cloth", server, dir);
  DrapeProcess beaCloth = characterCloth("--character Bea", "bea", "bea-cloth", server, dir);
  for (const std::string who : {"Ada", "Bea"}) {
    const CliResult sent = runDrape("anim-server '" + scene + "' --character " + who + " --events '" + duet +
                                        "' --name " + (who == "Ada" ? "ada" : "bea") + " --take duet --fast" +
                                        roles(server),
                                    dir);
    ASSERT_EQ(sent.code, 0) << sent.err;
    EXPECT_NE(sent.out.find("sent take duet: 169 pose frames of " + who + "'s event graph"), std::string::npos)
        << sent.out;
  }
  ASSERT_EQ(adaCloth.wait().code, 0);
  ASSERT_EQ(beaCloth.wait().code, 0);
  const CliResult recorded = runDrape(
      "player '" + scene + "' --cloth ada-cloth,bea-cloth --record '" + (dir / "recorded") + "'" + roles(server), dir);
  ASSERT_EQ(recorded.code, 0) << recorded.err;
  for (const char* file : {"garment-Ada_skirt.pc2", "garment-Bea_skirt.pc2", "body-Ada.pc2", "body-Bea.pc2",
                           "segments/Ada/Hips.pc2", "segments/Bea/LeftFoot.pc2", "manifest.json"})
    EXPECT_TRUE(slurp(dir / ("recorded/" + std::string(file))) == slurp(reference + "/" + file)) << file;
}

TEST(Studio, AnUnstableTakeIsRecordedUpToItsLastGoodFrame) {
  ScratchDir dir("studio-unstable");
  NatsServer server;
  // Four substeps a frame: far beyond the skirt's stable step; frame 2 goes unstable.
  std::string text = slurp(kScene);
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
           {"stepsPerFrame 33", "stepsPerFrame 4"},
           {"bendEvery 8", "bendEvery 1"},
           {"url \"../../data/", "url \"" + std::string(DRAPE_DATA_DIR) + "/"}})
    text.replace(text.find(from), from.size(), to);
  const std::string scene = dir / "unstable.wrl";
  std::ofstream(scene) << text;
  const StudioTake take = takeThroughTheStudio(dir, server, scene, "--motion '" + kWalk + "'");
  ASSERT_EQ(take.sent.code, 0) << take.sent.err;
  EXPECT_EQ(take.served.code, 3) << take.served.err;
  EXPECT_EQ(take.recorded.code, 3) << take.recorded.err;
  EXPECT_NE(take.recorded.err.find("garment 'Skirt': vertex"), std::string::npos) << take.recorded.err;
  EXPECT_NE(take.recorded.err.find("the 2 frames before it recorded in"), std::string::npos) << take.recorded.err;
  EXPECT_EQ(formats::readPc2(dir / "recorded/garment.pc2").frames.size(), 2u);
  EXPECT_TRUE(statsOf(dir / "recorded")["unstable"].get<bool>());
}

/// Whether windows can be tested: a virtual display, under xvfb-run.
bool haveXvfb() { return std::system("command -v xvfb-run >/dev/null 2>&1") == 0; }
constexpr const char* kNoXvfb = "xvfb-run is not installed (scripts/install-deps installs xvfb)";

/// `drape player ARGS --window` under a virtual display: exit status and what it said.
std::pair<int, std::string> showInWindow(const std::string& args, const NatsServer& server, const ScratchDir& dir,
                                         const std::string& name) {
  const std::string cmd = std::string("ASAN_OPTIONS=detect_leaks=0 xvfb-run -a '") + DRAPE_EXE + "' player '" + kScene +
                          "' --window --size 320x240 " + args + roles(server) + " >'" + (dir / (name + ".txt")) + "' 2>&1";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(dir / (name + ".txt"))};
}

/// The time code a player said it showed the take from.
TimeCode shownFrom(const std::string& said) {
  const std::size_t at = said.find(" from ", said.find("showed "));
  if (at == std::string::npos) return {};
  return TimeCode::parseSmpte(said.substr(at + 6, said.find(' ', at + 6) - at - 6), 30.0);
}

TEST(Studio, ThePlayerShowsATakeLiveInAWindowAndFromATimeCode) {
  if (!haveXvfb()) GTEST_SKIP() << kNoXvfb;
  ScratchDir dir("studio-window");
  NatsServer server;
  DrapeProcess cloth("cloth-server '" + kScene + "' --takes 1" + roles(server), dir, "cloth");
  DrapeProcess anim("anim-server '" + kScene + "' --motion '" + kWalk + "'" + roles(server), dir, "anim");
  const std::string shot = dir / "live.png";
  const auto [status, out] = showInWindow("--frames 8 --screenshot '" + shot + "'", server, dir, "player");
  ASSERT_EQ(status, 0) << out;
  EXPECT_NE(out.find("showed 8 frames of take"), std::string::npos) << out;
  EXPECT_GT(fs::file_size(shot), 1000u);
  EXPECT_EQ(anim.wait().code, 0);
  EXPECT_EQ(cloth.wait().code, 0);

  // The whole take is in the stream now: a player starts where it is told.
  const TimeCode start = shownFrom(out);
  studio::Bus bus = studio::Bus::connect(server.url(), "test");
  const studio::StreamRange range = bus.range("cloth");
  std::int64_t last = -1;
  for (std::uint64_t s = range.last; s >= range.first && last < 0; --s)
    if (const auto m = bus.get("cloth", s))
      if (const studio::Message msg = studio::decode(m->data); std::holds_alternative<studio::End>(msg.payload))
        last = std::get<studio::End>(msg.payload).frames;
  ASSERT_GT(last, 40);
  const TimeCode at{start.frame + 37, start.rate};
  const auto [atStatus, atOut] = showInWindow("--frames 3 --from " + at.smpte(), server, dir, "at");
  ASSERT_EQ(atStatus, 0) << atOut;
  EXPECT_NE(atOut.find("showed 3 frames of take"), std::string::npos) << atOut;
  EXPECT_EQ(shownFrom(atOut).frame, at.frame) << atOut;
  EXPECT_NE(atOut.find("(frame 37 of take"), std::string::npos) << atOut;

  // "now" on a take that has ended: its last frame, and the window closes after it.
  const auto [nowStatus, nowOut] = showInWindow("--frames 5 --from now", server, dir, "now");
  ASSERT_EQ(nowStatus, 0) << nowOut;
  EXPECT_NE(nowOut.find("showed 1 frame of take"), std::string::npos) << nowOut;
  EXPECT_EQ(shownFrom(nowOut).frame, start.frame + last) << nowOut;

  const TimeCode before{start.frame - 1, start.rate}, after{start.frame + last + 1, start.rate};
  const auto [beforeStatus, beforeOut] = showInWindow("--from " + before.smpte(), server, dir, "before");
  EXPECT_EQ(beforeStatus, 2) << beforeOut;
  EXPECT_NE(beforeOut.find("starts at " + start.smpte()), std::string::npos) << beforeOut;
  const auto [afterStatus, afterOut] = showInWindow("--from " + after.smpte(), server, dir, "after");
  EXPECT_EQ(afterStatus, 2) << afterOut;
  EXPECT_NE(afterOut.find(fmt::format("ends at {} (frame {})", TimeCode{start.frame + last, 30.0}.smpte(), last)),
            std::string::npos)
      << afterOut;
  const auto [badStatus, badOut] = showInWindow("--from 00:00:01", server, dir, "bad");
  EXPECT_EQ(badStatus, 2) << badOut;
  EXPECT_NE(badOut.find("expected HH:MM:SS:FF"), std::string::npos) << badOut;
}

/// Waits (up to two minutes) for `process` to say `what` on standard output or error.
bool said(const DrapeProcess& process, const std::string& what) {
  for (int i = 0; i < 2400; ++i) {
    if (process.outSoFar().find(what) != std::string::npos || process.errSoFar().find(what) != std::string::npos)
      return true;
    std::this_thread::sleep_for(50ms);
  }
  return false;
}

TEST(Studio, ARecorderRecordsTakeAfterTakeEachUnderItsNameUntilStopped) {
  ScratchDir dir("studio-takes");
  NatsServer server;
  const std::string reference = runInto(dir, "reference", "'" + kScene + "' --motion '" + kWalk + "'");
  DrapeProcess player("player '" + kScene + "' --record '" + (dir / "takes") + "' --takes 0" + roles(server), dir,
                      "player");
  DrapeProcess cloth("cloth-server '" + kScene + "'" + roles(server), dir, "cloth");
  const std::string motion = "anim-server '" + kScene + "' --motion '" + kWalk + "'";
  // Each take once the recorder has the last: a stream holds one take, the newest.
  ASSERT_EQ(runDrape(motion + " --fast --take monday-1" + roles(server), dir).code, 0);
  ASSERT_TRUE(said(player, "recorded take monday-1: 171 frames")) << player.errSoFar();
  ASSERT_EQ(runDrape(motion + " --fast --take 'scene 12/take 3'" + roles(server), dir).code, 0);
  ASSERT_TRUE(said(player, "recorded take scene 12/take 3: 171 frames")) << player.errSoFar();

  // A take cut short: its anim-server stops in the middle (killed) and another take comes.
  {
    DrapeProcess cut(motion + " --take cut" + roles(server), dir, "cut");
    studio::Bus bus = studio::Bus::connect(server.url(), "test");
    const auto clothOfCut = [&] {
      const studio::StreamRange range = bus.range("cloth");
      const auto first = range.messages > 0 ? bus.get("cloth", range.first) : std::nullopt;
      return first && studio::decode(first->data).take == "cut" ? range.messages : 0;
    };
    for (int i = 0; i < 2400 && clothOfCut() < 40; ++i) std::this_thread::sleep_for(50ms);
    ASSERT_GE(clothOfCut(), 40u);
    (void)cut.kill();
  }
  ASSERT_EQ(runDrape(motion + " --fast --take after-the-cut" + roles(server), dir).code, 0);
  ASSERT_TRUE(said(player, "recorded take after-the-cut: 171 frames")) << player.errSoFar();

  // Ctrl-C: the recorder stops where it waits.
  player.signal(SIGINT);
  const CliResult stopped = player.wait();
  EXPECT_EQ(stopped.code, 0) << stopped.err;
  EXPECT_NE(stopped.out.find("stopped (a signal) waiting for a take; 4 recorded"), std::string::npos) << stopped.out;
  EXPECT_NE((stopped.out + stopped.err).find("started take after-the-cut before take cut ended"), std::string::npos)
      << stopped.out << stopped.err;
  expectSameRun(dir / "takes/monday-1", reference);
  expectSameRun(dir / "takes/after-the-cut", reference);
  for (const char* file : {"garment.pc2", "garment.states", "body.pc2"})
    EXPECT_TRUE(slurp(dir / ("takes/scene_12_take_3/" + std::string(file))) == slurp(reference + "/" + file)) << file;
  const std::size_t cutFrames = formats::readPc2(dir / "takes/cut/garment.pc2").frames.size();
  EXPECT_GE(cutFrames, 1u);
  EXPECT_LT(cutFrames, 171u);
}

TEST(Studio, AWindowMovesOnToTheNextTake) {
  if (!haveXvfb()) GTEST_SKIP() << kNoXvfb;
  ScratchDir dir("studio-window-takes");
  NatsServer server;
  DrapeProcess cloth("cloth-server '" + kScene + "'" + roles(server), dir, "cloth");
  // Every frame of the first take and 29 of the second, then it closes.
  DrapeProcess window("player '" + kScene + "' --window --size 320x240 --takes 2 --every-frame --frames 200" +
                          roles(server),
                      dir, "window", "xvfb-run -a");
  const std::string motion = "anim-server '" + kScene + "' --motion '" + kWalk + "' --fast";
  ASSERT_EQ(runDrape(motion + " --take first" + roles(server), dir).code, 0);
  ASSERT_TRUE(said(window, "take first: its 171 frames read; waiting for the next take")) << window.errSoFar();
  ASSERT_EQ(runDrape(motion + " --take second" + roles(server), dir).code, 0);
  const CliResult shown = window.wait();
  ASSERT_EQ(shown.code, 0) << shown.err;
  EXPECT_NE(shown.out.find("showed 171 frames of take first from -00:00:01:00"), std::string::npos) << shown.out;
  EXPECT_NE(shown.out.find("showed 29 frames of take second from -00:00:01:00"), std::string::npos) << shown.out;
}

TEST(Studio, AnEventGraphThroughTheStudioIsDrapeRunsToTheByte) {
  // The bundled day (walk, kick, walk on, a gust) played live by the anim-server: the
  // cloth-server blows the gust its pose frames carry, and the recording is drape run
  // --events of the same graph.
  ScratchDir dir("studio-events");
  NatsServer server;
  const std::string day = std::string(DRAPE_SOURCE_DIR) + "/examples/event_graph/day.egml";
  const std::string reference = runInto(dir, "reference", "'" + kScene + "' --events '" + day + "'");
  const StudioTake take = takeThroughTheStudio(dir, server, kScene, "--events '" + day + "'");
  ASSERT_EQ(take.sent.code, 0) << take.sent.err;
  EXPECT_NE(take.sent.out.find("223 pose frames"), std::string::npos) << take.sent.out;
  ASSERT_EQ(take.served.code, 0) << take.served.err;
  ASSERT_EQ(take.recorded.code, 0) << take.recorded.err;
  for (const char* file : {"garment.pc2", "garment.states", "body.pc2", "segments/Hips.pc2"})
    EXPECT_TRUE(slurp(dir / ("recorded/" + std::string(file))) == slurp(reference + "/" + file)) << file;
}

/// The skirt's scene with its forearms kept apart from the parts it collides with (the
/// scene's Simulation keepApart, which every role reads), written into `dir`.
std::string keptApartScene(const ScratchDir& dir) {
  std::string text = slurp(kScene);
  const std::string relative = "url \"../../data/", simulation = "DEF Simulation Simulation {";
  const std::size_t url = text.find(relative), settings = text.find(simulation);
  EXPECT_NE(url, std::string::npos);
  EXPECT_NE(settings, std::string::npos);
  text.replace(url, relative.size(), "url \"" + std::string(DRAPE_SOURCE_DIR) + "/data/");
  text.insert(text.find(simulation) + simulation.size(), "\n  keepApart [ \"LeftForeArm\" \"RightForeArm\" ]");
  const std::string path = dir / "kept_apart.wrl";
  std::ofstream(path) << text;
  return path;
}

TEST(Studio, AMotionKeptApartIsCorrectedAsItComesAsDrapeRunCorrectsItWhole) {
  // drape run corrects a whole motion before it simulates; the anim-server corrects an event
  // graph's frames as the graph makes them, each once the smoothing's 15 frames after it have
  // come: the recorded take is drape run's, to the byte.
  ScratchDir dir("studio-kept-apart");
  NatsServer server;
  const std::string scene = keptApartScene(dir);
  const std::string day = std::string(DRAPE_SOURCE_DIR) + "/examples/event_graph/day.egml";
  const std::string reference = runInto(dir, "reference", "'" + scene + "' --events '" + day + "'");
  const nlohmann::json kept = statsOf(reference)["keep_apart"];
  ASSERT_GT(kept.value("frames_changed", 0), 0) << kept.dump();
  const StudioTake take = takeThroughTheStudio(dir, server, scene, "--events '" + day + "'");
  const CliResult& sent = take.sent;
  ASSERT_EQ(sent.code, 0) << sent.err;
  EXPECT_NE(sent.out.find("223 pose frames"), std::string::npos) << sent.out;
  EXPECT_NE(sent.err.find("each frame corrected 15 frames (0.50 s) after it comes"), std::string::npos) << sent.err;
  EXPECT_NE(sent.err.find(fmt::format("the motion corrected in {} frames", kept["frames_changed"].get<long>())),
            std::string::npos)
      << sent.err;
  ASSERT_EQ(take.served.code, 0) << take.served.err;
  ASSERT_EQ(take.recorded.code, 0) << take.recorded.err;
  for (const char* file : {"garment.pc2", "body.pc2", "segments/LeftForeArm.pc2", "segments/RightForeArm.pc2"})
    EXPECT_TRUE(slurp(dir / ("recorded/" + std::string(file))) == slurp(reference + "/" + file)) << file;

  // A capture kept apart as it comes (drape run --live) and its file kept apart whole: the
  // live motion is grounded over trailing windows, so the bodies stand at other heights by a
  // centimetre at most, but the same frames are corrected by the same turns.
  const std::string live = runInto(dir, "live", "'" + scene + "' --live - < '" + kWalk + "'");
  const std::string file = runInto(dir, "file", "'" + scene + "' --motion '" + kWalk + "'");
  const nlohmann::json a = statsOf(live)["keep_apart"], b = statsOf(file)["keep_apart"];
  ASSERT_GT(b.value("frames_changed", 0), 0) << b.dump();
  EXPECT_EQ(a["frames_changed"], b["frames_changed"]);
  EXPECT_NEAR(a["largest_turn_deg"].get<double>(), b["largest_turn_deg"].get<double>(), 1e-6);
  ASSERT_EQ(a["pairs"].size(), b["pairs"].size());
  for (std::size_t i = 0; i < a["pairs"].size(); ++i) {
    EXPECT_EQ(a["pairs"][i]["part"], b["pairs"][i]["part"]);
    EXPECT_EQ(a["pairs"][i]["frames"], b["pairs"][i]["frames"]);
  }
  EXPECT_EQ(statsOf(live)["vertex_substeps_inside_body"], 0);
  EXPECT_EQ(statsOf(live)["frames"], statsOf(file)["frames"]);
}

TEST(Studio, ALiveEventGraphTakesEventsAndGraphsInjected) {
  ScratchDir dir("studio-inject");
  NatsServer server;
  const std::string idle = dir / "idle.egml";
  std::ofstream(idle) << "#VRML V2.0 utf8\n"
                         "StateMachine { states [\n"
                         "  State { name \"Stand\" children [ Loop { children [ Wait { duration 1 } ] } ] on [ \"walk\" ] "
                         "to [ \"Walk\" ] }\n"
                         "  State { name \"Walk\" children [ Play { motion \"" + kWalk + "\" to 1.5 blend 0 } ] next \"Stand\" }\n"
                         "] }\n";
  DrapeProcess anim("anim-server '" + kScene + "' --events '" + idle + "' --hold --frames 150" + roles(server), dir,
                    "anim");
  // The anim-server listens once its take has begun.
  studio::Bus bus = studio::Bus::connect(server.url(), "test");
  bus.ensureStream("anim");
  for (int i = 0; i < 600 && bus.range("anim").messages < 20; ++i) std::this_thread::sleep_for(50ms);
  CliResult r = runDrape("inject --event walk" + roles(server), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("sent event 'walk' at frame "), std::string::npos) << r.out;
  const long at = std::stol(r.out.substr(r.out.find("at frame ") + 9));
  const std::string broken = dir / "broken.egml";
  std::ofstream(broken) << "#VRML V2.0 utf8\nPlay { from -1 motion \"" + kWalk + "\" }\n";
  r = runDrape("inject --graph '" + broken + "'" + roles(server), dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(broken + ":2: Play: from -1 must be >= 0 s"), std::string::npos) << r.err;
  r = runDrape("inject --to nobody --event walk" + roles(server), dir);
  EXPECT_EQ(r.code, 4);
  EXPECT_NE(r.err.find("nobody listens on drape.nobody.inject (is 'drape anim-server --name nobody --events FILE.egml' "
                       "running on it?)"),
            std::string::npos)
      << r.err;
  const CliResult sent = anim.wait();
  ASSERT_EQ(sent.code, 0) << sent.err;
  EXPECT_NE(sent.out.find("150 pose frames"), std::string::npos) << sent.out;

  // The poses: at rest up to the event, walking from it on.
  studio::Bus reader = studio::Bus::connect(server.url(), "test");
  const studio::StreamRange range = reader.range("anim");
  std::vector<Vec3> hips;
  for (std::uint64_t seq = range.first; seq <= range.last; ++seq) {
    const studio::Message m = studio::decode(reader.get("anim", seq)->data);
    if (const auto* p = std::get_if<studio::PoseFrame>(&m.payload)) hips.push_back(p->joints[0].translation);
  }
  ASSERT_EQ(hips.size(), 150u);
  ASSERT_GT(at, 5);
  ASSERT_LT(at + 30, 150);
  for (long f = 1; f < at; ++f) EXPECT_EQ(hips[static_cast<std::size_t>(f)], hips[0]) << "frame " << f << ": before the event";
  EXPECT_GT((hips[static_cast<std::size_t>(at + 30)] - hips[0]).norm(), 0.3) << "the walk did not move the hips";
}

/// A capture program's broadcast: a TCP server on a free loopback port that sends `text` to
/// the first client, `perBatch` lines at a time with `pause` between, after `before` has
/// returned true for the line about to go (a test's way to hold the source at a point).
class CaptureBroadcast {
 public:
  CaptureBroadcast() {
    listener_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(listener_, reinterpret_cast<sockaddr*>(&address), sizeof address);
    socklen_t length = sizeof address;
    ::getsockname(listener_, reinterpret_cast<sockaddr*>(&address), &length);
    ::listen(listener_, 1);
    url_ = "tcp://127.0.0.1:" + std::to_string(ntohs(address.sin_port));
  }
  ~CaptureBroadcast() {
    {
      const std::lock_guard lock(mutex_);
      done_ = true;
    }
    woken_.notify_all();  // a pause ends at once: a long silence costs the test nothing
    ::shutdown(listener_, SHUT_RDWR);  // and so does an accept nobody came to
    if (thread_.joinable()) thread_.join();
    ::close(listener_);
  }
  [[nodiscard]] const std::string& url() const { return url_; }

  void send(std::vector<std::string> lines, std::size_t perBatch, std::chrono::milliseconds pause,
            std::function<void(std::size_t)> before = {}) {
    thread_ = std::thread([this, lines = std::move(lines), perBatch, pause, before = std::move(before)] {
      const int peer = ::accept(listener_, nullptr, nullptr);
      if (peer < 0) return;
      for (std::size_t i = 0; i < lines.size(); i += perBatch) {
        if (before) before(i);
        std::string batch;
        for (std::size_t k = i; k < std::min(lines.size(), i + perBatch); ++k) batch += lines[k] + "\n";
        for (std::size_t done = 0; done < batch.size();) {
          const ssize_t n = ::send(peer, batch.data() + done, batch.size() - done, MSG_NOSIGNAL);
          if (n <= 0) break;
          done += static_cast<std::size_t>(n);
        }
        std::unique_lock lock(mutex_);
        if (woken_.wait_for(lock, pause, [this] { return done_; })) break;
      }
      ::close(peer);
    });
  }

 private:
  int listener_ = -1;
  std::string url_;
  std::mutex mutex_;
  std::condition_variable woken_;
  bool done_ = false;
  std::thread thread_;
};

std::vector<std::string> linesOf(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(Studio, ALiveCaptureOverTcpIsSimulatedAsItComes) {
  // The walk's BVH broadcast as a capture program sends it, 40 lines at a time, one of its
  // frame lines garbled: the anim-server sends poses while the capture goes on (the source
  // is held at its middle until the pose stream shows it), a cloth-server simulates them, a
  // player records the take.
  ScratchDir dir("studio-live");
  NatsServer server;
  std::vector<std::string> lines = linesOf(slurp(kWalk));
  ASSERT_EQ(lines.size(), 187u + 566u) << "the walk's header and frames";
  lines[187 + 300] = "0 0 oops";  // file line 488
  studio::Bus bus = studio::Bus::connect(server.url(), "test");
  bus.ensureStream("anim");
  std::atomic<std::uint64_t> posesAtMiddle{0};
  CaptureBroadcast capture;
  capture.send(lines, 40, 5ms, [&](std::size_t line) {
    if (line < 187 + 280 || posesAtMiddle > 0) return;
    // 280 of the 566 frames sent: at 120 Hz resampled to 30, 69 pose frames are due.
    for (int i = 0; i < 400 && bus.range("anim").messages < 60; ++i) std::this_thread::sleep_for(50ms);
    posesAtMiddle = bus.range("anim").messages;
  });
  DrapeProcess cloth("cloth-server '" + kScene + "' --takes 1" + roles(server), dir, "cloth");
  const CliResult sent = runDrape("anim-server '" + kScene + "' --live " + capture.url() + " --take live" + roles(server), dir);
  ASSERT_EQ(sent.code, 0) << sent.err;
  EXPECT_GE(posesAtMiddle.load(), 60u) << "the poses were to go out while the capture was still sending";
  EXPECT_NE(sent.out.find("sent take live: 141 pose frames of makehuman_CMU compliant skeleton from " + capture.url() +
                          " (566 source frames, 1 bad line)"),
            std::string::npos)
      << sent.out;
  EXPECT_NE(sent.err.find(capture.url() + ":488:5: expected a number, found 'oops' (the frame before it stands in)"),
            std::string::npos)
      << sent.err;
  EXPECT_NE(sent.err.find("joint map 'motionbuilder'"), std::string::npos) << sent.err;
  const CliResult served = cloth.wait();
  ASSERT_EQ(served.code, 0) << served.err;
  EXPECT_NE(served.out.find("take live: 170 cloth frames of Skirt"), std::string::npos) << served.out;
  const CliResult recorded = runDrape("player '" + kScene + "' --record '" + (dir / "recorded") + "'" + roles(server), dir);
  ASSERT_EQ(recorded.code, 0) << recorded.err;
  const nlohmann::json stats = statsOf(dir / "recorded");
  EXPECT_EQ(stats["frames"], 170);
  EXPECT_EQ(stats["vertex_substeps_inside_body"], 0);

  // The same broadcast into drape run --live, in one process: the studio's take, to the byte.
  CaptureBroadcast again;
  again.send(lines, 40, 1ms);
  const CliResult alone = runDrape("run '" + kScene + "' --live " + again.url() + " --out '" + (dir / "alone") + "'", dir);
  ASSERT_EQ(alone.code, 0) << alone.err;
  EXPECT_NE(alone.out.find("live: 141 motion frames from " + again.url() + " (566 source frames, 1 bad line)"),
            std::string::npos)
      << alone.out;
  expectSameRun(dir / "alone", dir / "recorded");
}

TEST(Studio, ALiveRunEndsWithItsSourceAndSaysWhy) {
  ScratchDir dir("live-run");
  // Piped in: the whole walk, then the pipe closes; --frames ends a run before its source does.
  const CliResult piped =
      runDrape("run '" + kScene + "' --live - --frames 40 --out '" + (dir / "piped") + "' < '" + kWalk + "'", dir);
  ASSERT_EQ(piped.code, 0) << piped.err;
  EXPECT_EQ(statsOf(dir / "piped")["frames"], 40);
  // The header and a second of frames, then silence: --give-up ends the run, which keeps what came.
  std::vector<std::string> lines = linesOf(slurp(kWalk));
  lines.resize(187 + 120);
  CaptureBroadcast silent;
  silent.send(lines, lines.size(), 60000ms);
  const CliResult quiet = runDrape(
      "run '" + kScene + "' --live " + silent.url() + " --give-up 1 --out '" + (dir / "quiet") + "'", dir);
  EXPECT_EQ(quiet.code, 4) << quiet.err;
  EXPECT_NE(quiet.out.find("went silent for 1 s (--give-up)"), std::string::npos) << quiet.out;
  // 120 frames at 120 Hz: 30 at 30 Hz, after the lead-in's 30.
  EXPECT_EQ(statsOf(dir / "quiet")["frames"], 59);
  EXPECT_EQ(statsOf(dir / "quiet")["vertex_substeps_inside_body"], 0);

  CliResult r = runDrape("run '" + kScene + "' --live - --motion '" + kWalk + "' --out '" + (dir / "x") + "'", dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("--live plays the motion its source sends: give it or --motion, not both"), std::string::npos)
      << r.err;
  r = runDrape("run '" + kScene + "' --give-up 3 --out '" + (dir / "x") + "'", dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("--give-up is for a live source: give --live SOURCE"), std::string::npos) << r.err;
  r = runDrape("run '" + kScene + "' --live - --out '" + (dir / "x") + "' < /dev/null", dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("stdin:1:1"), std::string::npos) << r.err;
}

TEST(Studio, ALiveCaptureIsShownInAWindowThatStaysLiveWhileItsSourceIsSilent) {
  // drape play SCENE --live: the header and a second of frames, then a long silence; the
  // window shows the frames that came, goes on drawing while the simulation waits for more,
  // and closes on Ctrl-C (which must reach the simulating thread's wait, or it would hang).
  if (!haveXvfb()) GTEST_SKIP() << kNoXvfb;
  ScratchDir dir("live-window");
  std::vector<std::string> lines = linesOf(slurp(kWalk));
  lines.resize(187 + 120);
  CaptureBroadcast capture;
  capture.send(lines, lines.size(), 60000ms);
  const std::string shot = dir / "live.png";
  DrapeProcess play("play '" + kScene + "' --live " + capture.url() + " --size 320x240 --screenshot '" + shot + "'", dir,
                    "play", "xvfb-run -a");
  ASSERT_TRUE(said(play, "waiting for motion frames from " + capture.url())) << play.errSoFar();
  // Ctrl-C to drape itself, not to xvfb-run: the one process whose command line starts with
  // it. The space after "play" keeps a `drape player` another test runs meanwhile out of it.
  std::string pattern = "^";
  for (const char c : std::string(DRAPE_EXE) + " play ")
    pattern += std::isalnum(static_cast<unsigned char>(c)) || c == ' ' || c == '/' ? std::string(1, c) : std::string("\\") + c;
  ASSERT_EQ(std::system(("pkill -INT -f '" + pattern + "'").c_str()), 0);
  const CliResult shown = play.wait();
  // 120 frames at 120 Hz: 30 at 30 Hz after the lead-in's 30, each shown but the last, whose
  // substeps wait for a motion frame after the 30th while the source is silent.
  EXPECT_NE(shown.out.find("simulated and showed 59 frames in "), std::string::npos) << shown.out << shown.err;
  EXPECT_NE(shown.out.find("of the live motion from " + capture.url()), std::string::npos) << shown.out;
  EXPECT_GT(fs::file_size(shot), 1000u);
}

TEST(Studio, ALiveSourceThatIsNotThereOrFallsSilentEndsTheTakeSaying) {
  ScratchDir dir("studio-live-errors");
  NatsServer server;
  std::string closedPort;
  {
    const CaptureBroadcast gone;
    closedPort = gone.url();
  }
  CliResult r = runDrape("anim-server '" + kScene + "' --live " + closedPort + " --server " + server.url() + " --give-up 1", dir);
  EXPECT_EQ(r.code, 4) << r.err;
  EXPECT_NE(r.err.find(closedPort + ": cannot connect (Connection refused); gave up after"), std::string::npos) << r.err;

  // The header, three frames, then silence: the take ends after --give-up, its End saying why.
  std::vector<std::string> lines = linesOf(slurp(kWalk));
  lines.resize(187 + 12);
  CaptureBroadcast silent;
  silent.send(lines, lines.size(), 60000ms);
  r = runDrape("anim-server '" + kScene + "' --live " + silent.url() + " --take quiet --server " + server.url() +
                   " --give-up 1",
               dir);
  EXPECT_EQ(r.code, 4) << r.err;
  EXPECT_NE(r.out.find("went silent for 1 s (--give-up)"), std::string::npos) << r.out;
  studio::Bus bus = studio::Bus::connect(server.url(), "test");
  const studio::StreamRange range = bus.range("anim");
  const studio::Message last = studio::decode(bus.get("anim", range.last)->data);
  const auto* end = std::get_if<studio::End>(&last.payload);
  ASSERT_NE(end, nullptr);
  EXPECT_EQ(end->exitCode, 4);
  EXPECT_NE(end->error.find("went silent"), std::string::npos) << end->error;

  // Not a BVH: the header's error where it is.
  CaptureBroadcast junk;
  junk.send({"HIERARCHY", "ROOT Hips", "{", "OFFSET 0 0"}, 4, 10ms);
  r = runDrape("anim-server '" + kScene + "' --live " + junk.url() + " --server " + server.url() + " --give-up 5", dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find(junk.url() + ":5:1: expected a number, found end of file"), std::string::npos) << r.err;
  // The take 'quiet' is in the stream: a live capture cannot complete it.
  CaptureBroadcast again;
  again.send(lines, lines.size(), 10ms);
  r = runDrape("anim-server '" + kScene + "' --live " + again.url() + " --take quiet --server " + server.url(), dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("--take quiet: drape.anim holds that take already"), std::string::npos) << r.err;
  r = runDrape("anim-server '" + kScene + "' --live - --motion '" + kWalk + "' --server " + server.url(), dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("--live plays the motion its source sends: give it or --motion, not both"), std::string::npos) << r.err;
}

/// Every pose frame's joints of the take in stream `source`.
std::vector<std::vector<RigidTransform>> poseFramesOf(const NatsServer& server, const std::string& source) {
  studio::Bus bus = studio::Bus::connect(server.url(), "test");
  const studio::StreamRange range = bus.range(source);
  std::vector<std::vector<RigidTransform>> frames;
  for (std::uint64_t seq = range.first; seq != 0 && seq <= range.last; ++seq) {
    const studio::Message m = studio::decode(bus.get(source, seq)->data);
    if (const auto* p = std::get_if<studio::PoseFrame>(&m.payload)) frames.push_back(p->joints);
  }
  return frames;
}

TEST(Studio, ALiveSourceOfFrameLinesTakesItsSkeletonFromABvhFile) {
  // A stream of frame lines with no header, the skeleton given by --live-header: the same
  // pose frames, to the bit, as the stream that sends its header first.
  ScratchDir dir("studio-live-header");
  NatsServer server;
  const std::vector<std::string> lines = linesOf(slurp(kWalk));
  CaptureBroadcast whole, framesOnly;
  whole.send(lines, 100, 1ms);
  framesOnly.send(std::vector<std::string>(lines.begin() + 187, lines.end()), 100, 1ms);
  CliResult r = runDrape("anim-server '" + kScene + "' --live " + whole.url() + " --name whole" + roles(server), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  r = runDrape("anim-server '" + kScene + "' --live " + framesOnly.url() + " --live-header '" + kWalk + "' --name lines" +
                   roles(server),
               dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("141 pose frames"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("frame lines only: the skeleton is " + kWalk + "'s"), std::string::npos) << r.err;
  const auto a = poseFramesOf(server, "whole"), b = poseFramesOf(server, "lines");
  ASSERT_EQ(a.size(), 141u);
  ASSERT_EQ(b.size(), a.size());
  for (std::size_t f = 0; f < a.size(); ++f)
    for (std::size_t j = 0; j < a[f].size(); ++j) {
      ASSERT_EQ(a[f][j].translation, b[f][j].translation) << "frame " << f << " joint " << j;
      ASSERT_EQ(a[f][j].rotation.coeffs(), b[f][j].rotation.coeffs()) << "frame " << f << " joint " << j;
    }
  r = runDrape("anim-server '" + kScene + "' --live-header '" + kWalk + "' --motion '" + kWalk + "'" + roles(server), dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("--live-header is the skeleton of a --live source"), std::string::npos) << r.err;
}

TEST(Studio, ErrorsSayWhatToDo) {
  ScratchDir dir("studio-errors");
  const RefusingPort refusing;
  const std::string nowhere = refusing.url();
  CliResult r = runDrape("player '" + kScene + "' --record '" + (dir / "rec") + "' --server " + nowhere, dir);
  EXPECT_EQ(r.code, 4) << r.err;
  EXPECT_NE(r.err.find(nowhere + ": no NATS server answers (start one with nats-server -js"), std::string::npos) << r.err;

  r = runDrape("player '" + kScene + "'", dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("give --record DIR or --window"), std::string::npos) << r.err;
  r = runDrape("player '" + kScene + "' --record '" + (dir / "rec") + "' --from now --server " + nowhere, dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("--from applies to --window"), std::string::npos) << r.err;
  r = runDrape("player '" + kScene + "' --record '" + (dir / "rec") + "' --take walk --takes 2 --server " + nowhere, dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("--take names one take: it does not go with --takes 2"), std::string::npos) << r.err;
  r = runDrape("anim-server '" + kScene + "' --server " + nowhere, dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("nothing moves the avatar: give --motion FILE"), std::string::npos) << r.err;
  r = runDrape("cloth-server '" + kScene + "' --garments Skirt,Cape --server " + nowhere, dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("has no garment 'Cape' (it has: Skirt)"), std::string::npos) << r.err;
  r = runDrape("cloth-server '" + kScene + "' --name anim --server " + nowhere, dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("needs a name of its own"), std::string::npos) << r.err;
  r = runDrape("cloth-server '" + kScene + "' --name 'my.cloth' --server " + nowhere, dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("1 to 64 letters, digits"), std::string::npos) << r.err;

  // A cloth-server waits for poses that never come, and gives up when told.
  const NatsServer server;
  r = runDrape("cloth-server '" + kScene + "' --server " + server.url() + " --give-up 1", dir);
  EXPECT_EQ(r.code, 4) << r.err;
  EXPECT_NE(r.err.find("for a take's poses from 'anim'; giving up"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace drape::testing
