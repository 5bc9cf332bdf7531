// The covariance of the odometry's motion between two scans the SLAM uses, from an odometry source that
// publishes a velocity (twist) covariance with every message, as laser_odometry_node does (the scan
// match's delta covariance / scan_time², stamped with the scan's time). When the SLAM skips scans, the
// motion since its last scan spans several odometry messages: each one's own delta covariance
// (velocity covariance × its dt²) is composed to first order along the odometry's poses, as DpSlam::process
// composes the deltas of the scans it does not weight. The covariance of the last message times the whole
// interval squared would grow with the square of the scans skipped instead of with their number. No ROS.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <deque>

#include "laser_dpslam/common/pose2d.h"

namespace laser_dpslam {

/// motion ← motion ⊕ step, and cov ← the first-order covariance of that composition (the two independent).
/// The one way motion and its covariance are accumulated over scans: by DpSlam between filter updates, by
/// MotionCovarianceWindow over odometry messages, by dpslam_offline over scans the SLAM does not receive.
void composeMotion(Pose2D& motion, Eigen::Matrix3d& cov, const Pose2D& step, const Eigen::Matrix3d& step_cov);

class MotionCovarianceWindow {
 public:
  /// Keeps the newest `capacity` messages at most (20 s of 50 Hz wheel odometry by default).
  explicit MotionCovarianceWindow(std::size_t capacity = 1000) : capacity_(capacity) {}

  /// One odometry message: stamp in ns, the odometry's pose and the (x, y, θ) covariance of its velocity.
  /// A stamp not after the newest one kept is ignored (returns false), and so is a non-finite pose or
  /// covariance.
  bool add(std::int64_t stamp_ns, const Pose2D& pose, const Eigen::Matrix3d& velocity_cov);

  /// Covariance of the odometry's motion from (from_ns, from_pose) to to_ns, in the base frame at from_ns.
  /// Each message in (from_ns, to_ns] contributes its velocity covariance × dt² (dt: since the message
  /// before it, or since from_ns for the first), composed along the messages' poses. Zero when no message
  /// has the stamp to_ns (then the SLAM's parametric motion noise applies). With one message in the
  /// interval (no scan skipped) it is that message's velocity covariance × (to − from)², exactly.
  Eigen::Matrix3d deltaCovariance(std::int64_t from_ns, const Pose2D& from_pose, std::int64_t to_ns) const;

  /// Forgets the messages stamped up to `stamp_ns` (they are behind the last scan used).
  void dropUntil(std::int64_t stamp_ns);
  void clear() { samples_.clear(); }

  bool empty() const { return samples_.empty(); }
  std::size_t size() const { return samples_.size(); }
  /// Stamp of the newest message kept (0 when empty).
  std::int64_t newestStamp() const { return samples_.empty() ? 0 : samples_.back().stamp_ns; }

 private:
  struct Sample {
    std::int64_t stamp_ns;
    Pose2D pose;
    Eigen::Matrix3d velocity_cov;
  };
  std::size_t capacity_;
  std::deque<Sample> samples_;
};

}  // namespace laser_dpslam
