#include "laser_dpslam/slam/motion_covariance.h"

#include <gtest/gtest.h>

using namespace laser_dpslam;

namespace {
constexpr std::int64_t kPeriod = 100000000;  // ns: 10 Hz
constexpr std::int64_t kT0 = 1000LL * 1000000000LL;

Eigen::Matrix3d diag(double a, double b, double c) { return Eigen::Vector3d(a, b, c).asDiagonal(); }
}  // namespace

// No scan skipped: the message at the scan's stamp, its velocity covariance × dt², bit for bit.
TEST(MotionCovariance, OneIntervalIsTheMessagesCovarianceTimesDtSquared) {
  MotionCovarianceWindow w;
  Eigen::Matrix3d v;
  v << 0.04, 0.01, 0.002, 0.01, 0.09, 0.003, 0.002, 0.003, 0.01;
  ASSERT_TRUE(w.add(kT0, Pose2D(), diag(1, 1, 1)));
  ASSERT_TRUE(w.add(kT0 + kPeriod, Pose2D(0.05, 0.0, 0.01), v));
  const Eigen::Matrix3d c = w.deltaCovariance(kT0, Pose2D(), kT0 + kPeriod);
  const double dt = 0.1;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(c(r, k), v(r, k) * dt * dt);
}

TEST(MotionCovariance, ZeroWithoutAMessageAtTheScansStamp) {
  MotionCovarianceWindow w;
  EXPECT_TRUE(w.deltaCovariance(kT0, Pose2D(), kT0 + kPeriod).isZero());
  w.add(kT0 + kPeriod / 2, Pose2D(), diag(1, 1, 1));  // e.g. 20 Hz wheel odometry between scan stamps
  w.add(kT0 + kPeriod + 1, Pose2D(), diag(1, 1, 1));
  EXPECT_TRUE(w.deltaCovariance(kT0, Pose2D(), kT0 + kPeriod).isZero());
  EXPECT_TRUE(w.deltaCovariance(kT0 + kPeriod, Pose2D(), kT0 + kPeriod).isZero());
}

// Skipped scans: n messages along a straight line compose to n × each one's translation variance (not
// n² × the last one's), plus the heading errors of earlier steps carried across over the later distance.
TEST(MotionCovariance, SkippedScansComposeAlongTheMotion) {
  const double sxx = 0.01, syy = 0.02, stt = 0.03, d = 0.04, dt = 0.1;
  const int n = 5;
  MotionCovarianceWindow w;
  w.add(kT0 - kPeriod, Pose2D(-d, 0.0, 0.0), diag(9, 9, 9));  // before the interval: not counted
  w.add(kT0, Pose2D(), diag(9, 9, 9));                        // at its start: not counted
  for (int k = 1; k <= n; ++k) w.add(kT0 + k * kPeriod, Pose2D(k * d, 0.0, 0.0), diag(sxx, syy, stt));
  w.add(kT0 + (n + 1) * kPeriod, Pose2D((n + 1) * d, 0.0, 0.0), diag(9, 9, 9));  // after it: not counted
  const Eigen::Matrix3d c = w.deltaCovariance(kT0, Pose2D(), kT0 + n * kPeriod);
  double sum_sq = 0.0, sum = 0.0;  // distances after each step's heading error: (n − j)·d, j = 1..n
  for (int j = 1; j <= n; ++j) {
    sum_sq += (n - j) * (n - j) * d * d;
    sum += (n - j) * d;
  }
  EXPECT_NEAR(c(0, 0), n * sxx * dt * dt, 1e-15);
  EXPECT_NEAR(c(1, 1), n * syy * dt * dt + stt * dt * dt * sum_sq, 1e-15);
  EXPECT_NEAR(c(2, 2), n * stt * dt * dt, 1e-15);
  EXPECT_NEAR(c(1, 2), stt * dt * dt * sum, 1e-15);
  EXPECT_NEAR(c(2, 1), c(1, 2), 1e-18);
  EXPECT_NEAR(c(0, 1), 0.0, 1e-18);
  EXPECT_NEAR(c(0, 2), 0.0, 1e-18);
  // The covariance of the last message alone over the whole interval: n² as large in x.
  EXPECT_NEAR(sxx * (n * dt) * (n * dt) / c(0, 0), n, 1e-9);
}

// Each step's covariance lives in the base frame before it: turned by the heading reached so far.
TEST(MotionCovariance, LaterStepsAreTurnedIntoTheFirstFrame) {
  MotionCovarianceWindow w;
  w.add(kT0 + kPeriod, Pose2D(0.0, 0.0, M_PI / 2), diag(0.0, 0.0, 0.0));  // a turn in place, exact
  w.add(kT0 + 2 * kPeriod, Pose2D(0.0, 0.1, M_PI / 2), diag(1.0, 0.0, 0.0));  // error along its own x
  const Eigen::Matrix3d c = w.deltaCovariance(kT0, Pose2D(), kT0 + 2 * kPeriod);
  EXPECT_NEAR(c(0, 0), 0.0, 1e-15);
  EXPECT_NEAR(c(1, 1), 0.01, 1e-15);  // the first frame's y
}

TEST(MotionCovariance, KeepsOrderCapacityAndForgetsWhatIsBehind) {
  MotionCovarianceWindow w(3);
  EXPECT_TRUE(w.add(kT0, Pose2D(), diag(1, 1, 1)));
  EXPECT_FALSE(w.add(kT0, Pose2D(), diag(1, 1, 1)));  // same stamp
  EXPECT_FALSE(w.add(kT0 - 1, Pose2D(), diag(1, 1, 1)));
  EXPECT_FALSE(w.add(kT0 + 1, Pose2D(std::nan(""), 0, 0), diag(1, 1, 1)));
  for (int k = 1; k <= 4; ++k) EXPECT_TRUE(w.add(kT0 + k * kPeriod, Pose2D(), diag(1, 1, 1)));
  EXPECT_EQ(w.size(), 3u);
  EXPECT_EQ(w.newestStamp(), kT0 + 4 * kPeriod);
  w.dropUntil(kT0 + 3 * kPeriod);
  EXPECT_EQ(w.size(), 1u);
  w.clear();
  EXPECT_TRUE(w.empty());
  EXPECT_EQ(w.newestStamp(), 0);
}

// dpslam_offline composes each scan's delta and delta covariance with composeMotion; the node gets the
// same from the window over the odometry's messages: both must agree (to rounding of dt).
TEST(MotionCovariance, ComposeMotionPerScanEqualsTheWindow) {
  const double dt = 0.1;
  const Pose2D poses[] = {Pose2D(), Pose2D(0.05, 0.01, 0.1), Pose2D(0.09, 0.03, 0.25), Pose2D(0.12, 0.08, 0.4)};
  Eigen::Matrix3d v;
  v << 0.04, 0.01, 0.002, 0.01, 0.09, 0.003, 0.002, 0.003, 0.01;
  MotionCovarianceWindow w;
  Pose2D motion;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int k = 0; k < 4; ++k) {
    const Eigen::Matrix3d vk = (1.0 + k) * v;
    w.add(kT0 + k * kPeriod, poses[k], vk);
    if (k > 0) composeMotion(motion, cov, between(poses[k - 1], poses[k]), vk * dt * dt);
  }
  const Eigen::Matrix3d c = w.deltaCovariance(kT0, poses[0], kT0 + 3 * kPeriod);
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(c(r, k), cov(r, k), 1e-16);
  const Pose2D end = between(poses[0], poses[3]);
  EXPECT_NEAR(motion.x, end.x, 1e-12);
  EXPECT_NEAR(motion.y, end.y, 1e-12);
  EXPECT_NEAR(motion.theta, end.theta, 1e-12);
}
