// The hand-off from a sensor callback to a slower worker when only the newest item matters: one slot, and
// an item still waiting when a newer one arrives is replaced (counted as skipped), so the worker never works
// through a backlog of stale items and its output lags the input by at most one step plus one period.
// Thread-safe; no ROS.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <utility>

namespace laser_dpslam {

/// What went through a NewestSlot: offered = taken + skipped + (1 if one is waiting).
struct SlotCounts {
  std::size_t offered = 0;  ///< put() calls accepted
  std::size_t taken = 0;    ///< handed to the worker
  std::size_t skipped = 0;  ///< replaced by a newer one before the worker took them
};

template <class T>
class NewestSlot {
 public:
  /// Leaves `item` for the worker, replacing (and counting as skipped) one still waiting. Returns whether
  /// one was replaced. After close(), items are refused (false, not counted).
  bool put(T item) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) return false;
    const bool replaced = full_;
    if (replaced) ++counts_.skipped;
    ++counts_.offered;
    item_ = std::move(item);
    full_ = true;
    ready_.notify_one();
    return replaced;
  }

  /// Waits for an item and moves it to *out; false, at once, after close().
  bool take(T* out) {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait(lock, [this] { return full_ || closed_; });
    if (closed_) return false;
    return takeLocked(out);
  }

  /// Takes the waiting item if there is one, without waiting.
  bool tryTake(T* out) {
    std::lock_guard<std::mutex> lock(mutex_);
    return !closed_ && full_ && takeLocked(out);
  }

  /// Wakes a waiting take() (which returns false) and refuses items from now on.
  void close() {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
    ready_.notify_all();
  }

  bool waiting() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return full_;
  }

  SlotCounts counts() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return counts_;
  }

 private:
  bool takeLocked(T* out) {
    *out = std::move(item_);
    item_ = T();
    full_ = false;
    ++counts_.taken;
    return true;
  }

  mutable std::mutex mutex_;
  std::condition_variable ready_;
  T item_{};
  bool full_ = false;
  bool closed_ = false;
  SlotCounts counts_;
};

}  // namespace laser_dpslam
