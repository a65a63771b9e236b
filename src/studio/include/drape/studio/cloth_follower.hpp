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

  /// Waits for the next take's ClothStart on the stream (the take `take` only, when given),
  /// passing over those of the take `after` (the one followed before, which the stream
  /// holds until another replaces it, and which a restarted server may announce again).
  const ClothStart& followNextTake(const std::string& take = "", const std::string& after = "");

  /// Waits until every garment of cloth frame `frame` is there; false when the take ended
  /// before it. Frames before `frame` are forgotten. Throws NewTake (pose_follower.hpp)
  /// when the stream starts another take first, and drape::Error with the take's own
  /// error when its server stopped it (a garment went unstable).
  bool waitForFrame(std::int64_t frame);
  /// What the stream holds of the take followed now: its newest whole frame (-1: none
  /// yet) and, when its End came, the frames it had.
  struct Held {
    std::int64_t newest = -1;
    std::optional<std::int64_t> ended;
  };
  [[nodiscard]] Held held();
  /// Jumps ahead (or back) to frame `frame` of the take without reading what lies before
  /// it: finds where the frame begins in the stream by a binary search over its sequence
  /// (the cloth-servers send a take's frames in order) and reads on from there. A jump
  /// forgets the frames gathered; the next waitForFrame asks for `frame` or later.
  void seek(std::int64_t frame);
  /// Messages of the stream read so far (the ones a seek jumps over are not read).
  [[nodiscard]] std::int64_t messagesRead() const { return read_; }

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
  /// The frame number of the first cloth frame of the take at or after `sequence`, looking
  /// at no more than a few messages; nothing when there is none (the take's End, another
  /// take, the stream's end).
  [[nodiscard]] std::optional<std::int64_t> frameFrom(std::uint64_t sequence, std::uint64_t last);

  StreamReader& stream_;
  std::optional<Message> pending_;
  std::uint64_t pendingSequence_ = 0;
  std::uint64_t startSequence_ = 0;  ///< where the take's ClothStart is in the stream
  std::int64_t read_ = 0;
  std::string take_;
  ClothStart start_;
  std::map<std::int64_t, std::vector<std::optional<ClothFrame>>> frames_;
  std::int64_t current_ = -1;
  std::optional<End> end_;
  std::int64_t skipped_ = 0;
};

}  // namespace drape::studio
