// `drape cloth-server SCENE --poses NAME`: the studio's cloth simulator (docs/STUDIO.md).
// Follows an anim-server's pose stream take after take, simulates the scene's garments on
// the avatar as the poses arrive (the loop of drape run, frame by frame), and publishes the
// garments into a cloth stream. Several cloth-servers may split a scene's garments
// (--garments); one restarted in the middle of a take computes it again from its start and
// sends what its stream does not hold yet.

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "command.hpp"
#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "drape/studio/pose_follower.hpp"
#include "drape/studio/publisher.hpp"
#include "drape/studio/takes.hpp"
#include "run_setup.hpp"
#include "studio_options.hpp"

namespace drape::cli {
namespace {

struct ClothServerOptions {
  std::string scene, poses = "anim", name = "cloth", positions = "double", character;
  std::vector<std::string> garments;
  std::vector<std::string> guests;  ///< --guest NAME=POSES
  long takes = 0;
  StudioOptions studio;
};

/// Keeps the garments `names` lists (all of them for an empty list), in the scene's order.
void keepGarments(RunSetup& setup, const std::vector<std::string>& names, const std::string& scene) {
  if (names.empty()) return;
  std::vector<std::string> have;
  for (const GarmentSetup& g : setup.garments) have.push_back(g.name);
  for (const std::string& n : names)
    if (std::find(have.begin(), have.end(), n) == have.end())
      throw Error(fmt::format("--garments: {} has no garment '{}' (it has: {})", scene, n, fmt::join(have, ", ")));
  keepGarmentsWhere(setup, [&](std::size_t g) {
    return std::find(names.begin(), names.end(), setup.garments[g].name) != names.end();
  });
  // A garment steps with the garments it is worn over: refused here, not at the first take.
  for (const GarmentSetup& g : setup.garments)
    for (const std::string& below : g.over)
      if (std::find(names.begin(), names.end(), below) == names.end())
        throw Error(fmt::format("--garments: '{}' is worn over '{}' (its over): give both, as in --garments {},{}",
                                g.name, below, below, g.name));
}

/// The character whose garments `garments` names, when they are all one's (so that
/// --character need not be given); "" otherwise.
std::string wearerOf(const RunSetup& setup, const std::vector<std::string>& garments) {
  std::string wearer;
  for (const CharacterSetup& c : setup.characters)
    for (const std::size_t g : c.garments)
      if (std::find(garments.begin(), garments.end(), setup.garments[g].name) != garments.end()) {
        if (!wearer.empty() && wearer != c.name) return "";
        wearer = c.name;
      }
  return wearer;
}

/// Another character of the scene whose body the garments collide with too, moved by its
/// anim-server's pose stream (--guest NAME=POSES): its part fields, built once, and its
/// take of the same name as the take simulated, followed as it comes.
struct GuestPoses {
  CharacterSetup character;  ///< its avatar, name and part fields
  std::string poses;         ///< the stream
  std::unique_ptr<studio::StreamReader> stream;
  std::unique_ptr<studio::PoseFollower> follower;
};

/// The --guest options as guests of `full` (the scene before a character was chosen), in
/// the scene's order, their fields built. Throws drape::Error naming --guest for a NAME the
/// scene lacks, the character simulated, one given twice or a bad stream name.
std::vector<GuestPoses> guestsOf(const RunSetup& full, const std::vector<std::string>& options,
                                 const std::string& simulated, const std::string& posesName) {
  std::vector<std::pair<std::size_t, std::string>> given;
  for (const std::string& option : options) {
    const std::optional<std::pair<std::size_t, std::string>> named = forCharacter(full, option, "--guest");
    if (!named)
      throw Error(fmt::format("--guest {}: expected NAME=POSES, a character of the scene and the --name of its "
                              "anim-server",
                              option));
    const auto& [index, poses] = *named;
    const std::string& name = full.characters[index].name;
    studio::checkSourceName(poses, "--guest " + name);
    if (name == simulated)
      throw Error(fmt::format("--guest {}: {} is the character this cloth-server dresses; its poses are --poses", option,
                              name));
    if (poses == posesName)
      throw Error(fmt::format("--guest {}: '{}' is the stream of the poses simulated (--poses)", option, poses));
    for (const auto& [other, stream] : given)
      if (other == index) throw Error(fmt::format("--guest {}: {} is a guest twice", option, name));
    given.push_back(*named);
  }
  std::sort(given.begin(), given.end());
  std::vector<GuestPoses> guests;
  for (const auto& [index, poses] : given) {
    GuestPoses g;
    g.character = full.characters[index];
    g.character.keepApart.clear();  // its anim-server sends the motion corrected
    buildPartFieldsOnce(full, g.character, fmt::format("for the guest {}", g.character.name));
    g.poses = poses;
    guests.push_back(std::move(g));
  }
  return guests;
}

/// The cloth take's frames onto the stream, garment by garment.
class ClothSink final : public FrameSink {
 public:
  explicit ClothSink(studio::Publisher& publisher) : publisher_(publisher) {}
  void begin(const std::vector<const sim::CharacterWorld*>&) override {}
  void write(const FrameTaken& taken) override {
    for (std::size_t g = 0; g < taken.positions.size(); ++g) {
      frame_.frame = taken.frame;
      frame_.garment = static_cast<std::uint32_t>(g);
      frame_.positions = taken.positions[g];
      frame_.states = taken.states[g];
      publisher_.send(frame_);
    }
    written_ = taken.frame;
  }
  void end(long) override {}
  void stats(const nlohmann::json& stats) override { stats_ = stats.dump(2) + "\n"; }
  [[nodiscard]] const std::string& statsText() const { return stats_; }
  [[nodiscard]] long written() const { return written_; }

 private:
  studio::Publisher& publisher_;
  studio::ClothFrame frame_;
  std::string stats_;
  long written_ = -1;
};

struct TakeOutcome {
  bool held = false;  ///< the cloth stream held the whole take already: nothing was simulated
  long frames = 0;
  std::string error;
  ExitCode code = ExitCode::Ok;
};

/// Simulates the take `poses` follows and publishes it; the take's End says how it ended.
TakeOutcome simulateTake(const RunSetup& scene, studio::PoseFollower& poses, std::vector<GuestPoses>& guests,
                         studio::Publisher& publisher, const std::string& posesName) {
  const studio::PoseStart& ps = poses.start();
  RunSetup setup = scene;
  CharacterSetup& character = setup.characters.front();
  // The stream's motion, growing as it comes; the world keeps a pointer to it (the take's
  // follower outlives the world).
  character.animation = std::shared_ptr<const motion::AvatarAnimation>(std::shared_ptr<void>(), &poses.animation());
  character.keepApart.clear();  // the anim-server sends the motion corrected
  setup.motionStreamed = true;
  // The wind an event graph of the anim-server sets, frame by frame, as the poses come.
  setup.motionWind = std::shared_ptr<const MotionWind>(std::shared_ptr<void>(), &poses.wind());
  setup.frames = 0;
  const double rate = setup.settings.frameRate_hz, leadIn = character.leadIn_s;

  studio::ClothStart start;
  start.poses = posesName;
  start.poseTake = poses.take();
  start.character = ps.character;
  start.start = studio::clothTimeCode(0, ps.start, leadIn);
  start.leadIn_s = leadIn;
  for (const GarmentSetup& g : setup.garments)
    start.garments.push_back({g.name, static_cast<std::uint32_t>(g.mesh.vertexCount())});
  publisher.beginTake(poses.take(), start);
  if (publisher.complete()) {
    spdlog::info("cloth take {} is in {} already, to its end; waiting for the next", poses.take(),
                 studio::subjectOf(publisher.source()));
    TakeOutcome held;
    held.held = true;
    return held;
  }

  ClothSink sink(publisher);
  const FrameGate gate = [&](long frame) {
    if (frame == 0) return true;  // motion frame 0 came before the world was built
    const std::int64_t needed = studio::motionFramesNeeded(frame, rate, leadIn, rate);
    // A take whose motion ended holds its last pose, as drape run plays a motion past its
    // end; the take runs as long as the longest of the character's and its guests', as
    // drape run simulates a cast for its longest motion.
    bool more = poses.waitForFrames(needed);
    std::int64_t longest = poses.frames();
    for (GuestPoses& g : guests) {
      more = g.follower->waitForFrames(needed) || more;
      longest = std::max(longest, g.follower->frames());
    }
    return more || frame <= studio::clothFramesOf(longest, rate, leadIn, rate);
  };
  TakeOutcome outcome;
  try {
    // Each guest's take of this take's name, its motion growing as it comes.
    for (GuestPoses& g : guests) {
      g.follower->followNextTake(*g.character.avatar, rate, poses.take());
      if (!g.follower->waitForFrames(1))
        throw Error(fmt::format("the guest {}'s pose take {} on '{}' ended without a frame", g.character.name,
                                poses.take(), g.poses));
      CharacterSetup guest = g.character;
      guest.animation =
          std::shared_ptr<const motion::AvatarAnimation>(std::shared_ptr<void>(), &g.follower->animation());
      setup.guests.push_back(std::move(guest));
    }
    simulateInto(setup, sink, gate);
  } catch (const studio::NewTake& e) {
    outcome.error = e.what();
    outcome.code = ExitCode::Unavailable;
  } catch (const Error& e) {
    outcome.error = e.what();
    outcome.code = e.code();
  }
  outcome.frames = std::max(0L, sink.written());
  publisher.send(studio::End{outcome.frames, sink.statsText(), outcome.error, static_cast<int>(outcome.code)});
  return outcome;
}

int runClothServer(const ClothServerOptions& o) {
  studio::checkSourceName(o.name, "--name");
  studio::checkSourceName(o.poses, "--poses");
  if (o.name == o.poses) throw Error(fmt::format("--name {}: the cloth stream needs a name of its own, not the poses'", o.name));
  if (o.positions != "double" && o.positions != "float")
    throw Error(fmt::format("--positions {}: expected double or float", o.positions));
  RunSetup setup = runSetupFromScene(o.scene);
  const RunSetup full = setup;  // every character, for the guests
  keepGarments(setup, o.garments, o.scene);
  const std::string chosen =
      o.character.empty() && setup.characters.size() > 1 ? wearerOf(setup, o.garments) : o.character;
  if (!chooseCharacter(setup, chosen, "--character"))
    throw Error(fmt::format("{}: the scene has no avatar for its garments to move with", o.scene));
  CharacterSetup& character = setup.characters.front();
  std::vector<GuestPoses> guests = guestsOf(full, o.guests, character.name, o.poses);
  {
    RunSetup check = setup;  // bad garments or settings are said before any waiting
    check.motionStreamed = true;
    validateRunSetup(check);
  }
  const scene::Avatar& avatar = *character.avatar;
  // The part fields once, for every take: a take's world is then ready in moments, well
  // within the lead-in.
  spdlog::info("building distance fields ({:.4g} m voxels) for every take", character.voxel_m);
  const auto fieldsBegan = std::chrono::steady_clock::now();
  character.fields = std::make_shared<const std::vector<sim::PartField>>(
      sim::buildPartFields(avatar, setup.garments, worldSettings(setup, character)));
  spdlog::info("{} distance fields in {:.2f} s", character.fields->size(),
               std::chrono::duration<double>(std::chrono::steady_clock::now() - fieldsBegan).count());

  studio::Bus bus = studio::Bus::connect(o.studio.server, "drape cloth-server " + o.name);
  studio::StreamReader stream(bus, o.poses, consumerName("cloth-server-" + o.name, false), o.studio.patience(),
                              o.studio.giveUp());
  studio::PoseFollower poses(stream);
  for (GuestPoses& g : guests) {
    g.stream = std::make_unique<studio::StreamReader>(bus, g.poses,
                                                      consumerName("cloth-server-" + o.name + "-guest-" + g.poses, false),
                                                      o.studio.patience(), o.studio.giveUp());
    g.follower = std::make_unique<studio::PoseFollower>(*g.stream);
    spdlog::info("its garments collide with {}'s body too, as the poses of '{}' move it (in each take, its take of "
                 "the same name)",
                 g.character.name, g.poses);
  }
  studio::Publisher publisher(bus, o.name, o.positions == "float" ? studio::Precision::Float : studio::Precision::Double,
                              o.studio.giveUp());
  std::vector<std::string> names;
  for (const GarmentSetup& g : setup.garments) names.push_back(g.name);
  spdlog::info("cloth-server '{}': {} on {}, following the poses of '{}' on {}", o.name, fmt::join(names, ", "),
               avatar.name, o.poses, bus.url());

  int exitCode = 0;
  for (long served = 0; o.takes == 0 || served < o.takes;) {
    poses.followNextTake(avatar, setup.settings.frameRate_hz);
    if (!chosen.empty() && poses.start().character != chosen)
      throw Error(fmt::format("pose take {} of '{}' moves {}, and this cloth-server simulates {}'s garments: give it the "
                              "--poses of {}'s anim-server",
                              poses.take(), o.poses, poses.start().character, chosen, chosen));
    if (!poses.waitForFrames(1)) throw Error(fmt::format("pose take {} ended without a frame", poses.take()));
    const auto began = std::chrono::steady_clock::now();
    const TakeOutcome outcome = simulateTake(setup, poses, guests, publisher, o.poses);
    if (outcome.held) continue;  // a take served before: it does not count
    ++served;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
    if (!outcome.error.empty()) {
      spdlog::error("take {}: {}", poses.take(), outcome.error);
      exitCode = static_cast<int>(outcome.code);
      continue;  // a server goes on to the next take
    }
    exitCode = 0;
    fmt::print("take {}: {} cloth frames of {} sent to {} in {:.1f} s ({} pose frames{})\n", poses.take(), outcome.frames,
               fmt::join(names, ", "), studio::subjectOf(o.name), seconds, poses.frames(),
               poses.filledFrames() > 0 ? fmt::format(", {} filled in", poses.filledFrames()) : std::string());
  }
  return exitCode;
}

RunFunction setupClothServer(CLI::App& app) {
  static ClothServerOptions o;
  app.add_option("scene", o.scene, "VRML97 scene with the garments and the avatar (the anim-server's)")->required();
  app.add_option("--poses", o.poses, "The anim-server whose pose stream to follow (its --name)")->capture_default_str();
  app.add_option("--name", o.name, "This broadcaster's name: it publishes on drape.NAME, into the stream DRAPE_NAME")
      ->capture_default_str();
  app.add_option("--garments", o.garments, "Simulate only these of the scene's garments (another cloth-server the rest)")
      ->delimiter(',');
  app.add_option("--character", o.character,
                 "Which of the scene's characters' garments it simulates (needed in a scene of several unless --garments "
                 "names one's); its --poses are the anim-server's of that --character")
      ->type_name("NAME");
  app.add_option("--guest", o.guests,
                 "Another character of the scene whose body the garments collide with too (two characters that "
                 "touch), moved by the pose stream POSES (its anim-server's --name): in each take, its take of the "
                 "same name (give the cast's anim-servers one --take); repeatable")
      ->type_name("NAME=POSES");
  app.add_option("--positions", o.positions,
                 "How positions travel: double (a player records what drape run writes, to the byte) or float (half "
                 "the bytes)")
      ->capture_default_str();
  app.add_option("--takes", o.takes,
                 "Stop after simulating N takes (default: serve take after take; a take its stream holds whole "
                 "already is not simulated again and does not count)")
      ->check(CLI::PositiveNumber);
  o.studio.add(app, "pose frames");
  app.footer(
      "Exit codes: 0 done, 2 bad input, 3 a garment went unstable (the take's End says where), 4 no NATS server "
      "answers or a peer went silent past --give-up. A server goes on to the next take after a failed one; with "
      "--takes the exit code is the last take's.");
  return [] { return runClothServer(o); };
}

const bool registered_cmd_cloth_server = registerCommand(
    {"cloth-server", "Studio: simulate the garments on a pose stream's avatar and publish them", "", 71,
     &setupClothServer});

}  // namespace
}  // namespace drape::cli
