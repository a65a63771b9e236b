#pragma once
// A simulation on a live motion capture in one process (`drape run --live`, `drape play
// SCENE --live`): the capture's frames become the avatar's motion as the simulation asks
// for them, with no studio in between. The simulation waits for each frame's motion as a
// cloth-server waits for a pose stream's, and ends when the capture does.

#include <cstdint>
#include <memory>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/motion/animation.hpp"
#include "live_capture.hpp"
#include "run_setup.hpp"

namespace drape::cli {

/// What a LiveRun on `setup` needs built before its capture is opened, so that the capture's
/// first frames do not wait for it: the part fields of its keep-apart.
void prepareLiveRun(RunSetup& setup);

class LiveRun {
 public:
  /// Plays `capture` on `setup`'s character (which must have an avatar): the setup's motion
  /// becomes the capture's, streamed, kept apart on its way in where the character keeps
  /// parts apart (liveKeepApart: the part fields are built here, and each frame comes the
  /// correction's delay later), and the capture's first frame is read, which the world is
  /// built on. `maxFrames` > 0 ends the run after that frame whatever the capture sends.
  /// Throws drape::Error (Unavailable) when the capture ends before its first frame.
  LiveRun(RunSetup& setup, LiveCapture& capture, long maxFrames);

  /// simulateInto's gate: waits until the motion frame `frame`'s substeps read has come;
  /// false once the capture has ended and the frames its motion makes are done.
  bool admit(long frame);
  [[nodiscard]] FrameGate gate() {
    return [this](long frame) { return admit(frame); };
  }

  /// How long after it was captured a frame comes (s): the keep-apart's delay, or 0.
  [[nodiscard]] double lag_s() const { return lag_s_; }

  /// Motion frames so far.
  [[nodiscard]] std::int64_t motionFrames() const { return static_cast<std::int64_t>(animation_->frameCount()); }

 private:
  /// Reads the capture until the motion has `count` frames or it ends; true when it has them.
  bool waitForFrames(std::int64_t count);

  LiveCapture& capture_;
  std::shared_ptr<motion::AvatarAnimation> animation_;
  std::vector<RigidTransform> joints_;
  double frameRate_, leadIn_s_, lag_s_ = 0.0;
  long maxFrames_;
  bool ended_ = false;
};

}  // namespace drape::cli
