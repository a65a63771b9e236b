#pragma once
// A producer running ahead of its consumer on a thread of its own, through a ring of slots:
// `drape run` writes frame N and `drape play SCENE` draws it while the next frames are
// simulated.

#include <algorithm>
#include <atomic>
#include <exception>
#include <functional>
#include <thread>
#include <utility>
#include <vector>

#include <tbb/concurrent_queue.h>

namespace drape {

/// Runs `take` for items first, first + 1, ... on a thread of its own, at most `slots` items
/// ahead of the consumer, which receives them in order from next(). The items live in a ring
/// of slots that `take` fills in place (sized once by `prepare`, so that a producer that
/// reuses a slot's storage allocates nothing per item). What `take` throws reaches the
/// consumer from next(), after the items taken before it.
template <typename Slot>
class RunAhead {
 public:
  /// Fills `slot` with item `index`; false ends the items before this one.
  using Take = std::function<bool(long index, Slot& slot)>;

  /// `last` < 0: no last item (the consumer stops by destroying this).
  RunAhead(std::size_t slots, long first, long last, const std::function<void(Slot&)>& prepare, Take take)
      : slots_(std::max<std::size_t>(slots, 1)), take_(std::move(take)) {
    for (std::size_t s = 0; s < slots_.size(); ++s) {
      prepare(slots_[s]);
      free_.push(static_cast<int>(s));
    }
    thread_ = std::thread([this, first, last] { produce(first, last); });
  }

  /// Stops the producer after the item it is taking, if the consumer stopped early.
  ~RunAhead() {
    // The flag stops a producer about to take another item; the -1 wakes one waiting for a
    // slot (a queue's abort() misses a thread that has not started waiting yet).
    stop_ = true;
    free_.push(-1);
    thread_.join();
  }

  RunAhead(const RunAhead&) = delete;
  RunAhead& operator=(const RunAhead&) = delete;

  /// Whether next() would return at once: an item, the end or what `take` threw is there.
  [[nodiscard]] bool ready() const { return ended_ || !full_.empty(); }

  /// The next item, or nullptr after the last; rethrows what `take` threw. The item is the
  /// consumer's until the next call.
  [[nodiscard]] const Slot* next() {
    if (held_ >= 0) free_.push(held_);
    held_ = -1;
    if (ended_) return nullptr;
    int slot = -1;
    full_.pop(slot);
    if (slot < 0) {
      ended_ = true;
      if (failure_) std::rethrow_exception(failure_);
      return nullptr;
    }
    held_ = slot;
    return &slots_[static_cast<std::size_t>(slot)];
  }

 private:
  void produce(long first, long last) {
    try {
      for (long index = first; last < 0 || index <= last; ++index) {
        int slot = -1;
        free_.pop(slot);
        if (slot < 0 || stop_) return;  // the consumer is gone: nobody waits for the end
        if (!take_(index, slots_[static_cast<std::size_t>(slot)])) break;
        full_.push(slot);
      }
    } catch (...) {
      failure_ = std::current_exception();
    }
    full_.push(-1);
  }

  std::vector<Slot> slots_;
  Take take_;
  tbb::concurrent_bounded_queue<int> free_;  ///< slots for the producer to fill; -1: stop
  tbb::concurrent_bounded_queue<int> full_;  ///< slots filled, in order; -1: no more
  std::atomic<bool> stop_{false};
  std::exception_ptr failure_;  ///< written before the -1 on full_, read after it
  int held_ = -1;               ///< the slot the consumer has
  bool ended_ = false;
  std::thread thread_;
};

}  // namespace drape
