#include "laser_dpslam/odometry/motion_filter.h"

#include <gtest/gtest.h>

#include <Eigen/LU>

#include <cmath>

using namespace laser_dpslam;

namespace {
// Feeds the filter exact poses of a robot driving straight along x at `speed` for `scans` scans.
void driveStraight(MotionFilter& f, double speed, int scans, double dt = 0.1) {
  const Eigen::MatrixXd rows = Eigen::MatrixXd::Identity(3, 3);
  const Eigen::MatrixXd noise = Eigen::Vector3d(1e-6, 1e-6, 1e-6).asDiagonal();
  for (int k = 0; k < scans; ++k) {
    const Pose2D truth(f.pose().x + speed * dt, 0.0, 0.0);
    f.predict(dt);
    f.updatePose(truth, rows, noise);
  }
}
}  // namespace

TEST(MotionFilter, LearnsAConstantVelocityFromPoses) {
  MotionFilter f;
  driveStraight(f, 0.3, 50);
  EXPECT_NEAR(f.velocity().x(), 0.3, 0.005);
  EXPECT_NEAR(f.velocity().y(), 0.0, 0.005);
  EXPECT_NEAR(f.delta().x, 0.03, 0.001);
  EXPECT_LT(f.velocityCovariance()(0, 0), 0.01 * 0.01);
}

// Along a direction no measurement constrains (a blank corridor) the velocity is kept and the pose's
// variance along it grows with time, without bound; across it stays small.
TEST(MotionFilter, ABlankDirectionKeepsTheVelocityAndItsVarianceGrows) {
  MotionFilter f;
  driveStraight(f, 0.3, 50);
  Eigen::MatrixXd across(2, 3);
  across << 0, 1, 0, 0, 0, 1;
  const Eigen::MatrixXd noise = Eigen::Vector2d(1e-6, 1e-6).asDiagonal();
  double last_var = f.poseCovariance()(0, 0);
  const double x0 = f.pose().x;
  for (int k = 1; k <= 300; ++k) {
    f.predict(0.1);
    f.updatePose(Pose2D(f.pose().x + 1.0, 0.0, 0.0), across, noise);  // its x is ignored: not a row
    if (k % 50 == 0) {
      EXPECT_GT(f.poseCovariance()(0, 0), last_var);
      last_var = f.poseCovariance()(0, 0);
    }
  }
  EXPECT_NEAR(f.pose().x - x0, 0.3 * 30.0, 0.05);
  EXPECT_NEAR(f.velocity().x(), 0.3, 0.005);
  EXPECT_LT(f.poseCovariance()(1, 1), 1e-4);
}

// A speed measurement along one direction moves that velocity component only.
TEST(MotionFilter, ASpeedMeasurementMovesItsComponent) {
  MotionFilter f;
  driveStraight(f, 0.3, 50);
  const double vy = f.velocity().y();
  for (int k = 0; k < 20; ++k) {
    f.predict(0.1, true, false);
    f.updateVelocity(Eigen::Vector3d::UnitX(), 0.0, 0.01 * 0.01);
  }
  EXPECT_NEAR(f.velocity().x(), 0.0, 0.01);
  EXPECT_NEAR(f.velocity().y(), vy, 1e-3);
  EXPECT_GT(f.velocityInnovation(Eigen::Vector3d::UnitX(), 0.3, 0.01 * 0.01), 6.63);
}

// The manoeuvre's process noise lets the velocity follow a robot that stopped within a few scans of 5 mm
// matches; with the cruise noise alone the position lags and the velocity follows several times slower.
TEST(MotionFilter, AManoeuvreLetsTheVelocityChangeFast) {
  double speed[2], lag[2];
  for (int manoeuvre = 0; manoeuvre < 2; ++manoeuvre) {
    MotionFilter f;
    driveStraight(f, 0.3, 50);
    const Eigen::MatrixXd rows = Eigen::MatrixXd::Identity(3, 3);
    const Eigen::MatrixXd noise = Eigen::Vector3d(2.5e-5, 2.5e-5, 1e-6).asDiagonal();
    const double x = f.pose().x;
    for (int k = 0; k < 5; ++k) {
      f.predict(0.1, manoeuvre == 1, false);
      f.updatePose(Pose2D(x, 0.0, 0.0), rows, noise);  // stopped
    }
    speed[manoeuvre] = std::abs(f.velocity().x());
    lag[manoeuvre] = std::abs(f.pose().x - x);
  }
  EXPECT_LT(speed[1], 0.05);
  EXPECT_GT(speed[0], 3.0 * speed[1]);
  EXPECT_GT(lag[0], lag[1]);
}

// The delta's covariance: an exactly measured pose after an exactly measured pose gives a tiny one; a
// predicted one with an unknown velocity a large one along the motion.
TEST(MotionFilter, DeltaCovarianceFollowsWhatWasMeasured) {
  MotionFilter f;
  driveStraight(f, 0.3, 20);
  EXPECT_LT(f.deltaCovariance()(0, 0), 1e-5);
  f.reset(f.pose());
  f.predict(0.1);
  EXPECT_NEAR(f.deltaCovariance()(0, 0), std::pow(0.5 * 0.1, 2), 1e-4);
}
