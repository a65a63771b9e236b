#pragma once
// The frames a player's window shows, read from the studio's streams on a thread of their
// own: take after take, so that the window stays live (it turns, zooms and closes) while a
// frame or the next take is awaited, and so that a new take follows the last one in it.

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "drape/core/timecode.hpp"
#include "frames_ahead.hpp"
#include "studio_frames.hpp"

namespace drape::cli {

class TakeFeed {
 public:
  /// One frame of one take.
  struct Item {
    FrameTaken taken;
    std::size_t take = 0;   ///< which take of the feed (0: the first)
    std::string takeName;
    TimeCode time;          ///< the frame's time code
  };

  /// Reads on from frame `first` of the take `frames` follows, then follows the next take
  /// until `takes` have been read (0: for ever). A take whose garments differ from the
  /// first's ends the feed with an error, as does a take's own error when it is the last
  /// (a garment went unstable: the frames before it come first); a take cut short by the
  /// next one, or an error of a take with more to follow, is logged and the feed goes on.
  TakeFeed(StudioFrames& frames, long first, long takes);
  /// Stops the reading where it waits (within a tenth of a second) and joins it.
  ~TakeFeed();
  TakeFeed(const TakeFeed&) = delete;
  TakeFeed& operator=(const TakeFeed&) = delete;

  /// Whether next() has something at once: a frame, or the end.
  [[nodiscard]] bool ready();
  /// How far a window that keeps to the take's time may jump: of the frames already
  /// there up to frame `frame` of take `take`, the newest.
  struct Latest {
    std::size_t take = 0;
    long frame = 0;
  };
  /// Waits for the next frame: nothing after the last, or rethrows what ended the feed.
  /// With `latest`, the frames of its take it jumps over are left out, and counted in `left`.
  [[nodiscard]] std::optional<Item> next(std::optional<Latest> latest = std::nullopt, long* left = nullptr);

 private:
  void read(long first, long takes);
  void push(Item item);

  StudioFrames& frames_;
  std::atomic<bool> stop_{false};
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Item> items_;
  bool ended_ = false;
  std::exception_ptr failure_;
  std::thread thread_;
};

}  // namespace drape::cli
