#include "laser_dpslam/common/run_statistics.h"

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>

namespace laser_dpslam {

TimingSummary summarize(std::vector<double> ms) {
  TimingSummary t;
  if (ms.empty()) return t;
  std::sort(ms.begin(), ms.end());
  const std::size_t n = ms.size();
  t.median = (n % 2) ? ms[n / 2] : 0.5 * (ms[n / 2 - 1] + ms[n / 2]);
  t.p95 = ms[std::min(n - 1, static_cast<std::size_t>(std::ceil(0.95 * n)) - 1)];
  t.max = ms.back();
  return t;
}

double peakRssMb() {
  struct rusage ru {};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_maxrss / 1024.0;  // Linux reports KiB
}

double currentRssMb() {
  FILE* f = std::fopen("/proc/self/status", "r");
  if (!f) return std::nan("");
  char line[256];
  double mb = std::nan("");
  while (std::fgets(line, sizeof(line), f)) {
    long kb = 0;
    if (std::sscanf(line, "VmRSS: %ld kB", &kb) == 1) {
      mb = kb / 1024.0;
      break;
    }
  }
  std::fclose(f);
  return mb;
}

double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

std::string jsonNumber(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\u%04x", c);
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string jsonTiming(const TimingSummary& t) {
  return "{\"median\": " + jsonNumber(t.median) + ", \"p95\": " + jsonNumber(t.p95) + ", \"max\": " + jsonNumber(t.max) + "}";
}

std::string jsonCounts(const std::map<std::string, int>& counts) {
  std::string out = "{";
  bool first = true;
  for (const auto& kv : counts) {
    out += (first ? "" : ", ") + jsonString(kv.first) + ": " + std::to_string(kv.second);
    first = false;
  }
  return out + "}";
}

}  // namespace laser_dpslam
