#include "laser_dpslam/common/parameter_registry.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace laser_dpslam {

bool ParameterRange::contains(double v) const {
  if (std::isnan(v)) return false;
  const bool lo_ok = lo_open ? v > lo : v >= lo;
  const bool hi_ok = hi_open ? v < hi : v <= hi;
  return lo_ok && hi_ok;
}

namespace {
// Bounds read better without ".0": ">= 3", "[0, 1]".
std::string boundText(double v) {
  const std::string s = formatParameterNumber(v);
  return s.size() > 2 && s.compare(s.size() - 2, 2, ".0") == 0 ? s.substr(0, s.size() - 2) : s;
}
}  // namespace

std::string ParameterRange::text() const {
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  const std::string l = boundText(lo), h = boundText(hi);
  if (has_lo && has_hi) return std::string(lo_open ? "(" : "[") + l + ", " + h + (hi_open ? ")" : "]");
  if (has_lo) return std::string(lo_open ? "> " : ">= ") + l;
  if (has_hi) return std::string(hi_open ? "< " : "<= ") + h;
  return "any";
}

ParameterRange anyValue() { return ParameterRange(); }
ParameterRange above(double lo) { return ParameterRange{lo, std::numeric_limits<double>::infinity(), true, false}; }
ParameterRange atLeast(double lo) { return ParameterRange{lo, std::numeric_limits<double>::infinity(), false, false}; }
ParameterRange below(double hi) { return ParameterRange{-std::numeric_limits<double>::infinity(), hi, false, true}; }
ParameterRange atMost(double hi) { return ParameterRange{-std::numeric_limits<double>::infinity(), hi, false, false}; }
ParameterRange closedInterval(double lo, double hi) { return ParameterRange{lo, hi, false, false}; }
ParameterRange leftOpenInterval(double lo, double hi) { return ParameterRange{lo, hi, true, false}; }

std::string formatParameterNumber(double v) {
  // YAML's spelling, so that the text reads back from a file.
  if (std::isinf(v)) return v > 0 ? ".inf" : "-.inf";
  if (std::isnan(v)) return ".nan";
  if (v == std::floor(v) && std::fabs(v) < 1e15) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), "%.1f", v);  // "1.0": says it is a number, not an integer
    return buf;
  }
  char buf[32];
  for (int precision = 1; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof(buf), "%.*g", precision, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

void checkParameterRange(const std::string& key, double value, const ParameterRange& range) {
  if (range.contains(value)) return;
  throw std::invalid_argument("parameter '" + key + "' = " + formatParameterNumber(value) + " is outside its range " +
                              range.text());
}

void checkParameterRange(const std::string& key, int value, const ParameterRange& range) {
  if (range.contains(value)) return;
  throw std::invalid_argument("parameter '" + key + "' = " + std::to_string(value) + " is outside its range " +
                              range.text());
}

}  // namespace laser_dpslam
