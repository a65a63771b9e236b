#pragma once
// A live motion capture (`--live SOURCE`): a BVH read while the capture program writes it,
// from standard input, a TCP server or a named pipe, and retargeted onto an avatar frame by
// frame as it comes (motion/live_motion.hpp). The anim-server sends its frames into a pose
// stream; drape run and drape play simulate on them in one process.
//
//   LiveCapture capture(avatar, {"tcp://127.0.0.1:7001"}, motionOptions(setup), stopOnSignals());
//   while (capture.next(joints)) use(joints);   // every frame at capture.motion().rate()
//   if (capture.silent()) ...                    // it went silent past the give-up
//
// Where the scene keeps parts apart, keepApart() puts the correction between the retargeting
// and next(): each frame then comes out the correction's delay later (sim/keep_apart.hpp).

#include <atomic>
#include <chrono>
#include <memory>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "drape/core/line_stream.hpp"
#include "drape/core/math.hpp"
#include "drape/formats/bvh.hpp"
#include "drape/motion/live_motion.hpp"
#include "drape/scene/avatar.hpp"
#include "drape/sim/keep_apart.hpp"

namespace drape::cli {

/// `--live`'s help: what a SOURCE may be and what is done with it.
inline constexpr const char* kLiveHelp =
    "a BVH written while it is captured, from SOURCE: - (standard input), tcp://HOST:PORT (connected to) or a named "
    "pipe, retargeted as --motion retargets a file (docs/MOTION.md), frame by frame as it comes, until the source "
    "closes or Ctrl-C";
/// `--live-header`'s help.
inline constexpr const char* kLiveHeaderHelp =
    "With --live: the skeleton from this BVH file's header (its frames are not played), for a source that sends "
    "frame lines only, one frame of channel values a line";

class LiveCapture {
 public:
  struct Options {
    std::string source;      ///< --live: -, tcp://HOST:PORT, a named pipe or a file
    std::string headerFile;  ///< --live-header: a BVH file whose skeleton the source has, or ""
    std::chrono::milliseconds patience{5000};  ///< say what is awaited after this long, and again each time
    std::chrono::milliseconds giveUp{0};       ///< 0: wait for a silent source for ever
  };

  /// Opens the source (a TCP server not up yet is tried each second until the give-up or
  /// `stop`), reads its header (or takes the header file's) and sets up the retargeting
  /// onto `avatar`, which must outlive this. Throws drape::Error where the header breaks
  /// (`SOURCE:LINE:COLUMN`), and (Unavailable) for a source that is not there or silent.
  LiveCapture(const scene::Avatar& avatar, const Options& options, const motion::MotionOptions& motion,
              const std::atomic<bool>& stop);

  /// The next pose frame at motion().rate() into `joints` (the avatar's joints' world
  /// transforms), reading the source until there is one: false once the source has ended
  /// (it closed, `stop` was set, or it stayed silent past the give-up) and every frame its
  /// lines make is out. A bad frame line is logged where it is and the frame before it
  /// stands in, so the motion keeps its time.
  bool next(std::span<RigidTransform> joints);

  /// From now on next() gives the frames as `keep` corrects them (null: as they come).
  void keepApart(std::shared_ptr<sim::LiveKeepApart> keep);
  /// The correction keepApart() gave, or null.
  [[nodiscard]] const sim::LiveKeepApart* keptApart() const { return keep_.get(); }

  [[nodiscard]] const motion::LiveMotion& motion() const { return live_; }
  [[nodiscard]] const formats::BvhFile& header() const { return header_; }
  [[nodiscard]] const std::string& name() const { return source_.name(); }
  [[nodiscard]] std::size_t badLines() const { return badLines_; }
  /// It went silent past the give-up.
  [[nodiscard]] bool silent() const { return silent_; }
  /// Why it ended, after next() said false: "" when it closed as a file ends; else its
  /// silence, the signal or the connection's end.
  [[nodiscard]] std::string ended() const;

 private:
  LiveCapture(const scene::Avatar& avatar, const Options& options, const motion::MotionOptions& motion,
              const std::atomic<bool>& stop, std::optional<formats::BvhFile> fileHeader);
  /// next() without the keep-apart: the retargeted frames as they come.
  bool nextRetargeted(std::span<RigidTransform> joints);

  Options options_;
  const std::atomic<bool>& stop_;
  LineStream source_;
  formats::BvhFile header_;
  motion::LiveMotion live_;
  std::vector<double> values_, previous_;
  std::size_t badLines_ = 0;
  bool finished_ = false, silent_ = false;
  std::shared_ptr<sim::LiveKeepApart> keep_;
  std::vector<RigidTransform> retargeted_;  ///< a frame on its way into keep_
  bool keepFinished_ = false;
};

}  // namespace drape::cli
