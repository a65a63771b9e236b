#include "drape/studio/cloth_follower.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "drape/studio/pose_follower.hpp"

namespace drape::studio {

const ClothStart& ClothFollower::followNextTake(const std::string& take, const std::string& after) {
  for (;;) {
    const bool wasPending = pending_.has_value();
    Message m = wasPending ? std::move(*pending_) : stream_.next("a take's cloth");
    const std::uint64_t sequence = wasPending ? pendingSequence_ : stream_.sequence();
    if (!wasPending) ++read_;
    pending_.reset();
    const auto* start = std::get_if<ClothStart>(&m.payload);
    if (start == nullptr || (!take.empty() && m.take != take)) continue;  // an earlier take's frames
    if (!after.empty() && m.take == after) continue;
    take_ = m.take;
    start_ = *start;
    startSequence_ = sequence;
    frames_.clear();
    current_ = -1;
    end_.reset();
    skipped_ = 0;
    spdlog::info("following cloth take {} from '{}': {} garment{} on {}, poses from '{}'", take_, stream_.source(),
                 start_.garments.size(), start_.garments.size() == 1 ? "" : "s", start_.character, start_.poses);
    return start_;
  }
}

void ClothFollower::readOne(const std::string& waitingFor) {
  Message m = stream_.next(waitingFor);
  ++read_;
  if (std::holds_alternative<ClothStart>(m.payload)) {
    if (m.take == take_) return;  // the same take announced again (a restarted server)
    pending_ = std::move(m);
    pendingSequence_ = stream_.sequence();
    throw NewTake(fmt::format("the cloth stream '{}' started take {} before take {} ended", stream_.source(),
                              pending_->take, take_));
  }
  if (m.take != take_) {
    ++skipped_;
    return;
  }
  if (const auto* end = std::get_if<End>(&m.payload)) {
    end_ = *end;
    return;
  }
  auto* frame = std::get_if<ClothFrame>(&m.payload);
  if (frame == nullptr) {
    ++skipped_;
    spdlog::warn("cloth take {}: a {} on the cloth stream; skipped", take_, describe(m.payload));
    return;
  }
  if (frame->garment >= start_.garments.size() || frame->positions.size() != start_.garments[frame->garment].vertices) {
    ++skipped_;
    spdlog::warn("cloth take {}: frame {} of garment {} does not fit the take's garments; skipped", take_, frame->frame,
                 frame->garment);
    return;
  }
  if (frame->frame <= current_) return;  // sent again
  std::vector<std::optional<ClothFrame>>& slots = frames_[frame->frame];
  slots.resize(start_.garments.size());
  slots[frame->garment] = std::move(*frame);
}

bool ClothFollower::waitForFrame(std::int64_t frame) {
  frames_.erase(frames_.begin(), frames_.lower_bound(frame));
  current_ = frame - 1;
  const auto whole = [&] {
    const auto it = frames_.find(frame);
    return it != frames_.end() &&
           std::all_of(it->second.begin(), it->second.end(), [](const auto& g) { return g.has_value(); });
  };
  while (!whole()) {
    if (end_) {
      if (!end_->error.empty())
        throw Error(fmt::format("cloth take {} from '{}' stopped after frame {}: {}", take_, stream_.source(),
                                end_->frames, end_->error),
                    end_->exitCode > 0 ? static_cast<ExitCode>(end_->exitCode) : ExitCode::Internal);
      return false;
    }
    readOne(fmt::format("cloth frame {} of take {}", frame, take_));
  }
  current_ = frame;
  return true;
}

std::optional<std::int64_t> ClothFollower::frameFrom(std::uint64_t sequence, std::uint64_t last) {
  // Between two frames there may be a restarted server's ClothStart again, or a message
  // that is not a frame: a few steps over them; a run of more ends the take as far as a
  // search cares.
  constexpr std::uint64_t kLookAhead = 8;
  for (std::uint64_t s = sequence; s <= last && s < sequence + kLookAhead; ++s) {
    const std::optional<Message> m = stream_.at(s);
    if (!m) continue;
    if (m->take != take_) {
      if (std::holds_alternative<ClothStart>(m->payload)) return std::nullopt;  // the next take
      continue;
    }
    if (std::holds_alternative<End>(m->payload)) return std::nullopt;
    if (const auto* f = std::get_if<ClothFrame>(&m->payload)) return f->frame;
  }
  return std::nullopt;
}

ClothFollower::Held ClothFollower::held() {
  Held out;
  if (end_) out.ended = end_->frames;
  const StreamRange range = stream_.range();
  // From the stream's end back to the newest frame of the take: past its End (and its
  // stats) or, live, at once.
  for (std::uint64_t s = range.last; s > startSequence_ && s >= range.first && s > 0; --s) {
    const std::optional<Message> m = stream_.at(s);
    if (!m || m->take != take_) continue;
    if (const auto* end = std::get_if<End>(&m->payload)) {
      out.ended = end->frames;
      continue;
    }
    if (const auto* f = std::get_if<ClothFrame>(&m->payload)) {
      // Garments go out in order: a frame is whole once its last garment is there.
      out.newest = f->garment + 1 == start_.garments.size() ? f->frame : f->frame - 1;
      break;
    }
  }
  return out;
}

void ClothFollower::seek(std::int64_t frame) {
  const StreamRange range = stream_.range();
  // lo: a message before the frame (the take's start at first); hi: one at or after it.
  std::uint64_t lo = startSequence_, hi = range.last + 1;
  while (hi - lo > 1) {
    const std::uint64_t mid = lo + (hi - lo) / 2;
    const std::optional<std::int64_t> f = frameFrom(mid, range.last);
    if (f && *f < frame)
      lo = mid;
    else
      hi = mid;
  }
  frames_.clear();
  pending_.reset();
  end_.reset();  // read again, if the jump was back from it
  current_ = frame - 1;
  stream_.restartAt(lo + 1);
  spdlog::debug("cloth take {}: frame {} begins at message {} of '{}'", take_, frame, lo + 1, stream_.source());
}

const ClothFrame& ClothFollower::garment(std::uint32_t garment) const {
  return *frames_.at(current_).at(garment);
}

}  // namespace drape::studio
