#include "laser_dpslam/slam/trajectory_smoother.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

using namespace laser_dpslam;

namespace {

// 60 s at 10 Hz along a circle of radius 2 m at 0.3 m/s: the heading crosses ±π several times.
std::vector<StampedPose> circle() {
  std::vector<StampedPose> out;
  for (int i = 0; i < 600; ++i) {
    const double t = 100.0 + 0.1 * i, a = 0.15 * (t - 100.0);
    out.push_back({t, Pose2D(2.0 * std::sin(a), 2.0 - 2.0 * std::cos(a), normalizeAngle(a))});
  }
  return out;
}

// The same motion seen from another frame (the odometry's frame is not the map's).
std::vector<StampedPose> inFrame(const std::vector<StampedPose>& p, const Pose2D& frame) {
  std::vector<StampedPose> out = p;
  for (auto& s : out) s.pose = frame * s.pose;
  return out;
}

double rmsError(const std::vector<StampedPose>& a, const std::vector<StampedPose>& b, double* rms_theta = nullptr) {
  double s = 0.0, st = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    s += std::pow(a[i].pose.x - b[i].pose.x, 2) + std::pow(a[i].pose.y - b[i].pose.y, 2);
    st += std::pow(normalizeAngle(a[i].pose.theta - b[i].pose.theta), 2);
  }
  if (rms_theta) *rms_theta = std::sqrt(st / a.size());
  return std::sqrt(s / a.size());
}

}  // namespace

TEST(TrajectorySmoother, AConstantCorrectionLeavesThePathUnchanged) {
  const std::vector<StampedPose> path = circle();
  const std::vector<StampedPose> motion = inFrame(path, Pose2D(-3.0, 1.5, 2.5));
  for (double sigma : {0.0, 0.3, 1.0, 5.0}) {
    double rms_theta = 0.0;
    EXPECT_LT(rmsError(smoothTrajectory(path, motion, sigma), path, &rms_theta), 1e-9) << sigma;
    EXPECT_LT(rms_theta, 1e-9) << sigma;
  }
}

TEST(TrajectorySmoother, ZeroSigmaReturnsThePathAsItIs) {
  std::vector<StampedPose> path = circle(), motion = circle();
  path[10].pose.x += 0.5;
  const std::vector<StampedPose> out = smoothTrajectory(path, motion, 0.0);
  ASSERT_EQ(out.size(), path.size());
  EXPECT_EQ(out[10].pose.x, path[10].pose.x);
}

// The SLAM path = the truth plus a per-pose jitter (the particle's proposal noise); the motion = the truth
// with a little jitter of its own, in another frame. The smoothed path is much closer to the truth.
TEST(TrajectorySmoother, TakesOutThePathsJitterKeepingTheMotionsShape) {
  const std::vector<StampedPose> truth = circle();
  std::mt19937 rng(7);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::vector<StampedPose> path = truth, motion = inFrame(truth, Pose2D(5.0, -2.0, -1.0));
  for (auto& s : path) s.pose = s.pose * Pose2D(0.01 * n01(rng), 0.01 * n01(rng), 0.003 * n01(rng));
  for (auto& s : motion) s.pose = s.pose * Pose2D(0.001 * n01(rng), 0.001 * n01(rng), 0.0003 * n01(rng));
  double raw_theta = 0.0, smooth_theta = 0.0;
  const double raw = rmsError(path, truth, &raw_theta);
  const std::vector<StampedPose> out = smoothTrajectory(path, motion, 1.0);
  const double smooth = rmsError(out, truth, &smooth_theta);
  EXPECT_NEAR(raw, 0.014, 0.002);  // √2 × 1 cm
  // The window weighs ~35 poses' worth (2√π σ / 0.1 s), so the jitter drops ~6× (less the motion's own and
  // the heading jitter's lever arm): under a third of it is left.
  EXPECT_LT(smooth, raw / 3.0) << smooth << " against " << raw;
  EXPECT_LT(smooth_theta, raw_theta / 3.0) << smooth_theta << " against " << raw_theta;
  for (std::size_t i = 0; i < out.size(); ++i) EXPECT_EQ(out[i].stamp, path[i].stamp);
}

// A slowly drifting odometry (its heading off by 0.01 rad per second) under an exact SLAM path: the
// correction changes slowly, and the smoothed path stays on the SLAM's, not the odometry's.
TEST(TrajectorySmoother, FollowsTheSlamWhereTheOdometryDrifts) {
  const std::vector<StampedPose> truth = circle();
  std::vector<StampedPose> motion = truth;
  Pose2D drifted;
  for (std::size_t i = 1; i < motion.size(); ++i) {
    Pose2D step = between(truth[i - 1].pose, truth[i].pose);
    step.theta += 0.001;  // 0.01 rad/s at 10 Hz
    drifted = drifted * step;
    motion[i].pose = drifted;
  }
  motion[0].pose = Pose2D();
  const double odometry_error = rmsError(inFrame(motion, truth[0].pose), truth);
  EXPECT_GT(odometry_error, 0.3);  // the drift is large (0.66 m RMS): it is not the motion that comes out
  EXPECT_LT(rmsError(smoothTrajectory(truth, motion, 1.0), truth), 0.005);
}

// A loop closure: the SLAM path jumps 0.1 m sideways at t = 130 s. The smoothed path spreads the jump over
// about ±2σ and is the SLAM's again 4σ away from it.
TEST(TrajectorySmoother, SpreadsAJumpOverTheWindow) {
  const std::vector<StampedPose> truth = circle();
  std::vector<StampedPose> path = truth;
  for (auto& s : path) {
    if (s.stamp >= 130.0) s.pose.y += 0.1;
  }
  const std::vector<StampedPose> out = smoothTrajectory(path, truth, 1.0);
  double largest_step_error = 0.0;
  for (std::size_t i = 1; i < out.size(); ++i) {
    const Pose2D d = between(out[i - 1].pose, out[i].pose), t = between(truth[i - 1].pose, truth[i].pose);
    largest_step_error = std::max(largest_step_error, std::hypot(d.x - t.x, d.y - t.y));
    if (std::abs(out[i].stamp - 130.0) > 4.05) {
      EXPECT_NEAR(out[i].pose.y, path[i].pose.y, 1e-9) << out[i].stamp;
    }
  }
  // Gaussian CDF: at most 0.1 × 0.1 / (√(2π) σ) ≈ 4 mm of the jump per step, against 0.1 m in the path.
  EXPECT_LT(largest_step_error, 0.005);
  EXPECT_GT(largest_step_error, 0.002);
}

TEST(TrajectorySmoother, MismatchedInputsAreRejected) {
  std::vector<StampedPose> path = circle(), motion = circle();
  motion.pop_back();
  EXPECT_THROW(smoothTrajectory(path, motion, 1.0), std::invalid_argument);
  motion = circle();
  motion[5].stamp += 0.01;
  EXPECT_THROW(smoothTrajectory(path, motion, 1.0), std::invalid_argument);
  EXPECT_TRUE(smoothTrajectory({}, {}, 1.0).empty());
}
