#include "laser_dpslam/dpslam_parameters.h"

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

void readDpSlamParameters(const ParameterSource& s, DpSlamConfig& c) {
  // Particle filter.
  atLeast(s, "particles", c.particles, 1);
  atLeast(s, "oversampling", c.oversampling, 1);
  positive(s, "cull_window", c.cull_window);
  if (s.get("resample_threshold", c.resample_threshold)) {
    require(c.resample_threshold >= 0.0 && c.resample_threshold <= 1.0, "resample_threshold", c.resample_threshold,
            "must be in [0, 1]");
  }
  atLeast(s, "refine_iterations", c.refine_iterations, 0);
  positive(s, "refine_step_xy", c.refine_step_xy);
  positive(s, "refine_step_theta", c.refine_step_theta);
  atLeast(s, "refine_halvings", c.refine_halvings, 0);
  nonNegative(s, "proposal_covariance_scale", c.proposal.covariance_scale);
  nonNegative(s, "proposal_min_sigma_xy", c.proposal.min_sigma_xy);
  nonNegative(s, "proposal_min_sigma_theta", c.proposal.min_sigma_theta);
  nonNegative(s, "proposal_sigma_xy_per_m", c.proposal.sigma_xy_per_m);
  nonNegative(s, "proposal_sigma_theta_per_rad", c.proposal.sigma_theta_per_rad);
  positive(s, "proposal_max_sigma_xy", c.proposal.max_sigma_xy);
  positive(s, "proposal_max_sigma_theta", c.proposal.max_sigma_theta);
  if (s.get("explore_noise_scale", c.explore_noise_scale)) {
    require(c.explore_noise_scale > 0.0 && c.explore_noise_scale <= 1.0, "explore_noise_scale", c.explore_noise_scale,
            "must be in (0, 1]");
  }
  s.get("revisit_freeze_map", c.revisit_freeze_map);
  positive(s, "revisit_radius", c.revisit_radius);
  nonNegative(s, "revisit_min_travel", c.revisit_min_travel);
  nonNegative(s, "min_travel_distance", c.min_travel_distance);
  nonNegative(s, "min_travel_angle", c.min_travel_angle);

  // Map.
  positive(s, "map_resolution", c.map_resolution);
  s.get("map_align_to_walls", c.map_align_to_walls);
  if (s.get("map_wall_min_strength", c.map_wall_min_strength)) {
    require(c.map_wall_min_strength >= 0.0 && c.map_wall_min_strength <= 1.0, "map_wall_min_strength",
            c.map_wall_min_strength, "must be in [0, 1]");
  }
  positive(s, "trace_max_range", c.trace_max_range);
  require(c.trace_max_range > c.map_resolution, "trace_max_range", c.trace_max_range, "must exceed map_resolution");
  positive(s, "no_return_range", c.no_return_range);
  positive(s, "entry_prior_cells", c.entry_prior_cells);
  atLeast(s, "update_beam_step", c.update_beam_step, 1);
  nonNegative(s, "free_saturation_distance", c.free_saturation_distance);
  nonNegative(s, "surface_depth", c.surface_depth);
  if (s.get("surface_min_cos", c.surface_min_cos)) {
    require(c.surface_min_cos > 0.0 && c.surface_min_cos <= 1.0, "surface_min_cos", c.surface_min_cos, "must be in (0, 1]");
  }
  if (s.get("cell_normal_min_cos", c.cell_normal_min_cos)) {
    require(c.cell_normal_min_cos >= 0.0 && c.cell_normal_min_cos <= 1.0, "cell_normal_min_cos", c.cell_normal_min_cos,
            "must be in [0, 1]");
  }
  s.get("cell_surface_offsets", c.cell_surface_offsets);
  nonNegative(s, "map_update_distance", c.map_update_distance);
  nonNegative(s, "map_update_angle", c.map_update_angle);

  // Observation model.
  positive(s, "beam_sigma", c.beam.sigma);
  positive(s, "beam_window", c.beam.window);
  if (s.get("beam_log_floor", c.beam.log_floor)) require(c.beam.log_floor < 0.0, "beam_log_floor", c.beam.log_floor, "must be < 0");
  positive(s, "unknown_mean_free_path", c.beam.unknown_mean_free_path);
  atLeast(s, "score_beam_step", c.score_beam_step, 1);
  nonNegative(s, "score_range_margin", c.score_range_margin);
  if (s.get("likelihood_weight", c.likelihood_weight)) {
    require(c.likelihood_weight > 0.0 && c.likelihood_weight <= 1.0, "likelihood_weight", c.likelihood_weight, "must be in (0, 1]");
  }
  s.get("score_no_return", c.score_no_return);
  atLeast(s, "slam_min_points", c.min_points, 1);

  // Output and execution.
  positive(s, "occupancy_stop_length", c.occupancy_stop_length);
  nonNegative(s, "trajectory_smoothing", c.trajectory_smoothing);
  s.get("refine_trajectory", c.refine_trajectory);
  int seed = static_cast<int>(c.seed);
  if (s.get("seed", seed)) {
    require(seed >= 0, "seed", seed, "must be >= 0");
    c.seed = static_cast<std::uint64_t>(seed);
  }
  atLeast(s, "threads", c.threads, 1);
}

const std::vector<std::string>& dpslamNodeKeys() {
  static const std::vector<std::string> keys{"map_frame",         "odom_frame",        "base_frame",
                                             "map_update_interval", "publish_particles", "transform_timeout",
                                             "min_range",         "max_range"};
  return keys;
}

}  // namespace laser_dpslam
