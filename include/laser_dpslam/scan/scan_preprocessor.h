// The one place where every incoming LaserScan is validated and turned into points (REP-117).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "laser_dpslam/common/laser_scan.h"

namespace laser_dpslam {

struct ScanPreprocessorConfig {
  double min_range = 0.0;  ///< m; beams shorter than max(this, scan.range_min) are invalid
  double max_range = 0.0;  ///< m; beams longer than min(this, scan.range_max) are invalid; 0 = scan's
  double angle_min = -std::numeric_limits<double>::infinity();  ///< rad; optional angular window
  double angle_max = std::numeric_limits<double>::infinity();   ///< rad
};

/// What happened to each beam of one scan. For a well-formed scan every beam is counted exactly once:
/// total = valid + nan + pos_inf + neg_inf + below_min + above_max + outside_window.
struct BeamCounts {
  std::size_t total = 0;
  std::size_t valid = 0;
  std::size_t nan = 0;             ///< NaN: no measurement
  std::size_t pos_inf = 0;         ///< +inf: no return within range (free space up to range_max)
  std::size_t neg_inf = 0;         ///< -inf: too close
  std::size_t below_min = 0;       ///< finite, < range_min (includes 0 and negative values)
  std::size_t above_max = 0;       ///< finite, > range_max
  std::size_t outside_window = 0;  ///< outside [angle_min, angle_max] of the config
};

struct PreprocessedScan {
  double stamp = 0.0;
  double range_max = 0.0;                 ///< m, the effective maximum range used
  std::vector<Eigen::Vector2d> points;    ///< valid returns in the laser frame, in beam order
  std::vector<int> beams;                 ///< beam index of each point
  std::vector<double> ranges;             ///< m, range of each point
  std::vector<double> angles;             ///< rad, beam angle of each point
  std::vector<double> no_return_angles;   ///< rad, beams that saw nothing up to range_max (+inf or above max)
  double angle_min = 0.0;                 ///< rad, the scan's beam 0 (beam i is at angle_min + i·angle_increment)
  double angle_increment = 0.0;           ///< rad; 0 when the scan was not built by preprocessScan
  BeamCounts counts;
  std::string error;                      ///< non-empty: the scan as a whole is malformed, and why

  bool ok() const { return error.empty(); }
};

/// Validates the scan's geometry (finite angles, non-zero increment consistent with angle_min/max,
/// sane range limits, non-empty ranges) and converts every valid beam to a point. Never throws.
/// A malformed scan comes back with `error` set and no points. Beam counts may change between calls.
/// An invalid config (NaN limits, empty angle or range window) is reported through `error` too.
/// Angles are compared with the config window as given (no wrapping): beam i is at angle_min + i·increment.
PreprocessedScan preprocessScan(const LaserScan& scan, const ScanPreprocessorConfig& config);

}  // namespace laser_dpslam
