#include "laser_dpslam/odometry/range_flow.h"

#include <gtest/gtest.h>

#include "laser_dpslam/sim/scan_simulator.h"
#include "test_rooms.h"

using namespace laser_dpslam;

namespace {

// A 2.4 m wide corridor along x (walls at y = 1 and 3.4) with a wall across it at x = 6 ("end"), or without.
FloorPlan corridor(bool with_end) {
  std::vector<test::Box> boxes{{0.0, 0.9, 12.0, 1.0}, {0.0, 3.4, 12.0, 3.5}};
  if (with_end) boxes.push_back({6.0, 1.0, 6.1, 3.4});
  return test::planFromBoxes(12.0, 4.4, 0.02, boxes);
}

ScanSimulatorConfig quiet() {
  ScanSimulatorConfig c;
  c.dropout_probability = 0.0;
  c.grazing_dropout_probability = 0.0;
  return c;
}

// Scans at x0 and x0 + step (heading +x, y = 2.2) and the flow along +x for the given motion estimate.
RangeFlow flowBetween(const FloorPlan& plan, double step, const Pose2D& estimate, std::uint64_t seed,
                      const ScanSimulatorConfig& sim_config = quiet(), const LaserMount& mount = LaserMount()) {
  ScanSimulator sim(plan, sim_config, seed);
  const Pose2D a(2.0, 2.2, 0.0), b = a * Pose2D(step, 0.0, 0.0);
  const Pose2D ma(mount.t.x(), mount.t.y(), std::atan2(mount.A(1, 0), mount.A(0, 0)));
  const PreprocessedScan s0 = preprocessScan(sim.simulate(a * ma, 100.0), ScanPreprocessorConfig());
  const PreprocessedScan s1 = preprocessScan(sim.simulate(b * ma, 100.1), ScanPreprocessorConfig());
  return measureRangeFlow(s0, s1, mount, estimate, Eigen::Vector2d(1.0, 0.0), 0.1);
}

}  // namespace

TEST(RangeFlow, MeasuresTheSpeedTowardsAWallAcross) {
  const FloorPlan plan = corridor(true);
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    // Whatever the estimate says along x (the match's prior): 0, the truth, or twice it.
    for (double guess : {0.0, 0.03, 0.06}) {
      const RangeFlow f = flowBetween(plan, 0.03, Pose2D(guess, 0.0, 0.0), seed);
      ASSERT_TRUE(f.valid) << "seed " << seed;
      EXPECT_NEAR(f.speed, 0.3, 3.0 * f.sigma + 0.01) << "seed " << seed << " guess " << guess;
      EXPECT_LT(f.sigma, 0.1);  // the wall 4 m ahead: 1 % range noise, 4 cm
      EXPECT_GE(f.beams, 20);
    }
    // Standing still reads as standing still.
    const RangeFlow still = flowBetween(plan, 0.0, Pose2D(0.03, 0.0, 0.0), seed);
    ASSERT_TRUE(still.valid);
    EXPECT_NEAR(still.speed, 0.0, 3.0 * still.sigma + 0.01) << "seed " << seed;
  }
}

TEST(RangeFlow, SaysNothingInAPlainCorridor) {
  // The end wall 8+ m ahead is out of the URG's 5.6 m: only walls along the motion are in view.
  const FloorPlan plan = corridor(false);
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    EXPECT_FALSE(flowBetween(plan, 0.03, Pose2D(0.03, 0.0, 0.0), seed).valid) << "seed " << seed;
  }
}

TEST(RangeFlow, FollowsTheLaserMount) {
  // A laser 0.2 m ahead of base_link and turned 30°: the robot's speed along its own x is still measured.
  const LaserMount mount = LaserMount::fromPose(Pose2D(0.2, 0.05, 0.5236));
  const RangeFlow f = flowBetween(corridor(true), 0.04, Pose2D(0.0, 0.0, 0.0), 1, quiet(), mount);
  ASSERT_TRUE(f.valid);
  EXPECT_NEAR(f.speed, 0.4, 3.0 * f.sigma + 0.01);
}

TEST(RangeFlow, RefusesScansOfDifferentLayouts) {
  const FloorPlan plan = corridor(true);
  ScanSimulator sim(plan, quiet(), 1);
  LaserScan a = sim.simulate(Pose2D(2.0, 2.2, 0.0), 100.0), b = sim.simulate(Pose2D(2.03, 2.2, 0.0), 100.1);
  b.ranges.pop_back();  // one beam fewer
  b.angle_max -= b.angle_increment;
  const PreprocessedScan s0 = preprocessScan(a, ScanPreprocessorConfig()), s1 = preprocessScan(b, ScanPreprocessorConfig());
  ASSERT_TRUE(s1.ok()) << s1.error;
  EXPECT_FALSE(measureRangeFlow(s0, s1, LaserMount(), Pose2D(), Eigen::Vector2d(1.0, 0.0), 0.1).valid);
  EXPECT_FALSE(measureRangeFlow(s0, s0, LaserMount(), Pose2D(), Eigen::Vector2d(1.0, 0.0), 0.0).valid);  // no time
  EXPECT_FALSE(measureRangeFlow(PreprocessedScan(), s0, LaserMount(), Pose2D(), Eigen::Vector2d(1.0, 0.0), 0.1).valid);
}
