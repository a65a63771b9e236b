#include "drape/studio/cloth_follower.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "drape/studio/pose_follower.hpp"

namespace drape::studio {

const ClothStart& ClothFollower::followNextTake(const std::string& take) {
  for (;;) {
    Message m = pending_ ? std::move(*pending_) : stream_.next("a take's cloth");
    pending_.reset();
    const auto* start = std::get_if<ClothStart>(&m.payload);
    if (start == nullptr || (!take.empty() && m.take != take)) continue;  // an earlier take's frames
    take_ = m.take;
    start_ = *start;
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
  if (std::holds_alternative<ClothStart>(m.payload)) {
    if (m.take == take_) return;  // the same take announced again (a restarted server)
    pending_ = std::move(m);
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

const ClothFrame& ClothFollower::garment(std::uint32_t garment) const {
  return *frames_.at(current_).at(garment);
}

}  // namespace drape::studio
