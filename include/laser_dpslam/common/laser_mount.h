// Where the laser sits on the robot: the planar part of the static base_link→laser transform.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "laser_dpslam/common/pose2d.h"

namespace laser_dpslam {

/// p_base = A·p_laser + t. A is the top-left 2×2 block of the 3D rotation, so an upside-down laser
/// (roll = π) mirrors the scan as it should; for an upright laser A is a plain rotation.
struct LaserMount {
  Eigen::Matrix2d A = Eigen::Matrix2d::Identity();
  Eigen::Vector2d t = Eigen::Vector2d::Zero();

  static LaserMount fromPose(const Pose2D& p, bool upside_down = false) {
    LaserMount m;
    m.A = p.rotation();
    if (upside_down) m.A.col(1) = -m.A.col(1);  // laser y axis flipped
    m.t = p.translation();
    return m;
  }

  Eigen::Vector2d apply(const Eigen::Vector2d& p) const { return A * p + t; }

  std::vector<Eigen::Vector2d> apply(const std::vector<Eigen::Vector2d>& pts) const {
    std::vector<Eigen::Vector2d> out;
    out.reserve(pts.size());
    for (const auto& p : pts) out.push_back(A * p + t);
    return out;
  }
};

}  // namespace laser_dpslam
