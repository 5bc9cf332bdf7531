// Scan validation and conversion to points (REP-117). See scan_preprocessor.h for the contract.
#include "laser_dpslam/scan/scan_preprocessor.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

namespace laser_dpslam {

namespace {

// More beams than any planar LRF has (a URG-04LX has 683, a UTM-30LX 1081): anything above is garbage.
constexpr std::size_t kMaxBeams = 100000;

PreprocessedScan fail(PreprocessedScan out, const std::string& why) {
  out.error = why;
  out.range_max = 0.0;
  return out;
}

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// Whole-scan checks: why the message is malformed, or "" when it is not.
std::string scanError(const LaserScan& scan) {
  const std::size_t n = scan.ranges.size();
  if (n == 0) return "scan has no ranges";
  if (n > kMaxBeams)
    return "scan has " + std::to_string(n) + " beams (more than " + std::to_string(kMaxBeams) + ": not a planar laser)";
  if (!std::isfinite(scan.angle_min) || !std::isfinite(scan.angle_max) || !std::isfinite(scan.angle_increment))
    return "non-finite angle field (angle_min " + num(scan.angle_min) + ", angle_max " + num(scan.angle_max) +
           ", angle_increment " + num(scan.angle_increment) + ")";
  if (scan.angle_increment == 0.0) return "angle_increment is zero";
  if (std::abs(scan.angle_increment) > 2.0 * M_PI)
    return "angle_increment " + num(scan.angle_increment) + " rad exceeds a full turn";
  const double span = scan.angle_max - scan.angle_min;
  // Upside-down / mirrored lasers have angle_max < angle_min with a negative increment: fine if they agree.
  if (span != 0.0 && ((span > 0.0) != (scan.angle_increment > 0.0)))
    return "angle_increment " + num(scan.angle_increment) + " has the wrong sign for angle_max - angle_min = " +
           num(span);
  if (!std::isfinite(scan.range_max) || scan.range_max <= 0.0)
    return "range_max " + num(scan.range_max) + " is not a positive finite number";
  if (!std::isfinite(scan.range_min)) return "range_min " + num(scan.range_min) + " is not finite";
  if (scan.range_min > scan.range_max)
    return "range_min " + num(scan.range_min) + " > range_max " + num(scan.range_max);
  return "";
}

// Configuration checks (a bad config is reported like a bad scan; it is never silently ignored).
std::string configError(const ScanPreprocessorConfig& config) {
  if (std::isnan(config.min_range)) return "config min_range is NaN";
  if (std::isnan(config.max_range)) return "config max_range is NaN";
  if (std::isnan(config.angle_min) || std::isnan(config.angle_max) || config.angle_min > config.angle_max)
    return "config angle window [" + num(config.angle_min) + ", " + num(config.angle_max) + "] is empty or NaN";
  return "";
}

// Per-beam classification (REP-117) against the range window [lo_f, hi_f] and the config's angle window.
// Plain loop, vectors reserved: this runs on every scan.
void classifyBeams(const LaserScan& scan, const ScanPreprocessorConfig& config, float lo_f, float hi_f,
                   PreprocessedScan& out) {
  const std::size_t n = scan.ranges.size();
  out.points.reserve(n);
  out.beams.reserve(n);
  out.ranges.reserve(n);
  out.angles.reserve(n);
  BeamCounts& c = out.counts;
  const double a0 = scan.angle_min, da = scan.angle_increment;
  const double wmin = config.angle_min, wmax = config.angle_max;
  for (std::size_t i = 0; i < n; ++i) {
    const double a = a0 + static_cast<double>(i) * da;  // beam i's angle, from angle_min, not angle_max
    if (a < wmin || a > wmax) {
      ++c.outside_window;
      continue;
    }
    const float rf = scan.ranges[i];
    if (std::isnan(rf)) {  // no measurement: says nothing about free space
      ++c.nan;
      continue;
    }
    if (std::isinf(rf)) {
      if (rf > 0.0f) {  // no return within range: free space up to range_max
        ++c.pos_inf;
        out.no_return_angles.push_back(a);
      } else {  // too close
        ++c.neg_inf;
      }
      continue;
    }
    if (rf <= 0.0f || rf < lo_f) {  // 0 and negative readings are error codes on several drivers
      ++c.below_min;
      continue;
    }
    if (rf > hi_f) {
      // Many lasers report range_max (or beyond) for "no return"; beyond a config max_range the beam
      // still travelled at least that far through free space. Either way: no return within range.
      ++c.above_max;
      out.no_return_angles.push_back(a);
      continue;
    }
    ++c.valid;
    const double r = rf;
    out.points.emplace_back(r * std::cos(a), r * std::sin(a));
    out.beams.push_back(static_cast<int>(i));
    out.ranges.push_back(r);
    out.angles.push_back(a);
  }
}

}  // namespace

PreprocessedScan preprocessScan(const LaserScan& scan, const ScanPreprocessorConfig& config) {
  PreprocessedScan out;
  out.stamp = scan.stamp;
  out.counts.total = scan.ranges.size();

  // A malformed message gives an error and no points, never an exception.
  std::string why = scanError(scan);
  if (why.empty()) why = configError(config);
  if (!why.empty()) return fail(std::move(out), why);

  // Effective range window: the tighter of the scan's and the config's; max_range <= 0 (or inf) = scan's.
  const double lo = std::max(scan.range_min, config.min_range);
  const double hi = (config.max_range > 0.0 && std::isfinite(config.max_range))
                        ? std::min(scan.range_max, config.max_range)
                        : scan.range_max;
  if (lo > hi)
    return fail(std::move(out), "effective range window [" + num(lo) + ", " + num(hi) + "] is empty");
  // Ranges are float32 on the wire: compare them with the limits rounded to float, so that a reading of
  // exactly range_min or range_max (as a float) is inside the window, not lost to rounding.
  constexpr double kFloatMax = std::numeric_limits<float>::max();
  const float lo_f = static_cast<float>(std::clamp(lo, -kFloatMax, kFloatMax));
  const float hi_f = static_cast<float>(std::min(hi, kFloatMax));
  out.range_max = std::max(hi, static_cast<double>(hi_f));
  out.angle_min = scan.angle_min;
  out.angle_increment = scan.angle_increment;
  classifyBeams(scan, config, lo_f, hi_f, out);
  return out;
}

}  // namespace laser_dpslam
