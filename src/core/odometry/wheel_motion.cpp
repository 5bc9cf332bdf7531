#include "laser_dpslam/odometry/wheel_motion.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace laser_dpslam {

namespace {
// σ of the wheels' motion between two scans: kWheelScaleSigma of the distance (encoder scale error, slip on
// carpet or at a bump: a few per cent) plus kWheelMinSigma (quantisation, vibration at rest).
constexpr double kWheelScaleSigma = 0.05;
constexpr double kWheelMinSigma = 0.001;  // m
// σ of their heading change: kWheelScaleSigma of the turn, plus the two wheels' scale errors apart over the
// distance driven (heading error (e_r − e_l)·d / wheel base, iRobot Create), plus kWheelMinSigmaTheta.
constexpr double kWheelBase = 0.258;             // m
constexpr double kWheelMinSigmaTheta = 0.001;    // rad
}  // namespace

Eigen::Vector3d wheelMotionSigma(const Pose2D& motion, int scans) {
  const double d = std::hypot(motion.x, motion.y);
  const double floors = std::sqrt(static_cast<double>(std::max(1, scans)));
  const double sigma_xy = kWheelScaleSigma * d + floors * kWheelMinSigma;
  return Eigen::Vector3d(sigma_xy, sigma_xy,
                         kWheelScaleSigma * (std::abs(motion.theta) + d / kWheelBase) + floors * kWheelMinSigmaTheta);
}

Eigen::Matrix3d boundedByWheels(const Eigen::Matrix3d& c, const Eigen::Vector3d& wheel_sigma) {
  const Eigen::Matrix3d S = wheel_sigma.asDiagonal();
  if (!c.allFinite()) return S * S;
  const Eigen::Matrix3d Si = wheel_sigma.cwiseInverse().asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
  es.computeDirect(Eigen::Matrix3d(Si * (0.5 * (c + c.transpose())) * Si));
  const Eigen::Vector3d ev = es.eigenvalues().cwiseMax(0.0).cwiseMin(1.0);
  return S * es.eigenvectors() * ev.asDiagonal() * es.eigenvectors().transpose() * S;
}

}  // namespace laser_dpslam
