#include "laser_dpslam/slam/revisit_detector.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

using laser_dpslam::RevisitDetector;
using laser_dpslam::RevisitDetectorConfig;

namespace {
// Drives from `from` to `to` in steps of `step` m; returns how many of the steps were revisits.
int drive(RevisitDetector& d, const Eigen::Vector2d& from, const Eigen::Vector2d& to, double step = 0.03) {
  const double length = (to - from).norm();
  const int n = static_cast<int>(std::ceil(length / step));
  int revisits = 0;
  for (int i = 1; i <= n; ++i) revisits += d.update(from + (to - from) * (static_cast<double>(i) / n), length / n) ? 1 : 0;
  return revisits;
}
}  // namespace

TEST(RevisitDetector, ExploringAStraightCorridorIsNeverARevisit) {
  RevisitDetector d;
  EXPECT_EQ(drive(d, {0, 0}, {50, 0}), 0);
  EXPECT_NEAR(d.travel(), 50.0, 1e-9);
}

TEST(RevisitDetector, ComingBackAroundALoopIsARevisitOnlyNearTheOldPath) {
  RevisitDetector d;  // radius 2 m, 10 m of travel
  drive(d, {0, 0}, {10, 0});
  drive(d, {10, 0}, {10, 10});
  drive(d, {10, 10}, {0, 10});
  // Coming down the west side: 10 m away from the start at first, within 2 m of it only at the end.
  EXPECT_EQ(drive(d, {0, 10}, {0, 2.2}), 0);
  EXPECT_GT(drive(d, {0, 1.9}, {0, 0.5}), 0);
  EXPECT_TRUE(d.update({1.0, 0.2}, 0.01));
  // A side trip away from everything seen.
  EXPECT_FALSE(d.update({5.0, 5.0}, 0.01));
}

TEST(RevisitDetector, TurningBackWithinTheMinimumTravelIsNotARevisit) {
  RevisitDetector d;
  drive(d, {0, 0}, {4, 0});
  // Back over the same 4 m: the path there is less than 10 m of travel old until the very end.
  EXPECT_EQ(drive(d, {4, 0}, {0.5, 0}), 0);
  RevisitDetectorConfig c;
  c.min_travel = 3.0;
  RevisitDetector shorter(c);
  drive(shorter, {0, 0}, {4, 0});
  EXPECT_GT(drive(shorter, {4, 0}, {0.5, 0}), 0);
}

TEST(RevisitDetector, ResetForgetsThePathAndBadInputIsIgnored) {
  RevisitDetector d;
  drive(d, {0, 0}, {20, 0});
  drive(d, {20, 0}, {20, 1});
  EXPECT_TRUE(d.update({10, 0.5}, 0.0));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(d.update({nan, 0.0}, 0.1));
  EXPECT_FALSE(d.update({10, 0.5}, nan));
  EXPECT_FALSE(d.update({10, 0.5}, -1.0));
  EXPECT_NEAR(d.travel(), 21.0, 1e-9);
  d.reset();
  EXPECT_EQ(d.samples(), 0u);
  EXPECT_FALSE(d.update({10, 0.5}, 0.0));
  RevisitDetectorConfig bad;
  bad.radius = 0.0;
  EXPECT_THROW(RevisitDetector{bad}, std::invalid_argument);
}
