// Whether the SLAM keeps up with its scans: processing time per scan, lag of its output (map → odom)
// behind the scan time, scans processed and skipped; what dpslam_node reports on /diagnostics. No ROS.
#pragma once

#include <cstddef>
#include <string>

namespace laser_dpslam {

/// Last, mean and max of a series (zeros before the first value).
struct RunningSummary {
  std::size_t count = 0;
  double last = 0.0, mean = 0.0, max = 0.0;
  void add(double v);
};

struct SlamLoadReport {
  bool warn = false;
  std::string message;           ///< "keeping up" or the reasons of the warning
  std::size_t received = 0, processed = 0, skipped = 0, dropped = 0;
  std::size_t skipped_recent = 0;  ///< since the previous report
  RunningSummary processing_s;     ///< wall time from taking a scan to its map → odom, s
  RunningSummary lag_s;            ///< publication time of map → odom − the scan's stamp, s
  double lag_recent_max_s = 0.0;   ///< largest lag since the previous report
  double backlog_s = 0.0;          ///< newest scan received − stamp of the last map → odom (0 before one)
};

class SlamLoadMonitor {
 public:
  /// A lag above `max_lag` seconds is a warning.
  explicit SlamLoadMonitor(double max_lag = 1.0) : max_lag_(max_lag) {}

  /// A scan arrived (its stamp, s).
  void received(double stamp);
  /// A scan could not be used (no transform for it).
  void dropped() { ++dropped_; }
  /// A scan was processed: its stamp, the time it took and when its map → odom went out (s).
  void processed(double stamp, double processing_seconds, double published_at);

  /// The state now. `skipped`: scans replaced by newer ones before they were processed, in total. WARN
  /// when some were skipped since the previous report, when a lag since then exceeded max_lag, or when the
  /// newest scan is more than max_lag ahead of the last map → odom (the SLAM is stuck on one). Starts the
  /// next reporting window.
  SlamLoadReport report(std::size_t skipped);

 private:
  double max_lag_;
  std::size_t received_ = 0, dropped_ = 0, skipped_reported_ = 0;
  double newest_stamp_ = 0.0, last_output_stamp_ = 0.0;
  bool have_output_ = false;
  RunningSummary processing_, lag_;
  double recent_max_lag_ = 0.0;
};

}  // namespace laser_dpslam
