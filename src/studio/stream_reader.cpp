#include "drape/studio/stream_reader.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/core/log.hpp"

namespace drape::studio {
namespace {

Reader openReader(Bus& bus, const std::string& source, const std::string& consumer, std::uint64_t sequence) {
  bus.ensureStream(source);
  return bus.read(source, consumer, sequence);
}

}  // namespace

StreamReader::StreamReader(Bus& bus, std::string source, const std::string& consumer,
                           std::chrono::milliseconds patience, std::chrono::milliseconds giveUp, std::uint64_t sequence)
    : bus_(bus), source_(std::move(source)), consumer_(consumer), reader_(openReader(bus, source_, consumer, sequence)),
      patience_(patience), giveUp_(giveUp) {}

void StreamReader::restartAt(std::uint64_t sequence) {
  reader_.reset();
  reader_.emplace(openReader(bus_, source_, consumer_, std::max<std::uint64_t>(sequence, 1)));
  sequence_ = sequence > 0 ? sequence - 1 : 0;
}

std::optional<Message> StreamReader::at(std::uint64_t sequence) {
  std::optional<Received> r = bus_.get(source_, sequence);
  if (!r) return std::nullopt;
  try {
    Message m = decode(r->data);
    if (m.source == source_) return m;
  } catch (const Error&) {  // not a studio frame: as if the stream held none there
  }
  return std::nullopt;
}

Message StreamReader::next(const std::string& waitingFor) {
  using std::chrono::milliseconds;
  // Waits in slices: up to the next line said (every `patience`), the give-up, and with a
  // stop flag a tenth of a second, so that a stop is seen at once.
  milliseconds waited{0}, saidAt{0};
  for (;;) {
    if (stop_ != nullptr && stop_->load()) throw Stopped(fmt::format("stopped while waiting for {} from '{}'", waitingFor, source_));
    milliseconds slice = std::max(patience_ - (waited - saidAt), milliseconds(1));
    if (giveUp_.count() > 0) slice = std::min(slice, std::max(giveUp_ - waited, milliseconds(1)));
    if (stop_ != nullptr) slice = std::min(slice, milliseconds(100));
    const auto began = std::chrono::steady_clock::now();
    std::optional<Received> r = reader_->next(slice);
    if (!r) {
      waited += std::max(slice, std::chrono::duration_cast<milliseconds>(std::chrono::steady_clock::now() - began));
      if (giveUp_.count() > 0 && waited >= giveUp_)
        throw Error(fmt::format("{}: waited {:.1f} s for {} from '{}'; giving up", bus_.url(),
                                static_cast<double>(waited.count()) / 1000.0, waitingFor, source_),
                    ExitCode::Unavailable);
      if (waited - saidAt >= patience_) {
        saidAt = waited;
        spdlog::info("waiting for {} from '{}' on {} (nothing for {:.0f} s)", waitingFor, source_, bus_.url(),
                     static_cast<double>(waited.count()) / 1000.0);
      }
      continue;
    }
    sequence_ = r->sequence;
    try {
      Message m = decode(r->data);
      if (m.source == source_) return m;
      ++skipped_;
      spdlog::warn("{} message {}: sent by '{}', not '{}'; skipped", subjectOf(source_), r->sequence, m.source, source_);
    } catch (const Error& e) {
      ++skipped_;
      spdlog::warn("{} message {}: {}; skipped", subjectOf(source_), r->sequence, e.what());
    }
  }
}

}  // namespace drape::studio
