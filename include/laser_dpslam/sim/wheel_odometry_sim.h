// Simulated wheel odometry of a differential-drive robot (an iRobot Create), for the simulator. No ROS.
#pragma once

#include <cstdint>
#include <random>

#include "laser_dpslam/common/pose2d.h"
#include "laser_dpslam/sim/sim_path.h"

namespace laser_dpslam {

/// Error model. Each wheel's travel is the true travel times (1 + its scale error) plus slip noise:
///   measured = true · (1 + e) + slip · sqrt(|true|) · N(0, 1)   (per step, per wheel)
/// with e drawn once per run, uniform in [−scale_error, scale_error], independently per wheel. The slip
/// term is a random walk: after D metres of travel a wheel's error has σ = slip · sqrt(D) (besides e·D).
/// A scale error common to both wheels makes the distance wrong by e; a difference between them turns the
/// heading by (e_r − e_l)·D / wheel_base (1 % over 0.258 m: 2.2° per metre driven).
struct WheelOdometryConfig {
  double wheel_base = 0.258;   ///< m, distance between the wheels (iRobot Create 1)
  double scale_error = 0.01;   ///< max |e| per wheel (fraction of the travel)
  double slip = 0.002;         ///< m per sqrt(m) of wheel travel
  /// Throws std::invalid_argument on a non-positive wheel base or negative errors.
  void validate() const;
};

/// One odometry reading: the pose integrated from the measured wheel travel in the odom frame (which is
/// the first true pose), and the velocity over the last step in the robot's frame.
struct WheelOdometryReading {
  double stamp = 0.0;  ///< as the truth's
  Pose2D pose;         ///< odom frame; starts at (0, 0, 0)
  double v = 0.0;      ///< m/s forward
  double w = 0.0;      ///< rad/s counter-clockwise
  double distance = 0.0;  ///< m, total measured travel of the robot's centre (for the covariance)
};

/// Turns successive true poses into wheel odometry. Its random stream is its own (seeded here), so that
/// adding wheel odometry to a simulation does not change its scans.
class WheelOdometrySimulator {
 public:
  WheelOdometrySimulator(const WheelOdometryConfig& config, std::uint64_t seed);

  /// The reading at `truth`, from the motion since the previous call (the first call returns the origin).
  /// Between calls the robot is assumed to drive straight or turn in place (what samplePath() drives).
  WheelOdometryReading step(const TimedPose& truth);

  double leftScale() const { return 1.0 + e_left_; }
  double rightScale() const { return 1.0 + e_right_; }
  const WheelOdometryConfig& config() const { return config_; }

 private:
  double uniform();
  double gaussian();
  double measure(double travel, double e);

  WheelOdometryConfig config_;
  std::mt19937_64 rng_;
  double e_left_ = 0.0, e_right_ = 0.0;
  bool started_ = false;
  TimedPose last_;
  WheelOdometryReading reading_;
};

}  // namespace laser_dpslam
