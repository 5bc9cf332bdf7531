#include "laser_dpslam/odometry/held_speed.h"

#include <cmath>

#include "laser_dpslam/common/pose2d.h"

namespace laser_dpslam {

bool HeldSpeed::sameRun(double a, double b) { return std::abs(normalizeAngle(a - b)) <= kStraightRunHeading; }

void HeldSpeed::observe(double heading, double dt) {
  if (!sameRun(heading, heading_)) {
    reset();
    return;
  }
  variance_ += kWalk * kWalk * dt;
}

double HeldSpeed::fuse(double v, double variance, double heading, const Eigen::Vector2d& direction) {
  const double last = direction_.dot(direction) < 0.0 ? -speed_ : speed_;
  if (sameRun(heading, heading_) && valid() && std::abs(v - last) <= kGate * std::sqrt(variance_ + variance)) {
    const double k = variance_ / (variance_ + variance);
    v = last + k * (v - last);
    variance = (1.0 - k) * variance_;
  }
  speed_ = v;
  variance_ = variance;
  heading_ = heading;
  direction_ = direction;
  return v;
}

}  // namespace laser_dpslam
