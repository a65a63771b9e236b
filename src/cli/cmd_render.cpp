// `drape render OUTDIR --png DIR [--video out.mp4] [--contact-sheet sheet.png] [--size WxH]`:
// pictures of a finished run, rendered headless (EGL surfaceless; no display needed).

#include <cstdint>
#include <filesystem>
#include <iostream>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <unistd.h>

#include <fmt/format.h>

#include "command.hpp"
#include "drape/core/error.hpp"
#include "drape/render/outputs.hpp"
#include "frame_range.hpp"
#include "render_options.hpp"
#include "run_setup.hpp"

namespace drape::cli {
namespace {

struct RenderOptions {
  std::string run;
  std::vector<std::string> motions;
  std::string animation;
  std::string runOut;
  long frames = 0;
  std::string range;
  std::string png;
  std::string video;
  std::string sheet;
  std::string sheetSize = "1920x1080";
  bool noHud = false;
  double orbit = 0.0;
  PictureOptions picture;
};

RunFunction setupRender(CLI::App& app) {
  static RenderOptions o;
  app.add_option("run", o.run, "A run directory (with manifest.json), as drape run --out writes, or a scene to simulate")
      ->required();
  app.add_option("--motion", o.motions, std::string("With a scene: motion for its avatar ") + kMotionHelp +
                                            kMotionPerCharacterHelp)
      ->type_name("FILE|NAME=FILE");
  app.add_option("--animation", o.animation, kAnimationHelp);
  app.add_option("--frames", o.frames,
                 "With a scene: frames to simulate, counted from the lead-in's first (default: the lead-in and the "
                 "whole motion)");
  app.add_option("--run-out", o.runOut, "With a scene: keep the simulated run in this directory (default: a temporary one)");
  app.add_option("--range", o.range,
                 "Only the run's frames FIRST:LAST (0-based, inclusive; FIRST: to the end; one FRAME), for every output; the "
                 "camera frames the whole run");
  app.add_option("--png", o.png, "Write every frame as DIR/frame_00000.png ...");
  app.add_option("--video", o.video, "Encode every frame as an H.264 MP4 (needs the ffmpeg command)");
  app.add_option("--contact-sheet", o.sheet, "Write a 4x4 grid of evenly spaced frames with their time codes");
  app.add_option("--sheet-size", o.sheetSize, "Contact sheet size WIDTHxHEIGHT")->capture_default_str();
  app.add_flag("--no-hud", o.noHud, "No time code or frame number on PNG and video frames");
  app.add_option("--orbit", o.orbit, "Turn the camera this many degrees about the vertical over the run");
  o.picture.add(app);
  app.footer(
      "Renders without a display (EGL surfaceless, Mesa llvmpipe). At least one of --png, --video,\n"
      "--contact-sheet is needed.");
  return [] {
    if (o.png.empty() && o.video.empty() && o.sheet.empty()) {
      throw Error("drape render: nothing to write: give --png DIR, --video FILE.mp4 or --contact-sheet FILE.png");
    }
    render::RenderJob job;
    if (!o.range.empty()) {
      const FrameRange range = parseFrameRange(o.range);
      job.firstFrame = range.first;
      job.lastFrame = range.last;
    }
    // A scene is simulated first, exactly as `drape run` does, into a run directory.
    std::string runDir = o.run;
    std::filesystem::path scratch;
    if (std::filesystem::is_regular_file(o.run)) {
      RunSetup setup = runSetupFromScene(o.run);
      addSceneMotions(setup, o.run, o.motions, o.animation);
      setup.frames = o.frames > 0 ? o.frames : defaultFrames(setup);
      if (o.frames > 0) warnOfFramesWithinTheLeadIn(setup, {o.frames, o.frames, "renders", false});
      if (o.runOut.empty()) {
        scratch = std::filesystem::temp_directory_path() / fmt::format("drape-render-{}", ::getpid());
        runDir = scratch.string();
      } else {
        runDir = o.runOut;
      }
      setup.outDir = runDir;
      setup.objEvery = setup.frames;
      (void)simulateRun(setup);
    } else if (!o.motions.empty() || !o.animation.empty()) {
      throw Error(fmt::format("{}: drape render takes a motion only with a scene file, not a run directory",
                              o.motions.empty() ? "--animation" : "--motion"));
    } else if (o.frames > 0) {
      throw Error("--frames: drape render simulates frames only from a scene file; for some of a run's frames, "
                  "--range FIRST:LAST");
    }
    std::tie(job.width, job.height) = o.picture.parsedSize();
    std::tie(job.sheetWidth, job.sheetHeight) = PictureOptions::parseSize(o.sheetSize, "--sheet-size");
    job.pngDirectory = o.png;
    job.videoPath = o.video;
    job.contactSheet = o.sheet;
    job.hud = !o.noHud;
    job.orbitDeg = o.orbit;
    job.follow = o.picture.follow;
    job.subdivisionLevels = o.picture.subdivide;
    job.view = o.picture.view();
    job.overlay = o.picture.overlay();
    const render::RenderSummary summary = render::renderRun(runDir, job);
    if (!scratch.empty()) {
      std::error_code ec;
      std::filesystem::remove_all(scratch, ec);
    }
    const char* frames = summary.frames == 1 ? "frame" : "frames";
    if (!o.png.empty()) std::cout << fmt::format("wrote {} {} to {}/\n", summary.frames, frames, o.png);
    if (!o.video.empty()) std::cout << fmt::format("wrote {} ({} {})\n", o.video, summary.frames, frames);
    if (!o.sheet.empty())
      std::cout << fmt::format("wrote {} (frames {})\n", o.sheet, fmt::join(summary.sheetFrames, " "));
    std::cerr << fmt::format("rendered in {:.1f} s with {}\n", summary.seconds, summary.glDescription);
    return 0;
  };
}

const bool registered_cmd_render = registerCommand(
    {"render", "Render a run (or simulate a scene and render it) to PNG, video and a contact sheet (headless)", "", 40, &setupRender});

}  // namespace
}  // namespace drape::cli
