#include "laser_dpslam/slam/dpslam_parameters.h"

#include <gtest/gtest.h>

using namespace laser_dpslam;

namespace {
YamlParameterSource yaml(const std::string& text) { return YamlParameterSource(YAML::Load(text)); }
}  // namespace

// config/dpslam.yaml holds the user-facing keys at their defaults: reading it must change nothing (that it
// holds every user-facing key is test/parameter_registry_test.cpp's).
TEST(DpSlamParameters, ShippedYamlEqualsTheBuiltInDefaults) {
  DpSlamConfig c;
  readDpSlamParameters(YamlParameterSource::load("config/dpslam.yaml"), c);
  const DpSlamConfig d;
  EXPECT_EQ(c.particles, d.particles);
  EXPECT_EQ(c.oversampling, d.oversampling);
  EXPECT_EQ(c.cull_window, d.cull_window);
  EXPECT_EQ(c.resample_threshold, d.resample_threshold);
  EXPECT_EQ(c.proposal.covariance_scale, d.proposal.covariance_scale);
  EXPECT_EQ(c.proposal.min_sigma_xy, d.proposal.min_sigma_xy);
  EXPECT_EQ(c.proposal.min_sigma_theta, d.proposal.min_sigma_theta);
  EXPECT_EQ(c.proposal.sigma_xy_per_m, d.proposal.sigma_xy_per_m);
  EXPECT_EQ(c.proposal.sigma_theta_per_rad, d.proposal.sigma_theta_per_rad);
  EXPECT_EQ(c.proposal.max_sigma_xy, d.proposal.max_sigma_xy);
  EXPECT_EQ(c.proposal.max_sigma_theta, d.proposal.max_sigma_theta);
  EXPECT_EQ(c.min_travel_distance, d.min_travel_distance);
  EXPECT_EQ(c.min_travel_angle, d.min_travel_angle);
  EXPECT_EQ(c.map_resolution, d.map_resolution);
  EXPECT_EQ(c.map_align_to_walls, d.map_align_to_walls);
  EXPECT_EQ(c.map_wall_min_strength, d.map_wall_min_strength);
  EXPECT_EQ(c.trace_max_range, d.trace_max_range);
  EXPECT_EQ(c.no_return_range, d.no_return_range);
  EXPECT_EQ(c.entry_prior_cells, d.entry_prior_cells);
  EXPECT_EQ(c.update_beam_step, d.update_beam_step);
  EXPECT_EQ(c.free_saturation_distance, d.free_saturation_distance);
  EXPECT_EQ(c.map_update_distance, d.map_update_distance);
  EXPECT_EQ(c.map_update_angle, d.map_update_angle);
  EXPECT_EQ(c.surface_depth, d.surface_depth);
  EXPECT_EQ(c.surface_min_cos, d.surface_min_cos);
  EXPECT_EQ(c.cell_normal_min_cos, d.cell_normal_min_cos);
  EXPECT_EQ(c.cell_surface_offsets, d.cell_surface_offsets);
  EXPECT_EQ(c.beam.sigma, d.beam.sigma);
  EXPECT_EQ(c.beam.window, d.beam.window);
  EXPECT_EQ(c.beam.log_floor, d.beam.log_floor);
  EXPECT_EQ(c.beam.unknown_mean_free_path, d.beam.unknown_mean_free_path);
  EXPECT_EQ(c.score_beam_step, d.score_beam_step);
  EXPECT_EQ(c.likelihood_weight, d.likelihood_weight);
  EXPECT_EQ(c.score_no_return, d.score_no_return);
  EXPECT_EQ(c.revisit_freeze_map, d.revisit_freeze_map);
  EXPECT_EQ(c.min_points, d.min_points);
  EXPECT_EQ(c.occupancy_stop_length, d.occupancy_stop_length);
  EXPECT_EQ(c.trajectory_smoothing, d.trajectory_smoothing);
  EXPECT_EQ(c.refine_trajectory, d.refine_trajectory);
  EXPECT_EQ(c.seed, d.seed);
  EXPECT_EQ(c.threads, d.threads);
  EXPECT_NO_THROW(c.validate());
}

TEST(DpSlamParameters, ValuesAreReadAndBadOnesNamed) {
  DpSlamConfig c;
  readDpSlamParameters(yaml("particles: 50\nbeam_sigma: 0.2\nscore_no_return: false\nseed: 7"), c);
  EXPECT_EQ(c.particles, 50);
  EXPECT_EQ(c.beam.sigma, 0.2);
  EXPECT_FALSE(c.score_no_return);
  EXPECT_EQ(c.seed, 7u);
  auto message = [&](const std::string& text) {
    try {
      DpSlamConfig x;
      readDpSlamParameters(yaml(text), x);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("particles: 0").find("particles"), std::string::npos);
  EXPECT_NE(message("beam_sigma: wide").find("beam_sigma"), std::string::npos);
  EXPECT_NE(message("beam_log_floor: 0.5").find("beam_log_floor"), std::string::npos);
  EXPECT_NE(message("resample_threshold: 1.5").find("resample_threshold"), std::string::npos);
  EXPECT_NE(message("map_resolution: -0.05").find("map_resolution"), std::string::npos);
  EXPECT_NE(message("trace_max_range: 0.01").find("trace_max_range"), std::string::npos);
  EXPECT_NE(message("threads: 0").find("threads"), std::string::npos);
  EXPECT_NE(message("surface_depth: -1").find("surface_depth"), std::string::npos);
  EXPECT_NE(message("surface_min_cos: 0").find("surface_min_cos"), std::string::npos);
  EXPECT_NE(message("trajectory_smoothing: -1").find("trajectory_smoothing"), std::string::npos);
  EXPECT_NE(message("surface_min_cos: 1.5").find("surface_min_cos"), std::string::npos);
  EXPECT_NE(message("cell_normal_min_cos: 1.5").find("cell_normal_min_cos"), std::string::npos);
  EXPECT_NE(message("cell_normal_min_cos: -0.1").find("cell_normal_min_cos"), std::string::npos);
  EXPECT_EQ(message("cell_normal_min_cos: 0"), "no error");
  EXPECT_NE(message("map_wall_min_strength: 1.5").find("map_wall_min_strength"), std::string::npos);
  EXPECT_EQ(message("particles: 5"), "no error");
}
