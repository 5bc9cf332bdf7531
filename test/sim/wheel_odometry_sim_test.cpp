#include "laser_dpslam/sim/wheel_odometry_sim.h"

#include <gtest/gtest.h>

#include <cmath>

namespace laser_dpslam {
namespace {

// A 4 x 3 m rectangle driven twice (28 m, 8 turns in place), sampled at 20 Hz.
std::vector<TimedPose> rectangle() {
  const std::vector<Eigen::Vector2d> wps = {{0, 0}, {4, 0}, {4, 3}, {0, 3}, {0, 0}};
  return samplePath(repeatLoop(wps, 2), 20.0);
}

WheelOdometryReading drive(const WheelOdometryConfig& config, std::uint64_t seed) {
  WheelOdometrySimulator sim(config, seed);
  WheelOdometryReading r;
  for (const TimedPose& tp : rectangle()) r = sim.step(tp);
  return r;
}

TEST(WheelOdometrySim, WithoutNoiseIntegratesToTheTruth) {
  WheelOdometryConfig config;
  config.scale_error = 0.0;
  config.slip = 0.0;
  WheelOdometrySimulator sim(config, 3);
  EXPECT_EQ(sim.leftScale(), 1.0);
  const std::vector<TimedPose> path = rectangle();
  const Pose2D start = path.front().pose;
  for (const TimedPose& tp : path) {
    const WheelOdometryReading r = sim.step(tp);
    const Pose2D truth = start.inverse() * tp.pose;  // the odom frame is the first pose
    // Exact for a step that only drives or only turns; a step spanning the end of a turn and the start
    // of a drive is integrated along the mean heading (micrometres off).
    ASSERT_NEAR(r.pose.x, truth.x, 1e-6) << tp.stamp;
    ASSERT_NEAR(r.pose.y, truth.y, 1e-6) << tp.stamp;
    ASSERT_NEAR(normalizeAngle(r.pose.theta - truth.theta), 0.0, 1e-9) << tp.stamp;
    ASSERT_NEAR(r.v, tp.v, 0.03) << tp.stamp;  // the mean over the last step, not the instant's
  }
}

TEST(WheelOdometrySim, ScaleErrorsGiveTheDocumentedDistanceAndHeadingErrors) {
  // Slip off: the distance is off by the mean scale error, the heading by the difference over the base.
  WheelOdometryConfig config;
  config.slip = 0.0;
  config.scale_error = 0.02;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    WheelOdometrySimulator sim(config, seed);
    EXPECT_LE(std::abs(sim.leftScale() - 1.0), 0.02);
    EXPECT_LE(std::abs(sim.rightScale() - 1.0), 0.02);
    // Straight 10 m.
    const auto path = samplePath(std::vector<Eigen::Vector2d>{{0, 0}, {10, 0}}, 20.0);
    WheelOdometryReading r;
    for (const TimedPose& tp : path) r = sim.step(tp);
    const double mean = 0.5 * (sim.leftScale() + sim.rightScale());
    EXPECT_NEAR(r.distance, 10.0 * mean, 1e-9);
    EXPECT_NEAR(r.pose.theta, 10.0 * (sim.rightScale() - sim.leftScale()) / config.wheel_base, 1e-9);
  }
}

TEST(WheelOdometrySim, SlipIsARandomWalkOfTheDocumentedSize) {
  WheelOdometryConfig config;
  config.scale_error = 0.0;
  config.slip = 0.002;
  // Straight 10 m: the heading error is (slip_r - slip_l) / base, each wheel's slip ~ N(0, slip² · 10 m).
  const double expected = std::sqrt(2.0 * 10.0) * config.slip / config.wheel_base;
  double sum2 = 0.0;
  const int runs = 200;
  const auto path = samplePath(std::vector<Eigen::Vector2d>{{0, 0}, {10, 0}}, 20.0);
  for (int seed = 0; seed < runs; ++seed) {
    WheelOdometrySimulator sim(config, static_cast<std::uint64_t>(seed));
    WheelOdometryReading r;
    for (const TimedPose& tp : path) r = sim.step(tp);
    sum2 += r.pose.theta * r.pose.theta;
  }
  EXPECT_NEAR(std::sqrt(sum2 / runs), expected, 0.15 * expected);
  // Seeded: the same seed, the same odometry.
  const WheelOdometryReading a = drive(WheelOdometryConfig(), 9), b = drive(WheelOdometryConfig(), 9);
  EXPECT_EQ(a.pose.x, b.pose.x);
  EXPECT_NE(a.pose.x, drive(WheelOdometryConfig(), 10).pose.x);
}

}  // namespace
}  // namespace laser_dpslam
