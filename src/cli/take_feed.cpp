#include "take_feed.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "drape/studio/pose_follower.hpp"
#include "drape/studio/takes.hpp"

namespace drape::cli {
namespace {

/// Enough frames to even out a draw that comes late, few enough to hold little memory.
constexpr std::size_t kFeedFrames = 8;

std::vector<std::string> garmentNames(const StudioFrames& frames) {
  std::vector<std::string> names;
  for (const studio::GarmentInfo& g : frames.start().garments) names.push_back(g.name);
  return names;
}

}  // namespace

TakeFeed::TakeFeed(StudioFrames& frames, long first, long takes) : frames_(frames) {
  frames_.stopOn(&stop_);
  thread_ = std::thread([this, first, takes] { read(first, takes); });
}

TakeFeed::~TakeFeed() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void TakeFeed::push(Item item) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return stop_ || items_.size() < kFeedFrames; });
  if (stop_) throw studio::Stopped("the window closed");
  items_.push_back(std::move(item));
  changed_.notify_all();
}

void TakeFeed::read(long first, long takes) {
  try {
    // The garments of every take are the first's: the window draws their meshes.
    const std::vector<std::string> shown = garmentNames(frames_);
    for (long take = 0;; ++take) {
      const bool last = takes > 0 && take + 1 >= takes;
      const std::string name = frames_.take();
      const TimeCode start = frames_.start().start;
      try {
        Item item;
        long frame = take == 0 ? first : 0;
        for (; !stop_ && frames_.next(frame, item.taken); ++frame) {
          item.take = static_cast<std::size_t>(take);
          item.takeName = name;
          item.time = TimeCode{start.frame + frame, start.rate};
          push(item);
        }
        if (!last) spdlog::info("take {}: its {} frames read; waiting for the next take", name, frame);
      } catch (const studio::NewTake& e) {
        spdlog::warn("take {} cut short: {}", name, e.what());
      } catch (const Error& e) {
        if (last) throw;
        spdlog::error("take {}: {}", name, e.what());  // a player goes on to the next take
      }
      if (last || stop_) break;
      frames_.followNextTake();
      if (const std::vector<std::string> now = garmentNames(frames_); now != shown)
        throw Error(fmt::format("take {} sends {}, where the window shows {}: start a player for it", frames_.take(),
                                fmt::join(now, ", "), fmt::join(shown, ", ")));
    }
  } catch (const studio::Stopped&) {  // the window closed: nobody waits for the end
  } catch (...) {
    const std::lock_guard lock(mutex_);
    failure_ = std::current_exception();
  }
  const std::lock_guard lock(mutex_);
  ended_ = true;
  changed_.notify_all();
}

bool TakeFeed::ready() {
  const std::lock_guard lock(mutex_);
  return ended_ || !items_.empty();
}

std::optional<TakeFeed::Item> TakeFeed::next(std::optional<Latest> latest, long* left) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return ended_ || !items_.empty(); });
  if (items_.empty()) {
    if (failure_) std::rethrow_exception(std::exchange(failure_, nullptr));
    return std::nullopt;
  }
  std::optional<Item> out = std::move(items_.front());
  items_.pop_front();
  // A new take is shown from its first frame: its time starts there.
  while (latest && out->take == latest->take && !items_.empty() && items_.front().take == latest->take &&
         items_.front().taken.frame <= latest->frame) {
    out = std::move(items_.front());
    items_.pop_front();
    if (left != nullptr) ++*left;
  }
  changed_.notify_all();
  return out;
}

}  // namespace drape::cli
