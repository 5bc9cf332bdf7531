#include "laser_dpslam/odometry/odometry_parameters.h"

#include <gtest/gtest.h>

#include <fstream>

using namespace laser_dpslam;

namespace {
YamlParameterSource yaml(const std::string& text) { return YamlParameterSource(YAML::Load(text)); }
}  // namespace

// config/laser_odometry.yaml documents the defaults: reading it must change nothing.
TEST(OdometryParameters, ShippedYamlEqualsTheBuiltInDefaults) {
  LaserOdometryConfig o;
  ScanPreprocessorConfig p;
  readOdometryParameters(YamlParameterSource::load("config/laser_odometry.yaml"), o, p);
  const LaserOdometryConfig d;
  EXPECT_EQ(o.resampling, d.resampling);
  EXPECT_EQ(o.resampling_budget, d.resampling_budget);
  EXPECT_EQ(o.polish_budget, d.polish_budget);
  EXPECT_EQ(o.keyframe_distance, d.keyframe_distance);
  EXPECT_EQ(o.keyframe_angle, d.keyframe_angle);
  EXPECT_EQ(o.local_map_keyframes, d.local_map_keyframes);
  EXPECT_EQ(o.keyframe_overlap_drop, d.keyframe_overlap_drop);
  EXPECT_EQ(o.prior_acceleration, d.prior_acceleration);
  EXPECT_EQ(o.degenerate_velocity_gain, d.degenerate_velocity_gain);
  EXPECT_EQ(o.degenerate_velocity_max_range, d.degenerate_velocity_max_range);
  EXPECT_EQ(o.range_flow_gain, d.range_flow_gain);
  EXPECT_EQ(o.prior_release_speed, d.prior_release_speed);
  EXPECT_EQ(o.map_voxel, d.map_voxel);
  EXPECT_EQ(o.align_to_walls, d.align_to_walls);
  EXPECT_EQ(o.wall_alignment_min_strength, d.wall_alignment_min_strength);
  EXPECT_EQ(o.min_points, d.min_points);
  EXPECT_EQ(o.max_prior_gap, d.max_prior_gap);
  EXPECT_EQ(o.seed, d.seed);
  const ScanMatcherConfig &m = o.matcher, &dm = d.matcher;
  EXPECT_EQ(m.cell_sizes, dm.cell_sizes);
  EXPECT_EQ(m.ndt.min_points, dm.ndt.min_points);
  EXPECT_EQ(m.ndt.eigen_ratio, dm.ndt.eigen_ratio);
  EXPECT_EQ(m.use_de, dm.use_de);
  EXPECT_EQ(m.de_population, dm.de_population);
  EXPECT_EQ(m.de_generations, dm.de_generations);
  EXPECT_EQ(m.de_CR, dm.de_CR);
  EXPECT_EQ(m.window_xy, dm.window_xy);
  EXPECT_EQ(m.window_theta, dm.window_theta);
  EXPECT_EQ(m.de_spread_xy, dm.de_spread_xy);
  EXPECT_EQ(m.de_spread_theta, dm.de_spread_theta);
  EXPECT_EQ(m.de_stall_generations, dm.de_stall_generations);
  EXPECT_EQ(m.newton_iterations, dm.newton_iterations);
  EXPECT_EQ(m.covariance_scale, dm.covariance_scale);
  EXPECT_EQ(m.min_sigma_xy, dm.min_sigma_xy);
  EXPECT_EQ(m.min_sigma_theta, dm.min_sigma_theta);
  EXPECT_EQ(m.degeneracy_ratio, dm.degeneracy_ratio);
  EXPECT_EQ(m.degenerate_sigma, dm.degenerate_sigma);
  EXPECT_EQ(m.degenerate_sigma_with_prior, dm.degenerate_sigma_with_prior);
  EXPECT_EQ(m.weak_score, dm.weak_score);
  EXPECT_EQ(m.weak_matched_fraction, dm.weak_matched_fraction);
  EXPECT_EQ(m.weak_inflation, dm.weak_inflation);
  EXPECT_EQ(m.rescue_margin, dm.rescue_margin);
  EXPECT_EQ(m.rescue_window_theta, dm.rescue_window_theta);
  EXPECT_EQ(p.min_range, 0.0);
  EXPECT_EQ(p.max_range, 0.0);
  EXPECT_LT(p.angle_min, -M_PI);
  EXPECT_GT(p.angle_max, M_PI);
}

TEST(OdometryParameters, ValuesAreReadAndBadOnesNamed) {
  LaserOdometryConfig o;
  ScanPreprocessorConfig p;
  readOdometryParameters(yaml("resampling: uniform\nde_population: 12\nndt_cell_sizes: [2.0, 1.0, 0.5]\nmax_range: 4"), o, p);
  EXPECT_EQ(o.resampling, ResamplingMethod::kUniform);
  EXPECT_EQ(o.matcher.de_population, 12);
  EXPECT_EQ(o.matcher.cell_sizes.size(), 3u);
  EXPECT_EQ(p.max_range, 4.0);
  auto message = [&](const std::string& text) {
    try {
      readOdometryParameters(yaml(text), o, p);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("de_population: 3").find("de_population"), std::string::npos);
  EXPECT_NE(message("resampling: random").find("saliency"), std::string::npos);
  EXPECT_NE(message("ndt_cell_sizes: [1.0, -0.5]").find("ndt_cell_sizes"), std::string::npos);
  EXPECT_NE(message("de_CR: 1.5").find("de_CR"), std::string::npos);
  EXPECT_NE(message("keyframe_overlap_drop: -0.5").find("keyframe_overlap_drop"), std::string::npos);
  EXPECT_NE(message("degenerate_velocity_gain: 2").find("degenerate_velocity_gain"), std::string::npos);
  EXPECT_NE(message("range_flow_gain: 1.5").find("range_flow_gain"), std::string::npos);
  EXPECT_NE(message("prior_release_speed: -0.1").find("prior_release_speed"), std::string::npos);
  EXPECT_NE(message("angle_min: 1.0\nangle_max: 0.5").find("angle_min"), std::string::npos);
}

TEST(OdometryParameters, MalformedFileIsReportedWithItsName) {
  const std::string path = ::testing::TempDir() + "/bad_params.yaml";
  std::ofstream(path) << "de_population: [1, 2\n";
  try {
    YamlParameterSource::load(path);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos);
  }
  EXPECT_THROW(YamlParameterSource::load(path + ".missing"), std::runtime_error);
}
