// The wheel odometry's error between two scans, and how it bounds a scan match's covariance. No ROS.
#pragma once

#include <Eigen/Core>

#include "laser_dpslam/common/pose2d.h"

namespace laser_dpslam {

/// σ (x, y, θ) of the wheel odometry's motion `motion` between two scans: a few per cent of the distance and
/// of the turn (encoder scale, slip), the two wheels' scale errors apart turning the heading over the distance
/// (differential drive), plus floors for quantisation and vibration at rest. Over a motion composed from
/// `scans` scans, the floors add up in variance.
Eigen::Vector3d wheelMotionSigma(const Pose2D& motion, int scans = 1);

/// The covariance `c` of a matched motion, never above the wheels' (σ `wheel_sigma`, independent axes) along
/// any direction: in coordinates where the wheels' error is unit, each principal variance of c above 1 is cut
/// to 1 (eigenvectors kept). Where the scan pins the motion down better than the wheels, c is unchanged; along
/// what it hardly constrains (a corridor's length, a ridge of the score, typically in heading) the match kept
/// the wheels' motion, and the wheels' variance is the honest one. A non-finite c gives the wheels'.
Eigen::Matrix3d boundedByWheels(const Eigen::Matrix3d& c, const Eigen::Vector3d& wheel_sigma);

}  // namespace laser_dpslam
