#include "laser_dpslam/common/newest_slot.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

using namespace laser_dpslam;

TEST(NewestSlot, TheNewestItemWinsAndTheReplacedOnesCountAsSkipped) {
  NewestSlot<int> slot;
  EXPECT_FALSE(slot.put(1));
  EXPECT_TRUE(slot.put(2));
  EXPECT_TRUE(slot.put(3));
  EXPECT_TRUE(slot.waiting());
  int v = 0;
  ASSERT_TRUE(slot.take(&v));
  EXPECT_EQ(v, 3);
  EXPECT_FALSE(slot.waiting());
  EXPECT_FALSE(slot.tryTake(&v));
  EXPECT_FALSE(slot.put(4));  // the slot was empty: nothing replaced
  ASSERT_TRUE(slot.tryTake(&v));
  EXPECT_EQ(v, 4);
  const SlotCounts c = slot.counts();
  EXPECT_EQ(c.offered, 4u);
  EXPECT_EQ(c.taken, 2u);
  EXPECT_EQ(c.skipped, 2u);
}

TEST(NewestSlot, CloseWakesAWaitingWorkerAndRefusesItems) {
  NewestSlot<int> slot;
  std::atomic<bool> returned{false};
  bool result = true;
  std::thread worker([&] {
    int v = 0;
    result = slot.take(&v);
    returned = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_FALSE(returned);
  slot.close();
  worker.join();
  EXPECT_FALSE(result);
  EXPECT_FALSE(slot.put(5));
  EXPECT_EQ(slot.counts().offered, 0u);
}

// A worker slower than the producer sees only ever newer items, never works through a backlog, and gets
// the last one; every item is either taken or counted as skipped.
TEST(NewestSlot, ASlowWorkerTakesIncreasingItemsAndTheLastOne) {
  NewestSlot<int> slot;
  std::vector<int> seen;
  std::thread worker([&] {
    int v = 0;
    while (slot.take(&v)) {
      seen.push_back(v);
      std::this_thread::sleep_for(std::chrono::microseconds(700));  // slower than the producer
      if (v == 199) return;
    }
  });
  for (int i = 0; i < 200; ++i) {
    slot.put(i);
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  worker.join();
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.back(), 199);
  for (std::size_t i = 1; i < seen.size(); ++i) EXPECT_LT(seen[i - 1], seen[i]);
  const SlotCounts c = slot.counts();
  EXPECT_EQ(c.offered, 200u);
  EXPECT_EQ(c.taken, seen.size());
  EXPECT_EQ(c.taken + c.skipped, 200u);
  EXPECT_GT(c.skipped, 0u);
}
