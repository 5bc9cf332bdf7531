#include "laser_dpslam/slam/slam_load_monitor.h"

#include <algorithm>
#include <cstdio>

namespace laser_dpslam {

void RunningSummary::add(double v) {
  ++count;
  last = v;
  mean += (v - mean) / static_cast<double>(count);
  max = count == 1 ? v : std::max(max, v);
}

void SlamLoadMonitor::received(double stamp) {
  ++received_;
  newest_stamp_ = received_ == 1 ? stamp : std::max(newest_stamp_, stamp);
}

void SlamLoadMonitor::processed(double stamp, double processing_seconds, double published_at) {
  processing_.add(processing_seconds);
  const double lag = published_at - stamp;
  lag_.add(lag);
  recent_max_lag_ = std::max(recent_max_lag_, lag);
  last_output_stamp_ = have_output_ ? std::max(last_output_stamp_, stamp) : stamp;
  have_output_ = true;
}

SlamLoadReport SlamLoadMonitor::report(std::size_t skipped) {
  SlamLoadReport r;
  r.received = received_;
  r.processed = processing_.count;
  r.skipped = skipped;
  r.dropped = dropped_;
  r.skipped_recent = skipped >= skipped_reported_ ? skipped - skipped_reported_ : skipped;
  r.processing_s = processing_;
  r.lag_s = lag_;
  r.lag_recent_max_s = recent_max_lag_;
  r.backlog_s = have_output_ ? std::max(0.0, newest_stamp_ - last_output_stamp_) : 0.0;

  std::string why;
  char buf[128];
  auto add = [&](const char* text) { why += (why.empty() ? "" : "; ") + std::string(text); };
  if (r.skipped_recent > 0) {
    std::snprintf(buf, sizeof(buf), "CPU short: %zu scans skipped", r.skipped_recent);
    add(buf);
  }
  if (r.lag_recent_max_s > max_lag_) {
    std::snprintf(buf, sizeof(buf), "map->odom lag %.2f s > %.2f s", r.lag_recent_max_s, max_lag_);
    add(buf);
  }
  if (r.backlog_s > max_lag_) {
    std::snprintf(buf, sizeof(buf), "newest scan %.2f s ahead of map->odom", r.backlog_s);
    add(buf);
  }
  r.warn = !why.empty();
  r.message = r.warn ? why : "keeping up";

  skipped_reported_ = skipped;
  recent_max_lag_ = 0.0;
  return r;
}

}  // namespace laser_dpslam
