#include "laser_dpslam/odometry/held_speed.h"

#include <gtest/gtest.h>

namespace laser_dpslam {
namespace {

const Eigen::Vector2d kAlong = Eigen::Vector2d::UnitX();

// The scan measures the motion for `seconds` at 10 Hz on one heading.
void observeFor(HeldSpeed& h, double heading, double seconds) {
  for (int i = 0; i < static_cast<int>(seconds * 10.0 + 0.5); ++i) h.observe(heading, 0.1);
}

TEST(HeldSpeed, TheFirstFitOfARunIsTakenAsItIs) {
  HeldSpeed h;
  EXPECT_FALSE(h.valid());
  EXPECT_DOUBLE_EQ(h.fuse(0.3, HeldSpeed::fitVariance(12.0), 0.0, kAlong), 0.3);
  EXPECT_TRUE(h.valid());
  EXPECT_DOUBLE_EQ(h.variance(), HeldSpeed::fitVariance(12.0));
}

TEST(HeldSpeed, AShortFitInsideABlankStretchBarelyMovesTheSpeed) {
  // 12 s of constrained matches before the stretch measured 0.2 m/s; inside it, two seconds of scans that
  // passed as constrained, fitted over half a second, read 15 % slow. Taken whole, 40 m of corridor would
  // end 6 m short.
  HeldSpeed h;
  h.fuse(0.2, HeldSpeed::fitVariance(12.0), 0.0, kAlong);
  observeFor(h, 0.0, 2.0);
  const double held = h.fuse(0.17, HeldSpeed::fitVariance(0.5), 0.01, kAlong);
  EXPECT_NEAR(held, 0.2, 0.002);
  EXPECT_LT(held, 0.2);
}

TEST(HeldSpeed, EqualFitsHalveTheVariance) {
  HeldSpeed h;
  h.fuse(0.2, HeldSpeed::fitVariance(6.0), 0.0, kAlong);
  EXPECT_NEAR(h.fuse(0.21, HeldSpeed::fitVariance(6.0), 0.0, kAlong), 0.205, 1e-12);
  EXPECT_NEAR(h.variance(), 0.5 * HeldSpeed::fitVariance(6.0), 1e-15);
}

TEST(HeldSpeed, AFitBeyondTheGateIsANewSpeed) {
  // The robot stopped where the scan saw it (and the fit says so over 3 s).
  HeldSpeed h;
  h.fuse(0.2, HeldSpeed::fitVariance(12.0), 0.0, kAlong);
  observeFor(h, 0.0, 1.0);
  EXPECT_DOUBLE_EQ(h.fuse(0.0, HeldSpeed::fitVariance(3.0), 0.0, kAlong), 0.0);
  EXPECT_DOUBLE_EQ(h.variance(), HeldSpeed::fitVariance(3.0));
}

TEST(HeldSpeed, TheSpeedMayChangeWhileTheScanMeasuresIt) {
  // A minute of constrained matches since the last fit: a new 12 s fit all but replaces it.
  HeldSpeed h;
  h.fuse(0.2, HeldSpeed::fitVariance(12.0), 0.0, kAlong);
  const double before = h.variance();
  observeFor(h, 0.0, 60.0);
  EXPECT_NEAR(h.variance(), before + HeldSpeed::kWalk * HeldSpeed::kWalk * 60.0, 1e-12);
  EXPECT_NEAR(h.fuse(0.21, HeldSpeed::fitVariance(12.0), 0.0, kAlong), 0.21, 5e-5);
}

TEST(HeldSpeed, ATurnStartsANewRun) {
  HeldSpeed h;
  h.fuse(0.2, HeldSpeed::fitVariance(12.0), 0.0, kAlong);
  observeFor(h, 0.2, 0.1);  // a constrained match after a turn
  EXPECT_FALSE(h.valid());
  EXPECT_DOUBLE_EQ(h.fuse(0.17, HeldSpeed::fitVariance(0.5), 0.2, kAlong), 0.17);
  // A fit at another heading without a constrained match in between is a new run as well.
  EXPECT_DOUBLE_EQ(h.fuse(0.3, HeldSpeed::fitVariance(0.5), 1.0, kAlong), 0.3);
}

TEST(HeldSpeed, TheDirectionsSignIsArbitrary) {
  // The same corridor's weak direction may come back flipped: the speed along it flips with it.
  HeldSpeed h;
  h.fuse(0.2, HeldSpeed::fitVariance(12.0), 0.0, kAlong);
  const double held = h.fuse(-0.17, HeldSpeed::fitVariance(0.5), 0.0, -kAlong);
  EXPECT_NEAR(held, -0.2, 0.002);
}

TEST(HeldSpeed, ResetForgetsTheRun) {
  HeldSpeed h;
  h.fuse(0.2, HeldSpeed::fitVariance(12.0), 0.0, kAlong);
  h.reset();
  EXPECT_FALSE(h.valid());
  EXPECT_DOUBLE_EQ(h.fuse(0.17, HeldSpeed::fitVariance(0.5), 0.0, kAlong), 0.17);
}

}  // namespace
}  // namespace laser_dpslam
