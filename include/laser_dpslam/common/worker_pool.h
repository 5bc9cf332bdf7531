// A tiny fixed pool of worker threads for data-parallel loops. Work items are handed out dynamically,
// so callers must write results per item (never accumulate across items) to stay independent of
// scheduling. No ROS.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace laser_dpslam {

class WorkerPool {
 public:
  /// `threads` ≥ 1 workers in total, the calling thread included (threads − 1 are started).
  explicit WorkerPool(int threads = 1);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  /// Calls f(i, worker) for i = 0 … n−1, worker ∈ [0, threads()), and returns when all are done. An
  /// exception thrown by f is rethrown here (the first one).
  void run(std::size_t n, const std::function<void(std::size_t, int)>& f);

 private:
  void work(int worker);
  void drain(int worker);

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  const std::function<void(std::size_t, int)>* job_ = nullptr;
  std::size_t n_ = 0;
  std::atomic<std::size_t> next_{0};
  std::uint64_t generation_ = 0;
  int active_ = 0;
  bool stop_ = false;
  std::exception_ptr error_;
};

}  // namespace laser_dpslam
