#include "laser_dpslam/sim/wheel_odometry_sim.h"

#include <cmath>
#include <stdexcept>

namespace laser_dpslam {

void WheelOdometryConfig::validate() const {
  if (!(wheel_base > 0.0) || !std::isfinite(wheel_base))
    throw std::invalid_argument("WheelOdometryConfig: wheel_base must be positive");
  if (!(scale_error >= 0.0 && scale_error < 1.0)) throw std::invalid_argument("WheelOdometryConfig: scale_error must be in [0, 1)");
  if (!(slip >= 0.0) || !std::isfinite(slip)) throw std::invalid_argument("WheelOdometryConfig: slip must be >= 0");
}

WheelOdometrySimulator::WheelOdometrySimulator(const WheelOdometryConfig& config, std::uint64_t seed)
    : config_(config), rng_(seed) {
  config_.validate();
  e_left_ = config_.scale_error * (2.0 * uniform() - 1.0);
  e_right_ = config_.scale_error * (2.0 * uniform() - 1.0);
}

double WheelOdometrySimulator::uniform() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }

double WheelOdometrySimulator::gaussian() {
  const double u1 = 1.0 - uniform();  // (0, 1]
  const double u2 = uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

double WheelOdometrySimulator::measure(double travel, double e) {
  const double g = gaussian();  // drawn even when standing still: keeps the stream aligned
  return travel * (1.0 + e) + config_.slip * std::sqrt(std::abs(travel)) * g;
}

WheelOdometryReading WheelOdometrySimulator::step(const TimedPose& truth) {
  if (!started_) {
    started_ = true;
    last_ = truth;
    reading_ = WheelOdometryReading();
    reading_.stamp = truth.stamp;
    return reading_;
  }
  // True wheel travel: forward distance along the mean heading, and the turn.
  const double dtheta = normalizeAngle(truth.pose.theta - last_.pose.theta);
  const double mid = last_.pose.theta + 0.5 * dtheta;
  const Eigen::Vector2d dp = truth.pose.translation() - last_.pose.translation();
  const double ds = dp.x() * std::cos(mid) + dp.y() * std::sin(mid);
  const double half = 0.5 * config_.wheel_base * dtheta;
  const double left = measure(ds - half, e_left_);
  const double right = measure(ds + half, e_right_);

  const double ds_m = 0.5 * (left + right);
  const double dth_m = (right - left) / config_.wheel_base;
  Pose2D& p = reading_.pose;
  const double heading = p.theta + 0.5 * dth_m;  // midpoint integration, as the Create driver does
  p.x += ds_m * std::cos(heading);
  p.y += ds_m * std::sin(heading);
  p.theta = normalizeAngle(p.theta + dth_m);
  const double dt = truth.stamp - last_.stamp;
  reading_.v = dt > 0.0 ? ds_m / dt : 0.0;
  reading_.w = dt > 0.0 ? dth_m / dt : 0.0;
  reading_.distance += std::abs(ds_m);
  reading_.stamp = truth.stamp;
  last_ = truth;
  return reading_;
}

}  // namespace laser_dpslam
