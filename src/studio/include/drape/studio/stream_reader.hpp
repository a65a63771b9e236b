#pragma once
// One broadcaster's stream read message by message, decoded: what the followers of pose and
// cloth takes share. A message that is not a studio frame, or that another broadcaster
// sent, is logged and skipped (a server survives bad frames); a stream that stays silent
// is waited for, with a line every `patience`, and given up on after `giveUp` (if > 0)
// with an Unavailable error that says what was awaited.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

#include "drape/studio/bus.hpp"
#include "drape/studio/messages.hpp"

namespace drape::studio {

/// Thrown by a reader waiting for a message when the flag it was given is set.
struct Stopped : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class StreamReader {
 public:
  /// Reads `source`'s stream (created if the server has none yet) as the durable consumer
  /// `consumer`, from its message `sequence` (0: its first).
  StreamReader(Bus& bus, std::string source, const std::string& consumer, std::chrono::milliseconds patience,
               std::chrono::milliseconds giveUp, std::uint64_t sequence = 0);

  /// The next message of the stream that is a studio frame of this source; `waitingFor`
  /// names it in the lines said while waiting. Throws Stopped when the flag of stopOn() is
  /// set while it waits.
  [[nodiscard]] Message next(const std::string& waitingFor);
  /// A flag (a signal's, another thread's) that ends a wait within a tenth of a second.
  void stopOn(const std::atomic<bool>* flag) { stop_ = flag; }
  /// The stream's sequence of the message next() returned last (0 before the first).
  [[nodiscard]] std::uint64_t sequence() const { return sequence_; }

  /// Reads on from the stream's message `sequence` (a jump, forwards or back).
  void restartAt(std::uint64_t sequence);
  /// The message at `sequence`, read without moving the reader; nothing where the stream
  /// holds none or it is not a studio frame of this source.
  [[nodiscard]] std::optional<Message> at(std::uint64_t sequence);
  /// What the stream holds now.
  [[nodiscard]] StreamRange range() { return bus_.range(source_); }

  [[nodiscard]] const std::string& source() const { return source_; }
  [[nodiscard]] const std::string& url() const { return bus_.url(); }
  /// Messages skipped as not studio frames of this source.
  [[nodiscard]] std::int64_t skipped() const { return skipped_; }

 private:
  Bus& bus_;
  std::string source_, consumer_;
  // Optional so that a jump closes the old consumer before making its namesake.
  std::optional<Reader> reader_;
  std::uint64_t sequence_ = 0;
  std::chrono::milliseconds patience_, giveUp_;
  std::int64_t skipped_ = 0;
  const std::atomic<bool>* stop_ = nullptr;
};

}  // namespace drape::studio
