#pragma once
// A pose take as it arrives: what a cloth-server simulates against and a player draws the
// body with. The follower reads a pose stream from its start, finds a take's PoseStart,
// checks it against the avatar, and grows an AvatarAnimation frame by frame as PoseFrames
// come, bit for bit the animation the anim-server sent.
//
// It survives what a stream may carry besides: a message that is not a frame (logged,
// skipped), a frame sent twice (dropped), a frame that never came (filled in between its
// neighbours when the next arrives, and logged). A new take on the stream ends the one
// being followed (NewTake); a stream that stays silent longer than the patience given is
// an Unavailable error naming the last frame.

#include <cstdint>
#include <optional>
#include <vector>
#include <stdexcept>
#include <string>

#include "drape/motion/animation.hpp"
#include "drape/scene/avatar.hpp"
#include "drape/studio/bus.hpp"
#include "drape/studio/messages.hpp"
#include "drape/studio/stream_reader.hpp"

namespace drape::studio {

/// Thrown while following a take when the stream starts another.
struct NewTake : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class PoseFollower {
 public:
  /// Follows the takes `stream` reads (from the stream's first message).
  explicit PoseFollower(StreamReader& stream) : stream_(stream) {}

  /// Waits for the next take's PoseStart on the stream (the take `take` only, when given),
  /// checks its joints against `avatar` and its rate against `rate`, and follows it.
  /// Throws drape::Error (BadInput) when the take moves another avatar or at another rate.
  void followNextTake(const scene::Avatar& avatar, double rate, const std::string& take = "");

  /// Waits until the take has `count` frames or has ended; true when it has them. Throws
  /// NewTake when the stream starts another take first.
  bool waitForFrames(std::int64_t count);

  [[nodiscard]] const std::string& take() const { return take_; }
  [[nodiscard]] const PoseStart& start() const { return start_; }
  /// The motion so far (the same object for the whole take: a world may keep a pointer).
  [[nodiscard]] const motion::AvatarAnimation& animation() const { return *animation_; }
  [[nodiscard]] bool ended() const { return ended_; }
  /// Per frame so far, the wind the sender's event graph set (none: the scene's); the same
  /// object for the whole take.
  [[nodiscard]] const std::vector<std::optional<Vec3>>& wind() const { return wind_; }
  /// The frames the take ended with (after ended()).
  [[nodiscard]] std::int64_t frames() const { return static_cast<std::int64_t>(animation_->frameCount()); }
  /// Frames that never came and were filled in, and messages skipped as not frames of the take.
  [[nodiscard]] std::int64_t filledFrames() const { return filled_; }
  [[nodiscard]] std::int64_t skippedMessages() const { return skipped_ + stream_.skipped(); }

 private:
  void add(const PoseFrame& frame);

  StreamReader& stream_;
  std::optional<Message> pending_;  ///< a PoseStart read while following the take before it
  std::string take_;
  PoseStart start_;
  std::optional<motion::AvatarAnimation> animation_;
  std::vector<std::optional<Vec3>> wind_;
  bool ended_ = false;
  std::int64_t filled_ = 0, skipped_ = 0;
};

}  // namespace drape::studio
