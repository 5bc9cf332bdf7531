#include "laser_dpslam/odometry/wheel_motion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace laser_dpslam;

// At rest only the floors remain; driving 1 m straight adds 5 % of it in translation and the two wheels'
// 5 % apart over the Create's 0.258 m wheel base in heading; a turn on the spot adds 5 % of the turn.
TEST(WheelMotion, SigmaGrowsWithDistanceAndTurn) {
  const Eigen::Vector3d rest = wheelMotionSigma(Pose2D());
  EXPECT_NEAR(rest.x(), 0.001, 1e-12);
  EXPECT_NEAR(rest.y(), 0.001, 1e-12);
  EXPECT_NEAR(rest.z(), 0.001, 1e-12);
  const Eigen::Vector3d straight = wheelMotionSigma(Pose2D(1.0, 0.0, 0.0));
  EXPECT_NEAR(straight.x(), 0.051, 1e-12);
  EXPECT_NEAR(straight.z(), 0.05 / 0.258 + 0.001, 1e-12);
  const Eigen::Vector3d turn = wheelMotionSigma(Pose2D(0.0, 0.0, -1.0));
  EXPECT_NEAR(turn.x(), 0.001, 1e-12);
  EXPECT_NEAR(turn.z(), 0.051, 1e-12);
}

// A match that pins the motion down better than the wheels keeps its covariance, correlations included.
TEST(WheelMotion, ConstrainedMatchIsUnchanged) {
  const Eigen::Vector3d w(0.005, 0.005, 0.01);
  Eigen::Matrix3d c;
  c << 4e-6, 1e-6, 0.0, 1e-6, 9e-6, 2e-7, 0.0, 2e-7, 1e-5;
  const Eigen::Matrix3d b = boundedByWheels(c, w);
  EXPECT_LT((b - c).cwiseAbs().maxCoeff(), 1e-15);
}

// A ridge of the score in heading (the match's σθ ~ 28 rad, as an indefinite Hessian gives): the bound brings
// the heading to the wheels' σ and leaves the well-matched translation as it was.
TEST(WheelMotion, RidgeInHeadingIsBoundedByTheWheels) {
  const Eigen::Vector3d w(0.0025, 0.0025, 0.006);
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
  c(0, 0) = 9e-6;
  c(1, 1) = 8e-6;
  c(2, 2) = 785.0;
  const Eigen::Matrix3d b = boundedByWheels(c, w);
  EXPECT_NEAR(b(2, 2), w.z() * w.z(), 1e-12);
  EXPECT_NEAR(b(0, 0), std::min(c(0, 0), w.x() * w.x()), 1e-12);
  EXPECT_NEAR(b(1, 1), std::min(c(1, 1), w.y() * w.y()), 1e-12);
}

// A corridor at 30° to x: along it the match says 0.3 m, across 2 mm. Along it the wheels' σ comes out,
// across it the match's; no variance anywhere above the wheels'.
TEST(WheelMotion, DegenerateDirectionTakesTheWheelsVariance) {
  const Eigen::Vector3d w(0.0025, 0.0025, 0.006);
  const Eigen::Vector2d along(std::cos(M_PI / 6), std::sin(M_PI / 6)), across(-along.y(), along.x());
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
  c.topLeftCorner<2, 2>() = 0.09 * along * along.transpose() + 4e-6 * across * across.transpose();
  c(2, 2) = 1e-6;
  const Eigen::Matrix3d b = boundedByWheels(c, w);
  const Eigen::Matrix2d t = b.topLeftCorner<2, 2>();
  EXPECT_NEAR(along.dot(t * along), w.x() * w.x(), 1e-12);
  EXPECT_NEAR(across.dot(t * across), 4e-6, 1e-12);
  EXPECT_NEAR(b(2, 2), 1e-6, 1e-12);
}

// A non-finite covariance says nothing: the wheels' own.
TEST(WheelMotion, NonFiniteCovarianceGivesTheWheels) {
  const Eigen::Vector3d w(0.002, 0.003, 0.004);
  Eigen::Matrix3d c = Eigen::Matrix3d::Identity();
  c(1, 2) = std::numeric_limits<double>::quiet_NaN();
  const Eigen::Matrix3d b = boundedByWheels(c, w);
  EXPECT_TRUE(b.allFinite());
  EXPECT_NEAR(b(0, 0), 4e-6, 1e-15);
  EXPECT_NEAR(b(1, 1), 9e-6, 1e-15);
  EXPECT_NEAR(b(2, 2), 16e-6, 1e-15);
}
