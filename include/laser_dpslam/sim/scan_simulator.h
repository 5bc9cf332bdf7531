// A Hokuyo URG-04LX-like laser simulator on a floor plan. No ROS.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <string>

#include "laser_dpslam/common/laser_scan.h"
#include "laser_dpslam/common/pose2d.h"
#include "laser_dpslam/sim/floor_plan.h"
#include "laser_dpslam/sim/vector_plan.h"

namespace laser_dpslam {

/// Sensor model. Defaults: Hokuyo URG-04LX datasheet (683 beams over 240°, 0.02–5.6 m, 10 Hz,
/// accuracy ±10 mm up to 1 m and ±1 % of the range beyond) and urg_node's conventions.
struct ScanSimulatorConfig {
  int beams = 683;                          ///< number of beams (first at angle_min, last at angle_max)
  double angle_min = -120.0 * M_PI / 180.0;  ///< rad, angle of the first beam (counter-clockwise positive)
  double angle_max = 120.0 * M_PI / 180.0;   ///< rad, angle of the last beam
  double range_min = 0.02;                  ///< m; true or noisy ranges below it are reported as −inf
  double range_max = 5.6;                   ///< m; nothing within it → +inf (REP-117 "no return")
  double scan_rate = 10.0;                  ///< Hz; scan_time = 1 / scan_rate
  double time_increment = 0.1 / 1024.0;     ///< s between beams (URG-04LX: 1024 steps per 100 ms turn)
  double noise_min_stddev = 0.010;          ///< m; range noise σ = max(noise_min_stddev, noise_range_fraction·r)
  double noise_range_fraction = 0.01;       ///< dimensionless fraction of the range (1 %)
  double dropout_probability = 0.01;        ///< per beam, 0–1: no measurement → NaN (as urg_node reports 0)
  double grazing_angle = 80.0 * M_PI / 180.0;  ///< rad; incidence (from the wall normal) beyond which ...
  double grazing_dropout_probability = 0.2;    ///< ... a beam is additionally dropped (NaN) with this probability
  double outlier_probability = 0.0;         ///< per beam, 0–1: a spurious short return, uniform in [range_min, r)
  std::string frame_id = "laser";           ///< header frame_id of the scans

  double angleIncrement() const { return beams > 1 ? (angle_max - angle_min) / (beams - 1) : 0.0; }  ///< rad

  /// Throws std::invalid_argument on an impossible configuration (no beams, range_max ≤ range_min,
  /// probabilities outside [0, 1], negative noise, ...).
  void validate() const;
};

/// Simulates scans of the laser at a given map-frame pose. Walls are the occupied cells of a raster plan,
/// hit exactly (see FloorPlan::raycast), or the shapes of a geometry plan (VectorPlan::raycast). All randomness comes from one std::mt19937_64 seeded in the
/// constructor, consumed in a fixed order (a fixed number of draws per beam), and turned into uniform
/// and Gaussian variates by portable code: the same seed, plan, config and calls give identical scans
/// on every platform. The scan is taken at one instant (no motion distortion within a sweep).
class ScanSimulator {
 public:
  ScanSimulator(const FloorPlan& plan, const ScanSimulatorConfig& config, std::uint64_t seed);
  /// On a geometry plan (walls at any angle; VectorPlan::raycast); the same noise model and draws.
  ScanSimulator(const VectorPlan& plan, const ScanSimulatorConfig& config, std::uint64_t seed);

  /// One scan from `laser_pose_in_map` (the laser frame's pose in the plan's map frame), header stamp
  /// `stamp` [s]. ranges[i]: noisy distance [m], NaN for a dropout, +inf when no wall lies within
  /// range_max, −inf below range_min. Intensities are left empty.
  LaserScan simulate(const Pose2D& laser_pose_in_map, double stamp);

  const ScanSimulatorConfig& config() const { return config_; }

 private:
  double uniform();   ///< [0, 1) with 53 random bits
  double gaussian();  ///< standard normal (Box–Muller), consumes two uniforms

  const FloorPlan* grid_ = nullptr;      ///< one of the two plans is set
  const VectorPlan* geometry_ = nullptr;
  ScanSimulatorConfig config_;
  std::mt19937_64 rng_;
};

}  // namespace laser_dpslam
