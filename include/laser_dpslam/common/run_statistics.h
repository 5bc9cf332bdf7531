// Per-scan timing and skip counts of an offline run, and their stats.json form.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace laser_dpslam {

struct TimingSummary {
  double median = 0.0, p95 = 0.0, max = 0.0;  ///< ms
};

/// Median / 95th percentile (nearest rank) / max of a list of durations in ms; zeros when empty.
TimingSummary summarize(std::vector<double> ms);

/// Peak resident set size of this process in MB (getrusage).
double peakRssMb();
/// Current resident set size of this process in MB (VmRSS of /proc/self/status); NaN where unavailable.
/// For memory-over-time logs: the peak alone cannot tell steady growth from one early spike.
double currentRssMb();

/// CPU time consumed by the calling thread, in seconds.
double threadCpuSeconds();
/// CPU time consumed by the whole process, in seconds.
double processCpuSeconds();

/// Minimal JSON helpers for the tools' outputs (numbers printed with enough digits, NaN as null).
std::string jsonNumber(double v);
std::string jsonString(const std::string& s);
std::string jsonTiming(const TimingSummary& t);
std::string jsonCounts(const std::map<std::string, int>& counts);

}  // namespace laser_dpslam
