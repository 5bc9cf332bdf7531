#include "laser_dpslam/common/worker_pool.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <thread>
#include <vector>

using namespace laser_dpslam;

TEST(WorkerPool, EveryItemRunsExactlyOnceOnAValidWorker) {
  for (int threads : {1, 2, 4}) {
    WorkerPool pool(threads);
    EXPECT_EQ(pool.threads(), threads);
    std::vector<std::atomic<int>> calls(1000);
    std::vector<int> worker_of(1000, -1);
    pool.run(calls.size(), [&](std::size_t i, int worker) {
      ++calls[i];
      worker_of[i] = worker;  // one writer per item
    });
    for (std::size_t i = 0; i < calls.size(); ++i) {
      EXPECT_EQ(calls[i].load(), 1) << "item " << i << ", " << threads << " threads";
      EXPECT_GE(worker_of[i], 0);
      EXPECT_LT(worker_of[i], threads);
    }
  }
}

TEST(WorkerPool, OneThreadRunsOnTheCaller) {
  WorkerPool pool(1);
  const std::thread::id caller = std::this_thread::get_id();
  bool elsewhere = false;
  pool.run(10, [&](std::size_t, int worker) { elsewhere = elsewhere || worker != 0 || std::this_thread::get_id() != caller; });
  EXPECT_FALSE(elsewhere);
}

TEST(WorkerPool, NothingToDoReturnsAtOnce) {
  WorkerPool pool(3);
  int calls = 0;
  pool.run(0, [&](std::size_t, int) { ++calls; });
  EXPECT_EQ(calls, 0);
}

// An exception in an item reaches the caller, and the pool keeps working afterwards.
TEST(WorkerPool, AnExceptionIsRethrownAndThePoolStaysUsable) {
  WorkerPool pool(3);
  EXPECT_THROW(pool.run(100,
                        [](std::size_t i, int) {
                          if (i == 37) throw std::runtime_error("item 37");
                        }),
               std::runtime_error);
  std::atomic<int> sum{0};
  pool.run(100, [&](std::size_t i, int) { sum += static_cast<int>(i); });
  EXPECT_EQ(sum.load(), 4950);
}

// Many short runs in a row: no item of one run leaks into the next (generations).
TEST(WorkerPool, RepeatedRunsStayIndependent) {
  WorkerPool pool(4);
  for (int round = 0; round < 200; ++round) {
    std::vector<int> out(static_cast<std::size_t>(round % 7 + 1), 0);
    pool.run(out.size(), [&](std::size_t i, int) { out[i] = round; });
    for (int v : out) ASSERT_EQ(v, round);
  }
}
