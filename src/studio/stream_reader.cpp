#include "drape/studio/stream_reader.hpp"

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
    : bus_(bus), source_(std::move(source)), reader_(openReader(bus, source_, consumer, sequence)), patience_(patience),
      giveUp_(giveUp) {}

Message StreamReader::next(const std::string& waitingFor) {
  std::chrono::milliseconds waited{0};
  for (;;) {
    std::optional<Received> r = reader_.next(patience_);
    if (!r) {
      waited += patience_;
      if (giveUp_.count() > 0 && waited >= giveUp_)
        throw Error(fmt::format("{}: no {} came from '{}' for {:g} s; giving up", bus_.url(), waitingFor, source_,
                                static_cast<double>(waited.count()) / 1000.0),
                    ExitCode::Unavailable);
      spdlog::info("waiting for {} from '{}' on {} (nothing for {:g} s)", waitingFor, source_, bus_.url(),
                   static_cast<double>(waited.count()) / 1000.0);
      continue;
    }
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
