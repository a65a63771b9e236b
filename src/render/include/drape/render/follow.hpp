#pragma once
// A camera that follows the characters: what it frames on each frame, so that a walk
// across a room fills the picture instead of crossing a wide, far shot of the whole run.
// The framing keeps one size and one height range over the run (no zooming, no bobbing
// horizon, the floor stays put) and moves only horizontally, smoothly.
//
//   const std::vector<Aabb> boxes = followFraming(perFrameBounds, 30.0);
//   view.bounds = boxes[i];  // the renderer looks at its centre from far enough to see it

#include <vector>

#include "drape/core/math.hpp"

namespace drape::render {

class RunReplay;

/// One framing box per frame of a finished run (offline: it sees the whole run). Each is
/// centred horizontally on the mean of the frames' centres within `window_s` around it (a
/// window that narrows at the ends, so a steady walk is followed without lag), spans the
/// run's heights, and is as wide as needed for every frame's box to lie inside its own
/// framing box. An empty frame box takes its predecessor's (the first non-empty one at the
/// start). Throws drape::Error when every box is empty or the frame rate is not positive.
[[nodiscard]] std::vector<Aabb> followFraming(const std::vector<Aabb>& frameBoxes, double frameRate,
                                              double window_s = 1.0);

/// followFraming of every frame of a run directory, at its frame rate.
[[nodiscard]] std::vector<Aabb> followFraming(const RunReplay& replay);

/// The live form (the player: frames arrive one at a time): the centre eases toward each
/// frame's centre with time constant `timeConstant_s`; the size and the height range grow
/// to hold every frame seen, so they settle after the first steps and then stay.
class FollowCamera {
 public:
  explicit FollowCamera(double timeConstant_s = 0.25) : timeConstant_s_(timeConstant_s) {}
  /// The framing box after a frame whose bounds are `frameBox`, `dt_s` after the last one.
  /// An empty frame box leaves the framing as it was.
  Aabb update(const Aabb& frameBox, double dt_s);
  [[nodiscard]] const Aabb& framing() const { return framing_; }

 private:
  [[nodiscard]] Aabb frame() const;

  double timeConstant_s_;
  bool started_ = false;
  double centreX_ = 0, centreZ_ = 0;
  double halfWidth_ = 0;  ///< horizontal half size, the same along x and z (any azimuth)
  double minY_ = 0, maxY_ = 0;
  Aabb framing_;
};

}  // namespace drape::render
