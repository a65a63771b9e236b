#pragma once
// A broadcaster's side of a stream: an anim-server's poses, a cloth-server's garments.
// Each take replaces the last one in the stream (a reader finds one take there, from its
// start), unless the stream already holds the beginning of this very take: then a server
// restarted in the middle of a take (after a crash, or on another machine) computes the
// take again from its start, as the simulation is deterministic, and sends only what the
// stream does not hold yet. Every message also carries an id, so that the stream drops one
// sent twice within its duplicate window.

#include <chrono>
#include <cstdint>
#include <string>

#include "drape/studio/bus.hpp"
#include "drape/studio/messages.hpp"

namespace drape::studio {

class Publisher {
 public:
  /// A message the server does not take (it is restarting, or out of reach) is sent again,
  /// under the same id, until it is taken, for at most `giveUp` (0: for ever); then the
  /// error is thrown.
  Publisher(Bus& bus, std::string source, Precision precision = Precision::Double,
            std::chrono::milliseconds giveUp = std::chrono::milliseconds(0));

  /// Starts take `take` with its PoseStart or ClothStart. Returns the messages of it the
  /// stream already held (0 for a new take: the stream was emptied for it).
  std::uint64_t beginTake(const std::string& take, const Payload& start);
  /// The take's next message (frames in order, then its End); sent unless the stream
  /// already holds it.
  void send(const Payload& payload);

  [[nodiscard]] const std::string& source() const { return source_; }
  [[nodiscard]] const std::string& take() const { return take_; }
  /// Messages of this take sent, and of those, how many the stream held already.
  [[nodiscard]] std::uint64_t sent() const { return index_; }
  [[nodiscard]] std::uint64_t held() const { return held_; }
  /// The stream held this take to its End already: there is nothing left to send.
  [[nodiscard]] bool complete() const { return complete_; }

 private:
  [[nodiscard]] std::string idOf(const Payload& payload) const;

  Bus& bus_;
  std::string source_;
  Precision precision_;
  std::chrono::milliseconds giveUp_;
  std::string take_;
  std::uint64_t held_ = 0;   ///< messages of this take the stream held when it began
  std::uint64_t index_ = 0;  ///< messages of this take sent so far, held ones included
  bool complete_ = false;
};

}  // namespace drape::studio
