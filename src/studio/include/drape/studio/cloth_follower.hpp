#pragma once
// A cloth take as it arrives, gathered by frame: a player waits for every garment of a
// frame and then has it whole. Several cloth-servers may each simulate some of a scene's
// garments (docs/STUDIO.md); a player follows each of their streams with one of these and
// collates their frames by frame number, which is the time code less the take's start.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "drape/studio/messages.hpp"
#include "drape/studio/stream_reader.hpp"

namespace drape::studio {

class ClothFollower {
 public:
  explicit ClothFollower(StreamReader& stream) : stream_(stream) {}

  /// Waits for the next take's ClothStart on the stream (the take `take` only, when given).
  const ClothStart& followNextTake(const std::string& take = "");

  /// Waits until every garment of cloth frame `frame` is there; false when the take ended
  /// before it. Frames before `frame` are forgotten. Throws NewTake (pose_follower.hpp)
  /// when the stream starts another take first, and drape::Error with the take's own
  /// error when its server stopped it (a garment went unstable).
  bool waitForFrame(std::int64_t frame);
  /// Garment `garment` of the frame waitForFrame last had.
  [[nodiscard]] const ClothFrame& garment(std::uint32_t garment) const;

  [[nodiscard]] const std::string& take() const { return take_; }
  [[nodiscard]] const ClothStart& start() const { return start_; }
  [[nodiscard]] bool ended() const { return end_.has_value(); }
  /// The take's End, once it came.
  [[nodiscard]] const std::optional<End>& end() const { return end_; }
  [[nodiscard]] std::int64_t skippedMessages() const { return skipped_ + stream_.skipped(); }

 private:
  /// Reads one message of the take into the frames gathered.
  void readOne(const std::string& waitingFor);

  StreamReader& stream_;
  std::optional<Message> pending_;
  std::string take_;
  ClothStart start_;
  std::map<std::int64_t, std::vector<std::optional<ClothFrame>>> frames_;
  std::int64_t current_ = -1;
  std::optional<End> end_;
  std::int64_t skipped_ = 0;
};

}  // namespace drape::studio
