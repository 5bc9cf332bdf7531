#include "laser_dpslam/slam/motion_covariance.h"

#include <cmath>

namespace laser_dpslam {

namespace {
/// Seconds of a duration in ns, converted as a ROS duration converts itself (whole seconds + 1e-9 × the
/// nanoseconds left), so that one interval gives the same dt as the node computed from its stamps.
double seconds(std::int64_t ns) {
  std::int64_t sec = ns / 1000000000;
  std::int64_t nsec = ns % 1000000000;
  if (nsec < 0) {
    nsec += 1000000000;
    --sec;
  }
  return static_cast<double>(sec) + 1e-9 * static_cast<double>(nsec);
}
}  // namespace

void composeMotion(Pose2D& motion, Eigen::Matrix3d& cov, const Pose2D& step, const Eigen::Matrix3d& step_cov) {
  Eigen::Matrix3d ja, jb;
  composeJacobians(motion, step, &ja, &jb);
  cov = ja * cov * ja.transpose() + jb * step_cov * jb.transpose();
  motion = motion * step;
}

bool MotionCovarianceWindow::add(std::int64_t stamp_ns, const Pose2D& pose, const Eigen::Matrix3d& velocity_cov) {
  if (!samples_.empty() && stamp_ns <= samples_.back().stamp_ns) return false;
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta) || !velocity_cov.allFinite()) {
    return false;
  }
  samples_.push_back({stamp_ns, pose, velocity_cov});
  while (samples_.size() > capacity_) samples_.pop_front();
  return true;
}

Eigen::Matrix3d MotionCovarianceWindow::deltaCovariance(std::int64_t from_ns, const Pose2D& from_pose,
                                                        std::int64_t to_ns) const {
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  if (to_ns <= from_ns) return cov;
  Pose2D motion;  // composed since from_pose
  Pose2D previous_pose = from_pose;
  std::int64_t previous_ns = from_ns;
  for (const Sample& s : samples_) {
    if (s.stamp_ns <= from_ns) continue;
    if (s.stamp_ns > to_ns) break;
    const double dt = seconds(s.stamp_ns - previous_ns);
    composeMotion(motion, cov, between(previous_pose, s.pose), s.velocity_cov * dt * dt);
    previous_pose = s.pose;
    previous_ns = s.stamp_ns;
  }
  // The stamps increase, so the last message used has the stamp to_ns exactly when one does.
  return previous_ns == to_ns ? cov : Eigen::Matrix3d::Zero();
}

void MotionCovarianceWindow::dropUntil(std::int64_t stamp_ns) {
  while (!samples_.empty() && samples_.front().stamp_ns <= stamp_ns) samples_.pop_front();
}

}  // namespace laser_dpslam
