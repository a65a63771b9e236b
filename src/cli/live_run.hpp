#pragma once
// A simulation on live motion captures in one process (`drape run --live`, `drape play
// SCENE --live`): each capture's frames become its character's motion as the simulation
// asks for them, with no studio in between. The simulation waits for each frame's motion as
// a cloth-server waits for a pose stream's, and ends when a capture does.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/motion/animation.hpp"
#include "live_capture.hpp"
#include "run_setup.hpp"

namespace drape::cli {

/// What a LiveRun of `character` needs built before its capture is opened, so that the
/// capture's first frames do not wait for it: the part fields of its keep-apart.
void prepareLiveRun(const RunSetup& setup, CharacterSetup& character);

class LiveRun {
 public:
  /// Plays `capture` on `character` of `setup`: its motion becomes the capture's, streamed,
  /// kept apart on its way in where the character keeps parts apart (liveKeepApart: the part
  /// fields are built here, and each frame comes the correction's delay later), and the
  /// capture's first frame is read, which the world is built on. `maxFrames` > 0 ends the
  /// run after that frame whatever the capture sends. Throws drape::Error (Unavailable) when
  /// the capture ends before its first frame.
  LiveRun(RunSetup& setup, CharacterSetup& character, LiveCapture& capture, long maxFrames);

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

/// `--live SOURCE` options of a scene command: the source of the scene's only character, or
/// NAME=SOURCE for each of several (by the scene's names for them). Index of the character
/// in setup.characters, and the source. Throws drape::Error naming the option for a source
/// among several characters that names none, a name the scene lacks, a character given
/// twice, or standard input ("-") twice.
[[nodiscard]] std::vector<std::pair<std::size_t, std::string>> liveSources(const RunSetup& setup,
                                                                           const std::vector<std::string>& options);

/// The characters `sources` leaves out play the motion their Avatar nodes name (or stand):
/// addMotion's, with `metresPerUnit` and `jointMap`.
void addMotionsOfTheOthers(RunSetup& setup, const std::vector<std::pair<std::size_t, std::string>>& sources,
                           const std::string& scenePath, double metresPerUnit = 0.0, const std::string& jointMap = "");

/// Every live capture of a run and its LiveRun, a character each; the run's frames wait for
/// all of them and end when one ends.
class LiveCast {
 public:
  struct Options {
    std::string headerFile;  ///< --live-header, for every source
    std::chrono::milliseconds giveUp{0};
    long maxFrames = 0;
  };
  /// Opens each source in turn (LiveCapture, which waits for its header) and follows it
  /// (LiveRun, which waits for its first frame). Each character's keep-apart fields are
  /// built before its source is opened.
  LiveCast(RunSetup& setup, const std::vector<std::pair<std::size_t, std::string>>& sources, const Options& options,
           const motion::MotionOptions& motion, const std::atomic<bool>& stop);

  /// Whether every capture has what frame `frame` needs (waiting for it); false once one
  /// has ended and its frames are done.
  bool admit(long frame);
  [[nodiscard]] FrameGate gate() {
    return [this](long frame) { return admit(frame); };
  }
  /// The longest lag of the captures' keep-aparts (s).
  [[nodiscard]] double lag_s() const;
  /// A capture went silent past the give-up.
  [[nodiscard]] bool silent() const;
  /// One line per capture: "live: N motion frames from SOURCE (M source frames...)[; how it ended]",
  /// with the character's name among several.
  [[nodiscard]] std::vector<std::string> summary() const;
  /// Logs what each capture's keep-apart changed.
  void logKeptApart() const;
  /// The sources, for messages.
  [[nodiscard]] std::string names() const;

 private:
  struct Member {
    std::string character;
    std::unique_ptr<LiveCapture> capture;
    std::unique_ptr<LiveRun> run;
  };
  std::vector<Member> members_;
  bool several_ = false;
};

}  // namespace drape::cli
