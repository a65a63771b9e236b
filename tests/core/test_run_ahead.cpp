// RunAhead: items in order, never more than its slots ahead, a slot never refilled while
// the consumer holds it, the producer's exception delivered after the items before it, and
// a consumer that stops early stopping the producer.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "drape/core/run_ahead.hpp"

namespace drape {
namespace {

struct Item {
  long index = -1;
  std::vector<long> payload;  ///< every entry the index: a slot refilled under the consumer shows
};

void fill(long index, Item& item) {
  item.index = index;
  for (long& v : item.payload) v = index;
}

const auto kPrepare = [](Item& item) { item.payload.resize(4096); };

TEST(RunAhead, DeliversEveryItemInOrderAndNeverMoreThanItsSlotsAhead) {
  constexpr std::size_t kSlots = 3;
  std::atomic<long> consumed{0};
  std::atomic<long> mostAhead{0};
  RunAhead<Item> ahead(kSlots, 0, 199, kPrepare, [&](long index, Item& item) {
    // The consumer has released `consumed` items (and may hold one more).
    const long ahead = index - consumed.load();
    long seen = mostAhead.load();
    while (ahead > seen && !mostAhead.compare_exchange_weak(seen, ahead)) {
    }
    fill(index, item);
    return true;
  });
  long expected = 0;
  while (const Item* item = ahead.next()) {
    ASSERT_EQ(item->index, expected);
    // Give the producer time to run into this slot if the ring were wrong.
    if (expected % 16 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    for (const long v : item->payload) ASSERT_EQ(v, expected) << "slot refilled while held";
    ++expected;
    consumed = expected - 1;  // items before this one are released at the next call
  }
  EXPECT_EQ(expected, 200);
  EXPECT_LE(mostAhead.load(), static_cast<long>(kSlots) + 1);
  EXPECT_GE(mostAhead.load(), 2) << "the producer never ran ahead";
  EXPECT_EQ(ahead.next(), nullptr) << "after the end, nullptr again";
}

TEST(RunAhead, AFalseFromTakeEndsTheItems) {
  RunAhead<Item> ahead(2, 5, -1, kPrepare, [](long index, Item& item) {
    if (index == 9) return false;
    fill(index, item);
    return true;
  });
  std::vector<long> seen;
  while (const Item* item = ahead.next()) seen.push_back(item->index);
  EXPECT_EQ(seen, (std::vector<long>{5, 6, 7, 8}));
  EXPECT_EQ(ahead.next(), nullptr);
}

TEST(RunAhead, WhatTakeThrowsComesAfterTheItemsBeforeIt) {
  RunAhead<Item> ahead(3, 0, 100, kPrepare, [](long index, Item& item) {
    if (index == 5) throw std::runtime_error("frame 5 went wrong");
    fill(index, item);
    return true;
  });
  std::vector<long> seen;
  try {
    while (const Item* item = ahead.next()) seen.push_back(item->index);
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "frame 5 went wrong");
  }
  EXPECT_EQ(seen, (std::vector<long>{0, 1, 2, 3, 4}));
  EXPECT_EQ(ahead.next(), nullptr) << "thrown once";
}

TEST(RunAhead, AConsumerThatStopsEarlyStopsTheProducer) {
  // An endless producer, a consumer that takes two items and goes: the destructor must
  // return (not wait for an end that never comes), with the producer stopped a slot's
  // worth of items later at most.
  std::atomic<long> taken{0};
  {
    RunAhead<Item> ahead(3, 0, -1, kPrepare, [&](long index, Item& item) {
      fill(index, item);
      ++taken;
      return true;
    });
    ASSERT_NE(ahead.next(), nullptr);
    ASSERT_NE(ahead.next(), nullptr);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // the producer fills the ring and waits
  }
  EXPECT_LE(taken.load(), 2 + 3);
  // Stopping while the producer is in the middle of an item: it finishes that one only.
  std::atomic<long> started{0};
  {
    RunAhead<Item> ahead(1, 0, -1, kPrepare, [&](long index, Item& item) {
      ++started;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      fill(index, item);
      return true;
    });
    ASSERT_NE(ahead.next(), nullptr);
  }
  EXPECT_LE(started.load(), 3);
}

}  // namespace
}  // namespace drape
