// `drape play OUTDIR [--frames N]`: replays a finished run in a window with the overlays.
// `drape play SCENE.wrl [--motion FILE]`: simulates the scene live in the window, the
// garments coloured by collision state when that overlay is on.

#include <chrono>
#include <filesystem>
#include <iostream>
#include <optional>
#include <vector>

#include <fmt/format.h>

#include "command.hpp"
#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "drape/render/follow.hpp"
#include "drape/render/player.hpp"
#include "drape/render/run_replay.hpp"
#include "drape/sim/body_skin.hpp"
#include "drape/sim/character_world.hpp"
#include "frames_ahead.hpp"
#include "render_options.hpp"
#include "live_capture.hpp"
#include "live_run.hpp"
#include "run_setup.hpp"
#include "shown_bodies.hpp"
#include "stop_signal.hpp"

namespace drape::cli {
namespace {

struct PlayOptions {
  std::string run;
  std::vector<std::string> motions;
  std::string animation;
  std::vector<std::string> lives;  ///< --live SOURCE (NAME=SOURCE per character): captures simulated as they come
  std::string liveHeader;
  double giveUp_s = 0.0;
  long frames = 0;
  bool once = false;
  bool fast = false;
  std::string screenshot;
  PictureOptions picture;
};

/// The live source: the characters' worlds step frame by frame on a thread of their own and
/// the player receives the garments (with their collision states) and the bodies where they are.
int playScene(const PlayOptions& o, render::PlayerOptions options) {
  RunSetup setup = runSetupFromScene(o.run);
  if (setup.characters.empty())
    throw Error(fmt::format("{}: drape play simulates scenes with an avatar (replay a run directory otherwise)", o.run));
  // Live captures: read as the simulation asks for their frames, on the simulating thread.
  std::unique_ptr<LiveCast> live;
  if (!o.lives.empty()) {
    const std::chrono::milliseconds giveUp(static_cast<long long>(1000.0 * o.giveUp_s));
    const std::vector<std::pair<std::size_t, std::string>> sources = liveSources(setup, o.lives);
    addMotionsOfTheOthers(setup, sources, o.run);
    live = std::make_unique<LiveCast>(setup, sources, LiveCast::Options{o.liveHeader, giveUp, 0}, motionOptions(setup),
                                      stopOnSignals());
    options.close = &stopOnSignals();  // Ctrl-C closes the window
  } else {
    addSceneMotions(setup, o.run, o.motions, o.animation);
    if (o.frames > 0) warnOfFramesWithinTheLeadIn(setup, {o.frames, o.frames - 1, "shows", false});
  }
  SetupWorlds worlds(setup);
  for (std::size_t c = 0; c < worlds.size(); ++c) (void)settleWorld(setup.characters[c], worlds.world(c));
  const std::size_t garmentCount = setup.garments.size();

  // The meshes: the garments, then per character its segments and its skinned body.
  std::vector<render::MeshInfo> meshes;
  for (const GarmentSetup& g : setup.garments)
    meshes.push_back({g.name, render::MeshRole::Garment, g.mesh.vertexCount(), g.mesh.triangles, "", g.colour});
  std::vector<const std::vector<sim::PartField>*> fields;
  std::vector<double> allowances;
  for (std::size_t c = 0; c < worlds.size(); ++c) {
    fields.push_back(&worlds.world(c).fields());
    allowances.push_back(leastT0(worlds.world(c)));
  }
  ShownBodies bodies(setup, meshes, fields, allowances);
  // The simulation runs on a thread of its own, a few frames ahead of the window, which
  // poses the segments and the skins (fitted and tucked under the cloth) and draws.
  const auto prepare = [&](FrameTaken& slot) {
    slot.positions.resize(garmentCount);
    slot.states.resize(garmentCount);
    worlds.sizeJoints(slot.joints);
  };
  StageLaps stageLaps;
  FramesAhead ahead(kFramesAhead, 0, -1, prepare, [&](long frame, FrameTaken& taken) {
    if (live && !live->admit(frame)) return false;  // the capture ended
    for (std::size_t c = 0; c < worlds.size() && frame > 0; ++c)
      if (!worlds.world(c).stepFrame(frame)) {
        spdlog::error("{}", worlds.world(c).instability());
        return false;
      }
    taken.frame = frame;
    StageMs totals{};
    for (std::size_t g = 0; g < garmentCount; ++g) totals += stageTotalsMs(worlds.solver(g).stageTimes());
    taken.stageMs = stageLaps.lap(totals);
    for (std::size_t g = 0; g < garmentCount; ++g) {
      worlds.solver(g).state().copyPositions(taken.positions[g]);
      garmentVertexStates(worlds.solver(g), worlds.collider(g), taken.states[g]);
    }
    worlds.evaluateJoints(frame, taken.joints);
    return true;
  });
  // However the window closes, a capture the simulating thread waits on stops, so that it ends.
  const struct StopCaptureOnLeave {
    bool live;
    ~StopCaptureOnLeave() {
      if (live) askToStop();
    }
  } stopCaptureOnLeave{live != nullptr};
  render::CallbackSource source(meshes, setup.settings.frameRate_hz, [&](render::Frame& out) {
    const FrameTaken* taken = ahead.next();
    if (!taken) return false;
    out.time = frameTimeCode(setup, taken->frame);
    out.stages = stagesTaken(taken->stageMs);
    out.positions.resize(meshes.size());
    out.states.resize(meshes.size());
    for (std::size_t g = 0; g < garmentCount; ++g) {
      out.positions[g] = taken->positions[g];
      out.states[g] = taken->states[g];
    }
    bodies.pose(taken->joints, taken->positions, out.positions);
    return true;
  }, [&](std::int64_t) { return ahead.ready(); });  // live, a frame may be a while coming: the window stays live
  options.loop = false;
  render::SubdividedSource shown(source, o.picture.subdivide);
  const render::PlayerStats stats = render::Player(options).run(shown);
  std::cout << fmt::format("simulated and showed {} frames in {:.1f} s{}\n", stats.framesDrawn, stats.seconds,
                           live ? " of the live motion from " + live->names() : std::string());
  return 0;
}

RunFunction setupPlay(CLI::App& app) {
  static PlayOptions o;
  app.add_option("run", o.run, "A run directory (with manifest.json), as drape run --out writes, or a scene to simulate live")
      ->required();
  app.add_option("--motion", o.motions, std::string("With a scene: motion for its avatar ") + kMotionHelp +
                                            kMotionPerCharacterHelp)
      ->type_name("FILE|NAME=FILE");
  app.add_option("--animation", o.animation, kAnimationHelp);
  app.add_option("--live", o.lives,
                 std::string("With a scene, instead of a motion: ") + kLiveHelp +
                     "; shown as it is simulated; NAME=SOURCE for each character a capture moves in a scene of several")
      ->type_name("SOURCE|NAME=SOURCE");
  app.add_option("--live-header", o.liveHeader, kLiveHeaderHelp)->type_name("FILE.bvh");
  app.add_option("--give-up", o.giveUp_s, "With --live: stop simulating after S seconds without a line")
      ->check(CLI::PositiveNumber);
  app.add_option("--frames", o.frames, "Close by itself after showing N frames (a scene's counted from the lead-in's first)")
      ->check(CLI::PositiveNumber);
  app.add_flag("--once", o.once, "Stop at the last frame instead of starting over");
  app.add_flag("--fast", o.fast, "Show a new frame on every redraw instead of at the run's frame rate");
  app.add_option("--screenshot", o.screenshot, "Save the window's last picture as a PNG when it closes");
  o.picture.add(app);
  app.footer(
      "Mouse: drag to orbit, wheel to zoom. Keys: space pause, left/right step, R reset view, Esc quit.\n"
      "Needs a display (run it under xvfb-run on a server); drape render works without one.");
  return [] {
    render::PlayerOptions options;
    if (std::filesystem::is_regular_file(o.run)) {
      std::tie(options.width, options.height) = o.picture.parsedSize();
      options.title = fmt::format("drape play {}", o.run);
      if (o.frames > 0) options.maxFrames = o.frames;
      options.realTime = !o.fast;
      options.view = o.picture.view();
      options.follow = o.picture.follow;
      options.overlay = o.picture.overlay();
      options.screenshot = o.screenshot;
      return playScene(o, options);
    }
    if (!o.motions.empty() || !o.animation.empty() || !o.lives.empty())
      throw Error(fmt::format("{}: drape play takes a motion only with a scene file, not a run directory",
                              !o.lives.empty() ? "--live" : o.motions.empty() ? "--animation" : "--motion"));
    render::RunReplay replay(o.run);
    std::tie(options.width, options.height) = o.picture.parsedSize();
    options.title = fmt::format("drape play {}", o.run);
    if (o.frames > 0) options.maxFrames = o.frames;
    options.loop = !o.once;
    options.realTime = !o.fast;
    options.view = o.picture.view();
    options.follow = o.picture.follow;
    options.followFraming = render::followFraming(replay);  // the whole run is known: no lag
    options.view.bounds = replay.bounds();
    options.overlay = o.picture.overlay();
    options.screenshot = o.screenshot;
    render::SubdividedSource shown(replay, o.picture.subdivide);
    const render::PlayerStats stats = render::Player(options).run(shown);
    std::cout << fmt::format("showed {} frames in {:.1f} s\n", stats.framesDrawn, stats.seconds);
    return 0;
  };
}

const bool registered_cmd_play =
    registerCommand({"play", "Replay a run, or simulate a scene live, in a window with time code and overlays", "", 41, &setupPlay});

}  // namespace
}  // namespace drape::cli
