#pragma once
// How many threads the parallel loops may use (`drape --threads`, a tbb::global_control),
// and a loop over pieces that keeps each piece on the same thread from call to call.

#include <cstddef>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

namespace drape {

/// The threads TBB's loops may use now: every core unless a tbb::global_control in force
/// says fewer. Asked once per solver or collider, not per loop (it takes TBB's locks).
[[nodiscard]] std::size_t threadsAllowed();

/// body(begin, end) over pieces of [0, count) of at least `grain`, on TBB's threads, each
/// piece on the thread that ran it at the previous call where TBB can
/// (tbb::affinity_partitioner). A loop run on every substep over the same data then finds
/// its piece in its core's caches: with pieces handed out anew on each call, the walking
/// dress's collision state moved between the two cores' caches on every substep and two
/// threads ran it slower than one. One PieceLoop per loop and data; a copy starts without
/// affinities.
class PieceLoop {
 public:
  PieceLoop() = default;
  PieceLoop(const PieceLoop&) {}
  PieceLoop& operator=(const PieceLoop&) { return *this; }
  ~PieceLoop() = default;

  template <typename Body>
  void operator()(std::size_t count, std::size_t grain, const Body& body) {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, count, grain),
        [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); }, affinity_);
  }

 private:
  tbb::affinity_partitioner affinity_;
};

}  // namespace drape
