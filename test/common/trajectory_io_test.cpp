#include "laser_dpslam/common/trajectory_io.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace laser_dpslam;

TEST(InterpolatePose, LinearBetweenNeighboursAndExactAtSamples) {
  const std::vector<StampedPose> poses{{1.0, Pose2D(0.0, 0.0, 0.0)}, {2.0, Pose2D(1.0, 2.0, 0.4)}, {4.0, Pose2D(3.0, 2.0, 0.0)}};
  Pose2D p;
  ASSERT_TRUE(interpolatePose(poses, 1.5, &p));
  EXPECT_NEAR(p.x, 0.5, 1e-12);
  EXPECT_NEAR(p.y, 1.0, 1e-12);
  EXPECT_NEAR(p.theta, 0.2, 1e-12);
  ASSERT_TRUE(interpolatePose(poses, 3.0, &p));
  EXPECT_NEAR(p.x, 2.0, 1e-12);
  EXPECT_NEAR(p.theta, 0.2, 1e-12);
  ASSERT_TRUE(interpolatePose(poses, 2.0, &p));
  EXPECT_NEAR(p.y, 2.0, 1e-12);
  ASSERT_TRUE(interpolatePose(poses, 1.0, &p));
  EXPECT_NEAR(p.x, 0.0, 1e-12);
  ASSERT_TRUE(interpolatePose(poses, 4.0, &p));
  EXPECT_NEAR(p.x, 3.0, 1e-12);
}

TEST(InterpolatePose, HeadingTakesTheShortArcAcrossPi) {
  const std::vector<StampedPose> poses{{0.0, Pose2D(0, 0, M_PI - 0.1)}, {1.0, Pose2D(0, 0, -M_PI + 0.1)}};
  Pose2D p;
  ASSERT_TRUE(interpolatePose(poses, 0.5, &p));
  EXPECT_NEAR(std::abs(p.theta), M_PI, 1e-9);  // not 0, which the long way round would give
  ASSERT_TRUE(interpolatePose(poses, 0.25, &p));
  EXPECT_NEAR(p.theta, M_PI - 0.05, 1e-9);
}

TEST(InterpolatePose, NoExtrapolationAndNoAnswerFromNothing) {
  const std::vector<StampedPose> poses{{1.0, Pose2D(0, 0, 0)}, {2.0, Pose2D(1, 0, 0)}};
  Pose2D p(7, 7, 7);
  EXPECT_FALSE(interpolatePose(poses, 0.999, &p));
  EXPECT_FALSE(interpolatePose(poses, 2.001, &p));
  EXPECT_FALSE(interpolatePose(poses, std::nan(""), &p));
  EXPECT_FALSE(interpolatePose({}, 1.0, &p));
  EXPECT_EQ(p.x, 7.0);  // untouched
}
