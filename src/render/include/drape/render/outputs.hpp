#pragma once
// Pictures of a run: PNG frames, an MP4 through the ffmpeg command, a 4x4 contact sheet
// of evenly spaced frames labelled with their time codes.

#include <cstdint>
#include <string>
#include <vector>

#include "drape/render/display_surface.hpp"
#include "drape/render/frame.hpp"
#include "drape/render/renderer.hpp"

namespace drape::render {

struct RenderJob {
  int width = 1280;
  int height = 720;
  std::string pngDirectory;  ///< "": no PNG frames; else DIR/frame_00000.png ...
  std::string videoPath;     ///< "": no video; else an H.264 MP4 at the run's frame rate
  std::string contactSheet;  ///< "": none; else a PNG of 16 tiles (4x4) with time codes
  int sheetWidth = 1920;     ///< contact sheet size
  int sheetHeight = 1080;
  bool hud = true;  ///< time code and frame on PNG and video frames
  double orbitDeg = 0.0;  ///< the camera turns this far about the vertical from first to last frame
  bool follow = false;    ///< the camera follows the characters (followFraming) instead of framing the whole run
  /// The run's frames to render, 0-based and inclusive (`drape render --range`); the last
  /// one negative: to the end. The camera frames the whole run either way, so a frame looks
  /// the same whichever range it is rendered in, and PNG files keep the run's frame numbers.
  std::int64_t firstFrame = 0;
  std::int64_t lastFrame = -1;
  /// Garments drawn as Loop subdivision surfaces of this many refinements (0: the simulated
  /// meshes as they are; display_surface.hpp).
  int subdivisionLevels = kDefaultSubdivisionLevels;
  ViewSettings view;
  OverlaySettings overlay;
};

struct RenderSummary {
  std::int64_t frames = 0;                ///< frames rendered for PNG/video
  std::vector<std::int64_t> sheetFrames;  ///< frame indices on the contact sheet
  double seconds = 0.0;                   ///< wall time
  std::string glDescription;              ///< the OpenGL implementation that rendered
};

/// Renders a run directory (see RunReplay) as the job asks. Throws drape::Error on a bad
/// run, a range outside it, an unwritable path, or an ffmpeg failure (with its last message
/// line).
RenderSummary renderRun(const std::string& runDirectory, const RenderJob& job);

/// The 16 frame indices a contact sheet of `frames` frames shows: evenly spaced from the
/// first to the last (repeats when there are fewer than 16 frames).
[[nodiscard]] std::vector<std::int64_t> contactSheetFrames(std::int64_t frames);

/// True when the ffmpeg command can be run.
[[nodiscard]] bool ffmpegAvailable();

struct PreviewFiles {
  std::string contactSheet;  ///< DIR/preview.png
  std::string video;         ///< DIR/preview.mp4, or "" when ffmpeg is not installed
};
/// What `drape run --preview` adds to a run directory: a contact sheet and, when ffmpeg
/// exists, an MP4 of every frame (1280x720), both with a camera that follows the characters.
PreviewFiles renderPreview(const std::string& runDirectory);

}  // namespace drape::render
