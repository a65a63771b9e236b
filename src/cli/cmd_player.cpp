// `drape player SCENE --cloth NAME[,NAME...] (--record DIR | --window)`: the studio's player
// (docs/STUDIO.md). Collates the cloth-servers' garments and the poses they simulated by
// frame, and records them as a run directory (what drape run --out writes, to the byte) or
// shows them live in a window.

#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "command.hpp"
#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "drape/render/player.hpp"
#include "drape/sim/body_skin.hpp"
#include "drape/studio/pose_follower.hpp"
#include "render_options.hpp"
#include "run_writer.hpp"
#include "stop_signal.hpp"
#include "shown_bodies.hpp"
#include "studio_frames.hpp"
#include "take_feed.hpp"

namespace drape::cli {
namespace {

namespace fs = std::filesystem;

struct PlayerRoleOptions {
  std::string scene, record, take, screenshot, from;
  std::vector<std::string> cloth{"cloth"};
  bool window = false, preview = false, everyFrame = false;
  long every = 1, frames = 0, takes = 1;
  StudioOptions studio;
  PictureOptions picture;
};

/// The part fields a character's skinned body is fitted to, as the cloth-servers' worlds
/// build them (none for an avatar without a skin: the segments need none).
std::vector<sim::PartField> skinFields(const RunSetup& setup, const CharacterSetup& character) {
  if (!character.avatar->skin) return {};
  spdlog::info("building distance fields ({:.4g} m voxels) to fit {}'s skinned body", character.voxel_m,
               setup.characters.size() > 1 ? character.name : std::string("the avatar"));
  return sim::buildPartFields(*character.avatar, garmentsOf(setup, character), worldSettings(setup, character));
}

/// How far a character's skin may stand out of its parts: the least T0 of what it wears.
double skinAllowance(const RunSetup& setup, const CharacterSetup& character) {
  return sim::leastT0(garmentsOf(setup, character), worldSettings(setup, character));
}

/// The cloth-servers' stats for stats.json: one server's as it wrote them, several by stream.
nlohmann::json statsOf(const std::vector<std::pair<std::string, std::string>>& stats) {
  if (stats.size() == 1) return nlohmann::json::parse(stats.front().second, nullptr, false);
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [source, text] : stats) out["cloth_servers"][source] = nlohmann::json::parse(text, nullptr, false);
  return out;
}

/// Where a take is recorded when a player records several: its name, made a file name.
std::string takeDirName(const std::string& take) {
  std::string name = take;
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
  return name.empty() || name == "." || name == ".." ? "take" : name;
}

/// The part fields of each character's skinned body, built again only when a take sends it
/// other garments.
class SkinFields {
 public:
  const std::vector<sim::PartField>& of(const RunSetup& setup, const CharacterSetup& character) {
    std::vector<std::string> key{character.name};
    for (const std::size_t g : character.garments) key.push_back(setup.garments[g].name);
    for (const auto& [k, fields] : built_)
      if (k == key) return *fields;
    return *built_.emplace_back(std::move(key), std::make_unique<std::vector<sim::PartField>>(skinFields(setup, character)))
                .second;
  }

 private:
  std::vector<std::pair<std::vector<std::string>, std::unique_ptr<std::vector<sim::PartField>>>> built_;
};

/// How one take's recording ended.
struct Recording {
  long frames = 0;
  std::string failure;  ///< the take's error (a garment went unstable), or ""
  ExitCode code = ExitCode::Ok;
  std::string cutShort;  ///< the stream started another take first: what it said, or ""
  bool stopped = false;  ///< a signal stopped the player
};

/// Records the take `frames` follows into `setup.outDir`: the frames it has (all of them,
/// or --frames), then the stats, as drape run writes them.
Recording recordTake(const PlayerRoleOptions& o, RunSetup& setup, StudioFrames& frames, SkinFields& fields,
                     const std::atomic<bool>& stop) {
  std::vector<CharacterAtStart> characters;
  const std::vector<std::vector<RigidTransform>> joints = frames.jointsAtStart();
  for (std::size_t c = 0; c < setup.characters.size(); ++c)
    characters.push_back({&fields.of(setup, setup.characters[c]), skinAllowance(setup, setup.characters[c]), joints[c]});
  RunWriter writer(setup, characters);
  FrameTaken taken;
  long last = -1;
  Recording out;
  try {
    while ((o.frames == 0 || last < o.frames) && !stop && frames.next(last + 1, taken)) {
      writer.write(taken);
      ++last;
    }
    out.stopped = stop;
  } catch (const studio::Stopped&) {
    out.stopped = true;
  } catch (const Error& e) {  // the take's own end: the frames before it are kept, as drape run keeps them
    out.failure = e.what();
    out.code = e.code();
  } catch (const studio::NewTake& e) {
    out.cutShort = e.what();
  }
  writer.close(std::max(0L, last));
  if (const auto stats = frames.stats(); !stats.empty()) writer.writeStats(statsOf(stats));
  out.frames = last + 1;
  return out;
}

int record(const PlayerRoleOptions& o) {
  RunSetup setup = runSetupFromScene(o.scene);
  studio::Bus bus = studio::Bus::connect(o.studio.server, "drape player");
  StudioFrames frames(bus, setup, o.cloth, o.studio);
  setup.preview = o.preview;
  setup.objEvery = o.every;
  SkinFields fields;
  // A signal ends the recording where it is, its files closed: how a recorder of take after take stops.
  const std::atomic<bool>& stop = stopOnSignals();
  frames.stopOn(&stop);
  int exitCode = 0;
  for (long recorded = 0; o.takes == 0 || recorded < o.takes; ++recorded) {
    try {
      frames.followNextTake(o.take);
    } catch (const studio::Stopped&) {
      fmt::print("stopped (a signal) waiting for a take; {} recorded\n", recorded);
      return exitCode;
    }
    const std::string dir = o.takes == 1 ? o.record : (fs::path(o.record) / takeDirName(frames.take())).string();
    setup.outDir = dir;
    setup.timeCodeOfFrame0 = frames.start().start.frame;  // the take's time code, kept in the recording
    const Recording r = recordTake(o, setup, frames, fields, stop);
    if (!r.failure.empty()) {
      const std::string said = fmt::format("{} (the {} frames before it recorded in {})", r.failure, r.frames, dir);
      if (o.takes == 1) throw Error(said, r.code);
      spdlog::error("take {}: {}", frames.take(), said);  // a recorder goes on to the next take
      exitCode = static_cast<int>(r.code);
      continue;
    }
    exitCode = 0;
    fmt::print("recorded take {}: {} frames of {} in {}/{}\n", frames.take(), r.frames, characterNames(setup), dir,
               r.stopped              ? " (stopped by a signal)"
               : !r.cutShort.empty() ? " (cut short: " + r.cutShort + ")"
                                     : "");
    std::fflush(stdout);
    if (r.stopped) break;
  }
  return exitCode;
}

/// What a window showed of one take, said when it moves on to the next and when it closes.
struct Shown {
  std::string take;
  TimeCode from;
  long frames = 0, left = 0;
  std::chrono::steady_clock::time_point began;

  void say() const {
    if (frames == 0) return;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
    std::cout << fmt::format("showed {} frame{} of take {} from {} in {:.1f} s{}\n", frames, frames == 1 ? "" : "s", take,
                             from.smpte(), seconds,
                             left > 0 ? fmt::format(" ({} left out to keep to the take's time)", left) : "");
    std::cout.flush();
  }
};

int show(const PlayerRoleOptions& o) {
  RunSetup setup = runSetupFromScene(o.scene);
  studio::Bus bus = studio::Bus::connect(o.studio.server, "drape player");
  StudioFrames frames(bus, setup, o.cloth, o.studio);
  frames.followNextTake(o.take);
  // The window's meshes are the first take's garments and characters; the feed reads on with
  // a setup of its own.
  const RunSetup shownSetup = setup;
  const std::size_t garmentsShown = shownSetup.garments.size();
  std::vector<render::MeshInfo> meshes;
  for (const GarmentSetup& g : shownSetup.garments)
    meshes.push_back({g.name, render::MeshRole::Garment, g.mesh.vertexCount(), g.mesh.triangles, "", g.colour});
  SkinFields skinFieldsOf;
  std::vector<const std::vector<sim::PartField>*> fields;
  std::vector<double> allowances;
  for (const CharacterSetup& c : shownSetup.characters) {
    fields.push_back(&skinFieldsOf.of(shownSetup, c));
    allowances.push_back(skinAllowance(shownSetup, c));
  }
  ShownBodies bodies(shownSetup, meshes, fields, allowances);
  const std::string firstTake = frames.take();
  const double rate = setup.settings.frameRate_hz;

  const long firstShown = o.from.empty() ? 0 : frames.seek(o.from);
  TakeFeed feed(frames, firstShown, o.takes);
  Shown shown;
  std::optional<std::size_t> showing;  // which take of the feed
  std::optional<std::chrono::steady_clock::time_point> first;
  long firstOfTake = firstShown;
  render::CallbackSource source(
      meshes, rate,
      [&](render::Frame& out) {
        // Live, a window that draws slower than the frame rate keeps to the take's time by
        // leaving frames out (their poses and cloth still read, in order); --every-frame shows
        // each, falling behind.
        const auto now = std::chrono::steady_clock::now();
        std::optional<TakeFeed::Latest> due;
        if (!o.everyFrame && showing)
          due = TakeFeed::Latest{
              *showing, firstOfTake + static_cast<long>(std::chrono::duration<double>(now - *first).count() * rate)};
        long left = 0;
        std::optional<TakeFeed::Item> item = feed.next(due, &left);
        if (!item) return false;
        if (showing != item->take) {  // a take begins: its time from its first frame shown
          shown.say();
          if (showing) spdlog::info("the next take: {}", item->takeName);
          showing = item->take;
          first = now;
          firstOfTake = item->taken.frame;
          shown = Shown{item->takeName, item->time, 0, 0, now};
        }
        ++shown.frames;
        shown.left += left;
        // The take's time code: cloth frame 0 is the lead-in's start, before the poses' first.
        out.time = item->time;
        const FrameTaken& taken = item->taken;
        out.positions.resize(meshes.size());
        out.states.resize(meshes.size());
        for (std::size_t g = 0; g < garmentsShown; ++g) {
          out.positions[g] = taken.positions[g];
          out.states[g] = taken.states[g];
        }
        bodies.pose(taken.joints, taken.positions, out.positions);
        return true;
      },
      [&](std::int64_t) { return feed.ready(); });
  render::PlayerOptions options;
  std::tie(options.width, options.height) = o.picture.parsedSize();
  options.title = o.takes == 1 ? fmt::format("drape player: take {}", firstTake)
                               : fmt::format("drape player: take after take of {}", fmt::join(o.cloth, ", "));
  if (o.frames > 0) options.maxFrames = o.frames;
  options.loop = false;
  options.view = o.picture.view();
  options.follow = o.picture.follow;
  options.overlay = o.picture.overlay();
  options.screenshot = o.screenshot;
  options.close = &stopOnSignals();  // Ctrl-C closes the window as its user would: the screenshot, what it showed
  render::SubdividedSource subdivided(source, o.picture.subdivide);
  (void)render::Player(options).run(subdivided);
  shown.say();
  return 0;
}

RunFunction setupPlayer(CLI::App& app) {
  static PlayerRoleOptions o;
  app.add_option("scene", o.scene, "VRML97 scene the cloth-servers simulate (its garments and avatar)")->required();
  app.add_option("--cloth", o.cloth, "The cloth-servers to collate (their --name), each sending some of the garments")
      ->delimiter(',')
      ->capture_default_str();
  auto* rec = app.add_option("--record", o.record, "Record the take as a run directory, as drape run --out writes it");
  auto* win = app.add_flag("--window", o.window, "Show the take live in a window (needs a display)");
  rec->excludes(win);
  app.add_option("--take", o.take, "The take to play (default: the one the cloth streams hold, or the next)");
  app.add_option("--frames", o.frames, "Stop after frame N (with --window: after N frames shown)")->check(CLI::PositiveNumber);
  app.add_option("--takes", o.takes,
                 "Play N takes one after another, 0 for take after take until stopped (with --record: each in "
                 "DIR/TAKE, its name, unless N is 1)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--preview", o.preview, "With --record: also a contact sheet and, with ffmpeg, an MP4");
  app.add_option("--every", o.every, "With --record: an OBJ frame every K frames")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--from", o.from,
                 "With --window: start at time code HH:MM:SS:FF of the take, or 'now' (the newest frame: join a live "
                 "take where it is), without reading the cloth before it");
  app.add_option("--screenshot", o.screenshot, "With --window: save the last picture as a PNG when it closes");
  app.add_flag("--every-frame", o.everyFrame,
               "With --window: show every frame, however long drawing takes (default: leave frames out to keep to "
               "the take's time)");
  o.studio.add(app, "frames");
  o.picture.add(app);
  app.footer("drape render DIR and drape play DIR show a recording afterwards.\n"
             "Exit codes: 0 done, 2 bad input, 3 a garment went unstable in the take (the frames before are kept), "
             "4 no NATS server answers or a peer went silent past --give-up. With --takes the exit code is the last "
             "take's; Ctrl-C stops a recorder with the take it was recording closed, and closes a window.");
  return [] {
    if (o.record.empty() && !o.window) throw Error("drape player: give --record DIR or --window");
    if (!o.take.empty() && o.takes != 1)
      throw Error("--take names one take: it does not go with --takes " + std::to_string(o.takes));
    if (!o.from.empty() && !o.window)
      throw Error("--from applies to --window: a recording is the whole take, which the streams keep from its start");
    return o.window ? show(o) : record(o);
  };
}

const bool registered_cmd_player = registerCommand(
    {"player", "Studio: collate a take's cloth and poses by time code; record it or show it live", "", 72,
     &setupPlayer});

}  // namespace
}  // namespace drape::cli
