// The laser odometry's motion estimate: an extended Kalman filter over the robot's pose (x, y, θ, odometry
// frame) and its velocity in its own frame (vx, vy, ω), with a constant-velocity process model. Scan matches
// update the pose only along the directions they constrain, speed measurements (range flow, wheels) update the
// velocity, and along a direction nothing measures the state keeps its velocity while its covariance grows.
// The previous pose is kept in the state (stochastic cloning, Roumeliotis & Burdick 2002) so that the motion
// between two scans comes with its own covariance. No ROS.
#pragma once

#include <Eigen/Core>

#include "laser_dpslam/common/pose2d.h"

namespace laser_dpslam {

/// Process noise. The filter predicts with the "cruise" noise; a measurement that contradicts that
/// prediction beyond the gate is taken as a manoeuvre (the robot accelerates, brakes, starts or stops a
/// turn): the step is predicted again with the velocity free to change by up to the maximal acceleration
/// (Bar-Shalom, Li & Kirubarajan 2001, §11.2, manoeuvre detection with an adjustable process noise level).
struct MotionFilterConfig {
  /// m/s^1.5: √q of the white-noise acceleration while cruising. A robot driving a corridor keeps its speed
  /// to a few mm/s over seconds; a small q lets the velocity average many matches (a blank corridor is then
  /// crossed at the speed measured before it).
  double cruise_acceleration = 0.01;
  double cruise_angular_acceleration = 0.1;  ///< rad/s^1.5, the same for the turn rate
  double max_acceleration = 1.0;            ///< m/s², a manoeuvre's bound (iRobot Create: ~0.5 m/s²)
  double max_angular_acceleration = 6.0;    ///< rad/s², a manoeuvre's bound for the turn rate
  double initial_speed_sigma = 0.5;          ///< m/s, σ of the velocity at a start (the robot may be moving)
  double initial_turn_rate_sigma = 1.0;      ///< rad/s
};

class MotionFilter {
 public:
  using Vector9 = Eigen::Matrix<double, 9, 1>;
  using Matrix9 = Eigen::Matrix<double, 9, 9>;

  explicit MotionFilter(const MotionFilterConfig& config = MotionFilterConfig()) : config_(config) { reset(Pose2D()); }

  /// Starts at `pose` (known exactly) with an unknown velocity around zero.
  void reset(const Pose2D& pose);

  /// Predicts `dt` seconds ahead at constant velocity. The current pose becomes the previous one.
  /// `manoeuvre_xy` / `manoeuvre_theta`: the translation / turn-rate velocity may change by up to the
  /// maximal acceleration over dt.
  void predict(double dt, bool manoeuvre_xy = false, bool manoeuvre_theta = false);

  /// Normalised innovation squared of a pose measurement: `z` observed through the k×3 rows `rows` (an
  /// orthonormal basis of the directions it constrains, in the odometry frame) with covariance `noise`
  /// (k×k). Split into its translation part (rows with a translation component) and rotation part.
  void poseInnovation(const Pose2D& z, const Eigen::MatrixXd& rows, const Eigen::MatrixXd& noise, double* nis_xy,
                      double* nis_theta) const;
  /// Kalman update with that measurement.
  void updatePose(const Pose2D& z, const Eigen::MatrixXd& rows, const Eigen::MatrixXd& noise);

  /// Normalised innovation squared of a speed measurement `speed` = row·(vx, vy, ω) with variance `variance`.
  double velocityInnovation(const Eigen::Vector3d& row, double speed, double variance) const;
  /// Kalman update with that measurement.
  void updateVelocity(const Eigen::Vector3d& row, double speed, double variance);

  Pose2D pose() const { return Pose2D(x_.segment<3>(3)); }
  Pose2D previousPose() const { return Pose2D(x_.head<3>()); }
  Eigen::Vector3d velocity() const { return x_.tail<3>(); }
  Eigen::Matrix3d poseCovariance() const { return P_.block<3, 3>(3, 3); }
  Eigen::Matrix3d velocityCovariance() const { return P_.block<3, 3>(6, 6); }
  /// The motion from the previous pose to the current one (in the previous pose's frame) and its covariance.
  Pose2D delta() const { return between(previousPose(), pose()); }
  Eigen::Matrix3d deltaCovariance() const;

  const MotionFilterConfig& config() const { return config_; }

 private:
  /// Generic linear(ised) Kalman update: innovation y, measurement Jacobian H (k×9), noise R (k×k).
  void update(const Eigen::VectorXd& y, const Eigen::MatrixXd& H, const Eigen::MatrixXd& R);

  MotionFilterConfig config_;
  Vector9 x_ = Vector9::Zero();  ///< previous pose, pose, velocity
  Matrix9 P_ = Matrix9::Zero();
};

}  // namespace laser_dpslam
