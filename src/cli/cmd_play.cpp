// `drape play OUTDIR [--frames N]`: replays a finished run in a window with the overlays.

#include <iostream>

#include <fmt/format.h>

#include "command.hpp"
#include "drape/render/player.hpp"
#include "drape/render/run_replay.hpp"
#include "render_options.hpp"

namespace drape::cli {
namespace {

struct PlayOptions {
  std::string run;
  long frames = 0;
  bool once = false;
  bool fast = false;
  std::string screenshot;
  PictureOptions picture;
};

RunFunction setupPlay(CLI::App& app) {
  static PlayOptions o;
  app.add_option("run", o.run, "A run directory (with manifest.json), as drape run --out writes")->required();
  app.add_option("--frames", o.frames, "Close by itself after showing N frames")->check(CLI::PositiveNumber);
  app.add_flag("--once", o.once, "Stop at the last frame instead of starting over");
  app.add_flag("--fast", o.fast, "Show a new frame on every redraw instead of at the run's frame rate");
  app.add_option("--screenshot", o.screenshot, "Save the window's last picture as a PNG when it closes");
  o.picture.add(app);
  app.footer(
      "Mouse: drag to orbit, wheel to zoom. Keys: space pause, left/right step, R reset view, Esc quit.\n"
      "Needs a display (run it under xvfb-run on a server); drape render works without one.");
  return [] {
    render::RunReplay replay(o.run);
    render::PlayerOptions options;
    std::tie(options.width, options.height) = o.picture.parsedSize();
    options.title = fmt::format("drape play {}", o.run);
    if (o.frames > 0) options.maxFrames = o.frames;
    options.loop = !o.once;
    options.realTime = !o.fast;
    options.view = o.picture.view();
    options.view.bounds = replay.bounds();
    options.overlay = o.picture.overlay();
    options.screenshot = o.screenshot;
    const render::PlayerStats stats = render::Player(options).run(replay);
    std::cout << fmt::format("showed {} frames in {:.1f} s\n", stats.framesDrawn, stats.seconds);
    return 0;
  };
}

const bool registered =
    registerCommand({"play", "Replay a run in a window with time code and overlays", "", 41, &setupPlay});

}  // namespace
}  // namespace drape::cli
