// `drape player SCENE --cloth NAME[,NAME...] (--record DIR | --window)`: the studio's player
// (docs/STUDIO.md). Collates the cloth-servers' garments and the poses they simulated by
// frame, and records them as a run directory (what drape run --out writes, to the byte) or
// shows them live in a window.

#include <chrono>
#include <iostream>
#include <optional>

#include <fmt/format.h>

#include "command.hpp"
#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "drape/render/player.hpp"
#include "drape/sim/body_skin.hpp"
#include "drape/studio/pose_follower.hpp"
#include "render_options.hpp"
#include "run_writer.hpp"
#include "studio_frames.hpp"

namespace drape::cli {
namespace {

struct PlayerRoleOptions {
  std::string scene, record, take, screenshot, from;
  std::vector<std::string> cloth{"cloth"};
  bool window = false, preview = false, everyFrame = false;
  long every = 1, frames = 0;
  StudioOptions studio;
  PictureOptions picture;
};

/// The part fields the skinned body is fitted to, as the cloth-servers' worlds build them
/// (none for an avatar without a skin: the segments need none).
std::vector<sim::PartField> skinFields(const RunSetup& setup) {
  if (!setup.character->avatar->skin) return {};
  spdlog::info("building distance fields ({:.4g} m voxels) to fit the skinned body", setup.character->voxel_m);
  return sim::buildPartFields(*setup.character->avatar, setup.garments, worldSettings(setup));
}

/// The cloth-servers' stats for stats.json: one server's as it wrote them, several by stream.
nlohmann::json statsOf(const std::vector<std::pair<std::string, std::string>>& stats) {
  if (stats.size() == 1) return nlohmann::json::parse(stats.front().second, nullptr, false);
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [source, text] : stats) out["cloth_servers"][source] = nlohmann::json::parse(text, nullptr, false);
  return out;
}

int record(const PlayerRoleOptions& o) {
  RunSetup setup = runSetupFromScene(o.scene);
  studio::Bus bus = studio::Bus::connect(o.studio.server, "drape player");
  StudioFrames frames(bus, setup, o.cloth, o.take, o.studio);
  setup.outDir = o.record;
  setup.preview = o.preview;
  setup.objEvery = o.every;
  const std::vector<sim::PartField> fields = skinFields(setup);
  RunWriter writer(setup, &fields, sim::leastT0(setup.garments, worldSettings(setup)), frames.jointsAtStart());
  FrameTaken taken;
  long last = -1;
  std::string failure;
  ExitCode failed = ExitCode::Ok;
  try {
    while ((o.frames == 0 || last < o.frames) && frames.next(last + 1, taken)) {
      writer.write(taken);
      ++last;
    }
  } catch (const Error& e) {  // the take's own end: the frames before it are kept, as drape run keeps them
    failure = e.what();
    failed = e.code();
  }
  writer.close(std::max(0L, last));
  if (const auto stats = frames.stats(); !stats.empty()) writer.writeStats(statsOf(stats));
  if (!failure.empty())
    throw Error(fmt::format("{} (the {} frames before it recorded in {})", failure, last + 1, o.record), failed);
  fmt::print("recorded take {}: {} frames of {} in {}/\n", frames.take(), last + 1, frames.start().character, o.record);
  return 0;
}

int show(const PlayerRoleOptions& o) {
  RunSetup setup = runSetupFromScene(o.scene);
  studio::Bus bus = studio::Bus::connect(o.studio.server, "drape player");
  StudioFrames frames(bus, setup, o.cloth, o.take, o.studio);
  const scene::Avatar& avatar = *setup.character->avatar;
  std::vector<render::MeshInfo> meshes;
  for (const GarmentSetup& g : setup.garments)
    meshes.push_back({g.name, render::MeshRole::Garment, g.mesh.vertexCount(), g.mesh.triangles});
  for (const scene::Segment& seg : avatar.segments)
    meshes.push_back({seg.name, render::MeshRole::Segment, seg.mesh.vertexCount(), seg.mesh.triangles});
  if (avatar.skin)
    meshes.push_back({"body", render::MeshRole::Skin, avatar.skin->mesh.vertexCount(), avatar.skin->mesh.triangles});
  const std::vector<sim::PartField> fields = skinFields(setup);
  std::unique_ptr<sim::BodySkin> skin;
  if (avatar.skin) skin = std::make_unique<sim::BodySkin>(avatar, fields, sim::leastT0(setup.garments, worldSettings(setup)));

  FrameTaken taken;
  const long firstShown = o.from.empty() ? 0 : frames.seek(o.from);
  long next = firstShown, skipped = 0;
  std::vector<sim::GarmentSurface> garments;
  std::optional<std::chrono::steady_clock::time_point> first;
  render::CallbackSource source(meshes, setup.settings.frameRate_hz, [&](render::Frame& out) {
    // Live, a window that draws slower than the frame rate keeps to the take's time by
    // leaving frames out (their poses and cloth still read, in order); --every-frame shows
    // each, falling behind.
    const auto now = std::chrono::steady_clock::now();
    if (!first) first = now;
    const auto due =
        firstShown + static_cast<long>(std::chrono::duration<double>(now - *first).count() * setup.settings.frameRate_hz);
    for (; !o.everyFrame && next < due; ++next, ++skipped)
      if (!frames.next(next, taken)) return false;
    if (!frames.next(next, taken)) return false;
    // The take's time code: cloth frame 0 is the lead-in's start, before the poses' first.
    out.time = TimeCode{frames.start().start.frame + next, frames.start().start.rate};
    ++next;
    out.positions.resize(meshes.size());
    out.states.resize(meshes.size());
    garments.clear();
    for (std::size_t g = 0; g < setup.garments.size(); ++g) {
      out.positions[g] = taken.positions[g];
      out.states[g] = taken.states[g];
      garments.push_back({taken.positions[g], setup.garments[g].mesh.triangles});
    }
    for (std::size_t s = 0; s < avatar.segments.size(); ++s) {
      const scene::Segment& seg = avatar.segments[s];
      std::vector<Vec3>& p = out.positions[setup.garments.size() + s];
      p.clear();
      const RigidTransform& pose = taken.joints[static_cast<std::size_t>(seg.joint)];
      for (const Vec3& v : seg.mesh.positions) p.push_back(pose.apply(v));
    }
    if (skin) skin->pose(taken.joints, garments, out.positions.back());
    return true;
  });
  render::PlayerOptions options;
  std::tie(options.width, options.height) = o.picture.parsedSize();
  options.title = fmt::format("drape player: take {}", frames.take());
  if (o.frames > 0) options.maxFrames = o.frames;
  options.loop = false;
  options.view = o.picture.view();
  options.follow = o.picture.follow;
  options.overlay = o.picture.overlay();
  options.screenshot = o.screenshot;
  render::SubdividedSource shown(source, o.picture.subdivide);
  const render::PlayerStats stats = render::Player(options).run(shown);
  const TimeCode from{frames.start().start.frame + firstShown, frames.start().start.rate};
  std::cout << fmt::format("showed {} frame{} of take {} from {} in {:.1f} s{}\n", stats.framesDrawn,
                           stats.framesDrawn == 1 ? "" : "s", frames.take(),
                           from.smpte(), stats.seconds,
                           skipped > 0 ? fmt::format(" ({} left out to keep to the take's time)", skipped) : "");
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
             "4 no NATS server answers or a peer went silent past --give-up.");
  return [] {
    if (o.record.empty() && !o.window) throw Error("drape player: give --record DIR or --window");
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
