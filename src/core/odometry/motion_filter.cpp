#include "laser_dpslam/odometry/motion_filter.h"

#include <Eigen/Cholesky>
#include <cmath>

namespace laser_dpslam {

void MotionFilter::reset(const Pose2D& pose) {
  x_.setZero();
  x_.head<3>() = pose.vector();
  x_.segment<3>(3) = pose.vector();
  P_.setZero();
  const double sv = config_.initial_speed_sigma, sw = config_.initial_turn_rate_sigma;
  P_.block<3, 3>(6, 6) = Eigen::Vector3d(sv * sv, sv * sv, sw * sw).asDiagonal();
}

void MotionFilter::predict(double dt, bool manoeuvre_xy, bool manoeuvre_theta) {
  const Pose2D p = pose();
  const Eigen::Vector3d v = velocity();
  const Pose2D step(v.x() * dt, v.y() * dt, v.z() * dt);
  Eigen::Matrix3d Ja, Jb;
  composeJacobians(p, step, &Ja, &Jb);
  // x = (previous, pose, velocity) → (pose, pose ⊕ v·dt, velocity).
  Matrix9 F = Matrix9::Zero();
  F.block<3, 3>(0, 3).setIdentity();
  F.block<3, 3>(3, 3) = Ja;
  F.block<3, 3>(3, 6) = Jb * dt;
  F.block<3, 3>(6, 6).setIdentity();
  x_.head<3>() = p.vector();
  x_.segment<3>(3) = (p * step).vector();
  // Process noise: white-noise acceleration of spectral density q in the robot's frame (the pose takes its
  // integral: q·dt³/3, q·dt²/2 across), plus a manoeuvre's change of velocity, up to a·dt (σ² = (a·dt)²/3,
  // uniform in ±a·dt) with its displacement over the step (half of it on average).
  const double qa = config_.cruise_acceleration * config_.cruise_acceleration;
  const double qw = config_.cruise_angular_acceleration * config_.cruise_angular_acceleration;
  const Eigen::Matrix3d q = Eigen::Vector3d(qa, qa, qw).asDiagonal();
  Matrix9 Q = Matrix9::Zero();
  Q.block<3, 3>(3, 3) = Jb * q * Jb.transpose() * (dt * dt * dt / 3.0);
  Q.block<3, 3>(3, 6) = Jb * q * (dt * dt / 2.0);
  Q.block<3, 3>(6, 3) = Q.block<3, 3>(3, 6).transpose();
  Q.block<3, 3>(6, 6) = q * dt;
  const double ma = manoeuvre_xy ? config_.max_acceleration * dt : 0.0;
  const double mw = manoeuvre_theta ? config_.max_angular_acceleration * dt : 0.0;
  if (ma > 0.0 || mw > 0.0) {
    const Eigen::Matrix3d m = Eigen::Vector3d(ma * ma / 3.0, ma * ma / 3.0, mw * mw / 3.0).asDiagonal();
    Eigen::Matrix<double, 9, 3> G = Eigen::Matrix<double, 9, 3>::Zero();
    G.block<3, 3>(3, 0) = Jb * (0.5 * dt);
    G.block<3, 3>(6, 0).setIdentity();
    Q += G * m * G.transpose();
  }
  P_ = F * P_ * F.transpose() + Q;
}

void MotionFilter::update(const Eigen::VectorXd& y, const Eigen::MatrixXd& H, const Eigen::MatrixXd& R) {
  const Eigen::MatrixXd S = H * P_ * H.transpose() + R;
  const Eigen::MatrixXd K = P_ * H.transpose() * S.ldlt().solve(Eigen::MatrixXd::Identity(S.rows(), S.cols()));
  x_ += K * y;
  x_(2) = normalizeAngle(x_(2));
  x_(5) = normalizeAngle(x_(5));
  // Joseph form: stays symmetric and positive semi-definite with an approximate gain.
  const Matrix9 IKH = Matrix9::Identity() - K * H;
  P_ = IKH * P_ * IKH.transpose() + K * R * K.transpose();
  P_ = 0.5 * (P_ + P_.transpose());
}

namespace {
Eigen::VectorXd poseResidual(const Pose2D& z, const Pose2D& p, const Eigen::MatrixXd& rows) {
  const Eigen::Vector3d d(z.x - p.x, z.y - p.y, normalizeAngle(z.theta - p.theta));
  return rows * d;
}
Eigen::MatrixXd poseJacobian(const Eigen::MatrixXd& rows) {
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(rows.rows(), 9);
  H.middleCols(3, 3) = rows;
  return H;
}
}  // namespace

void MotionFilter::poseInnovation(const Pose2D& z, const Eigen::MatrixXd& rows, const Eigen::MatrixXd& noise,
                                  double* nis_xy, double* nis_theta) const {
  *nis_xy = 0.0;
  *nis_theta = 0.0;
  const Eigen::VectorXd y = poseResidual(z, pose(), rows);
  const Eigen::MatrixXd H = poseJacobian(rows);
  const Eigen::MatrixXd S = H * P_ * H.transpose() + noise;
  // Each row on its own (the rows are orthonormal directions, mostly pure translation or pure heading).
  for (int i = 0; i < y.size(); ++i) {
    const double n = y(i) * y(i) / S(i, i);
    if (std::abs(rows(i, 2)) > 0.5) {
      *nis_theta += n;
    } else {
      *nis_xy += n;
    }
  }
}

void MotionFilter::updatePose(const Pose2D& z, const Eigen::MatrixXd& rows, const Eigen::MatrixXd& noise) {
  if (rows.rows() == 0) return;
  update(poseResidual(z, pose(), rows), poseJacobian(rows), noise);
}

double MotionFilter::velocityInnovation(const Eigen::Vector3d& row, double speed, double variance) const {
  const double y = speed - row.dot(velocity());
  const double s = row.dot(P_.block<3, 3>(6, 6) * row) + variance;
  return y * y / s;
}

void MotionFilter::updateVelocity(const Eigen::Vector3d& row, double speed, double variance) {
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(1, 9);
  H.block<1, 3>(0, 6) = row.transpose();
  Eigen::VectorXd y(1);
  y(0) = speed - row.dot(velocity());
  update(y, H, Eigen::MatrixXd::Constant(1, 1, variance));
}

Eigen::Matrix3d MotionFilter::deltaCovariance() const {
  // Δ = a⁻¹ ⊕ b: ∂Δ/∂a and ∂Δ/∂b.
  const Pose2D a = previousPose(), b = pose();
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  const double dx = b.x - a.x, dy = b.y - a.y;
  Eigen::Matrix<double, 3, 6> J;
  J << -c, -s, -s * dx + c * dy, c, s, 0,  //
      s, -c, -c * dx - s * dy, -s, c, 0,   //
      0, 0, -1, 0, 0, 1;
  return J * P_.topLeftCorner<6, 6>() * J.transpose();
}

}  // namespace laser_dpslam
