#include "laser_dpslam/odometry_parameters.h"

#include <stdexcept>
#include <string>

namespace laser_dpslam {

namespace {
template <class T>
void require(bool ok, const std::string& key, const T& value, const char* what) {
  if (!ok) throw std::invalid_argument("parameter '" + key + "' = " + std::to_string(value) + ": " + what);
}
void positive(const ParameterSource& s, const std::string& key, double& v) {
  if (s.get(key, v)) require(v > 0.0, key, v, "must be > 0");
}
void nonNegative(const ParameterSource& s, const std::string& key, double& v) {
  if (s.get(key, v)) require(v >= 0.0, key, v, "must be >= 0");
}
void atLeast(const ParameterSource& s, const std::string& key, int& v, int min) {
  if (s.get(key, v)) require(v >= min, key, v, ("must be >= " + std::to_string(min)).c_str());
}
}  // namespace

void readOdometryParameters(const ParameterSource& s, LaserOdometryConfig& o, ScanPreprocessorConfig& p) {
  // Scan preprocessing.
  nonNegative(s, "min_range", p.min_range);
  nonNegative(s, "max_range", p.max_range);
  s.get("angle_min", p.angle_min);
  s.get("angle_max", p.angle_max);
  if (p.angle_min >= p.angle_max) throw std::invalid_argument("parameter 'angle_min' must be < 'angle_max'");

  // Resampling.
  std::string method;
  if (s.get("resampling", method)) o.resampling = parseResamplingMethod(method);
  atLeast(s, "resampling_budget", o.resampling_budget, 3);
  atLeast(s, "polish_budget", o.polish_budget, 0);

  // Keyframes and local map.
  nonNegative(s, "keyframe_distance", o.keyframe_distance);
  nonNegative(s, "keyframe_angle", o.keyframe_angle);
  atLeast(s, "local_map_keyframes", o.local_map_keyframes, 1);
  nonNegative(s, "keyframe_overlap_drop", o.keyframe_overlap_drop);
  nonNegative(s, "prior_acceleration", o.prior_acceleration);
  positive(s, "velocity_gain", o.velocity_gain);
  require(o.velocity_gain <= 1.0, "velocity_gain", o.velocity_gain, "must be <= 1");
  nonNegative(s, "match_range_margin", o.match_range_margin);
  if (s.get("degenerate_velocity_gain", o.degenerate_velocity_gain)) {
    require(o.degenerate_velocity_gain <= 1.0, "degenerate_velocity_gain", o.degenerate_velocity_gain, "must be <= 1");
  }
  nonNegative(s, "degenerate_velocity_max_range", o.degenerate_velocity_max_range);
  nonNegative(s, "degenerate_hold_time", o.degenerate_hold_time);
  if (s.get("range_flow_gain", o.range_flow_gain)) {
    require(o.range_flow_gain >= 0.0 && o.range_flow_gain <= 1.0, "range_flow_gain", o.range_flow_gain, "must be in [0, 1]");
  }
  nonNegative(s, "prior_release_speed", o.prior_release_speed);
  nonNegative(s, "map_voxel", o.map_voxel);
  s.get("align_to_walls", o.align_to_walls);
  if (s.get("wall_alignment_min_strength", o.wall_alignment_min_strength)) {
    require(o.wall_alignment_min_strength >= 0.0 && o.wall_alignment_min_strength <= 1.0, "wall_alignment_min_strength",
            o.wall_alignment_min_strength, "must be in [0, 1]");
  }
  atLeast(s, "min_points", o.min_points, 3);
  positive(s, "max_prior_gap", o.max_prior_gap);
  int seed = static_cast<int>(o.seed);
  if (s.get("seed", seed)) o.seed = static_cast<std::uint64_t>(seed);

  // NDT.
  ScanMatcherConfig& m = o.matcher;
  std::vector<double> cells;
  if (s.get("ndt_cell_sizes", cells)) {
    if (cells.empty()) throw std::invalid_argument("parameter 'ndt_cell_sizes' must not be empty");
    for (double c : cells) require(c > 0.0, "ndt_cell_sizes", c, "every cell size must be > 0");
    m.cell_sizes = cells;
  }
  atLeast(s, "ndt_min_points", m.ndt.min_points, 3);
  positive(s, "ndt_eigen_ratio", m.ndt.eigen_ratio);
  nonNegative(s, "ndt_point_sigma", m.ndt.point_sigma);
  positive(s, "raster_resolution", m.raster_resolution);

  // Differential Evolution.
  s.get("use_de", m.use_de);
  atLeast(s, "de_population", m.de_population, 4);
  atLeast(s, "de_generations", m.de_generations, 0);
  positive(s, "de_F", m.de_F);
  nonNegative(s, "de_CR", m.de_CR);
  require(m.de_CR <= 1.0, "de_CR", m.de_CR, "must be <= 1");
  s.get("de_dither", m.de_dither);
  positive(s, "window_xy", m.window_xy);
  positive(s, "window_theta", m.window_theta);
  nonNegative(s, "de_spread_xy", m.de_spread_xy);
  nonNegative(s, "de_spread_theta", m.de_spread_theta);
  atLeast(s, "de_stall_generations", m.de_stall_generations, 0);

  // Newton and covariance.
  atLeast(s, "newton_iterations", m.newton_iterations, 0);
  positive(s, "covariance_scale", m.covariance_scale);
  positive(s, "min_sigma_xy", m.min_sigma_xy);
  positive(s, "min_sigma_theta", m.min_sigma_theta);
  positive(s, "degeneracy_ratio", m.degeneracy_ratio);
  positive(s, "degenerate_sigma", m.degenerate_sigma);
  positive(s, "degenerate_sigma_with_prior", m.degenerate_sigma_with_prior);
  s.get("keep_prior_when_degenerate", m.keep_prior_when_degenerate);
  nonNegative(s, "prior_sigma_xy", m.prior_sigma_xy);
  nonNegative(s, "weak_score", m.weak_score);
  nonNegative(s, "weak_matched_fraction", m.weak_matched_fraction);
  positive(s, "weak_inflation", m.weak_inflation);
  nonNegative(s, "rescue_margin", m.rescue_margin);
  positive(s, "rescue_window_theta", m.rescue_window_theta);
  nonNegative(s, "prior_release_margin", m.prior_release_margin);
  nonNegative(s, "prior_release_sigmas", m.prior_release_sigmas);
}

const std::vector<std::string>& odometryNodeKeys() {
  static const std::vector<std::string> keys{"base_frame", "odom_frame", "publish_tf", "transform_timeout",
                                                "use_wheel_odometry"};
  return keys;
}

}  // namespace laser_dpslam
