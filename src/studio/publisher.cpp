#include "drape/studio/publisher.hpp"

#include <thread>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "drape/studio/takes.hpp"

namespace drape::studio {

Publisher::Publisher(Bus& bus, std::string source, Precision precision, std::chrono::milliseconds giveUp)
    : bus_(bus), source_(std::move(source)), precision_(precision), giveUp_(giveUp) {
  bus_.ensureStream(source_);
}

std::string Publisher::idOf(const Payload& payload) const {
  struct Id {
    const std::string& take;
    std::string operator()(const PoseStart&) const { return messageId(take, "start", 0); }
    std::string operator()(const ClothStart&) const { return messageId(take, "start", 0); }
    std::string operator()(const PoseFrame& p) const { return messageId(take, "pose", p.frame); }
    std::string operator()(const ClothFrame& c) const { return messageId(take, "cloth", c.frame, c.garment); }
    std::string operator()(const End&) const { return messageId(take, "end", 0); }
    // Requests and answers are not a take's messages; a broadcaster never sends them.
    std::string operator()(const Inject&) const { return messageId(take, "inject", 0); }
    std::string operator()(const InjectReply&) const { return messageId(take, "reply", 0); }
  };
  return std::visit(Id{take_}, payload);
}

std::uint64_t Publisher::beginTake(const std::string& take, const Payload& start) {
  take_ = take;
  index_ = 0;
  held_ = 0;
  complete_ = false;
  const StreamRange range = bus_.range(source_);
  if (range.messages > 0) {
    // Does the stream hold this take's beginning? Then it holds a prefix of what this take
    // sends, in order: a server stops between two messages, never inside one.
    bool same = false;
    if (const std::optional<Received> first = bus_.get(source_, range.first)) {
      try {
        const Message m = decode(first->data);
        same = m.take == take && m.source == source_ && m.payload.index() == start.index();
      } catch (const Error&) {
        same = false;
      }
    }
    if (same) {
      held_ = range.messages;
      if (const std::optional<Received> last = bus_.get(source_, range.last)) {
        try {
          complete_ = std::holds_alternative<End>(decode(last->data).payload);
        } catch (const Error&) {
          complete_ = false;
        }
      }
      spdlog::info("{}: the stream already holds {} messages of take {}; sending the rest", subjectOf(source_), held_,
                   take);
    } else {
      bus_.purge(source_);
    }
  }
  send(start);
  return held_;
}

void Publisher::send(const Payload& payload) {
  const std::uint64_t index = index_++;
  if (index < held_) return;
  const std::vector<std::uint8_t> bytes = encode(Message{source_, take_, payload}, precision_);
  const std::string id = idOf(payload);
  const auto began = std::chrono::steady_clock::now();
  for (bool said = false;; said = true) {
    try {
      (void)bus_.publish(source_, bytes, id);
      if (said) spdlog::info("{}: the server takes messages again", subjectOf(source_));
      return;
    } catch (const Error& e) {
      // Sent again under the same id: the stream keeps it once if the first did arrive.
      if (e.code() != ExitCode::Unavailable ||
          (giveUp_.count() > 0 && std::chrono::steady_clock::now() - began > giveUp_))
        throw;
      if (!said) spdlog::warn("{}; sending it again until the server takes it", e.what());
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
    }
  }
}

}  // namespace drape::studio
