#pragma once
// The interactive player: a GLFW window with the renderer and the Dear ImGui overlay
// (time code, frame, fps, ms per stage, overlay toggles). It plays any FrameSource: a run
// directory (RunReplay) or a live simulation (CallbackSource).
//
//   render::CallbackSource live(meshes, 30.0, [&](render::Frame& f) { return sim.step(f); });
//   render::Player(render::PlayerOptions{}).run(live);
//
// Mouse: drag to orbit, wheel to zoom. Keys: space pause, left/right step (paused),
// F follow the characters or frame all seen so far, R reset the view, Esc or Q quit.

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "drape/render/frame.hpp"
#include "drape/render/renderer.hpp"

namespace drape::render {

struct PlayerOptions {
  int width = 1280;
  int height = 720;
  std::string title = "drape";
  std::optional<std::int64_t> maxFrames;  ///< close by itself after drawing this many frames
  bool loop = true;                       ///< a replay starts over at its end (a live source ends the player)
  bool realTime = true;                   ///< advance at the source's frame rate; false: one frame per redraw
  ViewSettings view;
  bool follow = false;  ///< the camera follows the characters; F toggles it
  /// Per frame index, the follow camera's framing when the whole run is known beforehand
  /// (followFraming: centred, no lag); empty: the live FollowCamera, which eases after each frame.
  std::vector<Aabb> followFraming;
  OverlaySettings overlay;
  std::string screenshot;  ///< "": none; else the last picture the window showed, as PNG
  /// Set (by a signal handler, another thread): the window closes as if its user closed it.
  const std::atomic<bool>* close = nullptr;
};

struct PlayerStats {
  std::int64_t framesDrawn = 0;
  double seconds = 0.0;  ///< wall time the window was open
};

class Player {
 public:
  explicit Player(PlayerOptions options) : options_(std::move(options)) {}
  /// Opens the window and plays until it is closed, the live source ends or maxFrames
  /// frames were drawn. Throws drape::Error when no display or GL 3.3 context is available.
  PlayerStats run(FrameSource& source);

 private:
  PlayerOptions options_;
};

}  // namespace drape::render
