// SE(2) pose and the few operations on it that the core needs.
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace laser_dpslam {

/// Wraps an angle to (-pi, pi].
inline double normalizeAngle(double a) {
  a = std::fmod(a + M_PI, 2.0 * M_PI);
  if (a <= 0.0) a += 2.0 * M_PI;
  return a - M_PI;
}

/// A planar pose (x, y in metres, theta in radians): the transform from its own frame to the parent frame.
struct Pose2D {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;

  Pose2D() = default;
  Pose2D(double x_, double y_, double theta_) : x(x_), y(y_), theta(theta_) {}
  explicit Pose2D(const Eigen::Vector3d& v) : x(v.x()), y(v.y()), theta(v.z()) {}

  Eigen::Vector3d vector() const { return {x, y, theta}; }
  Eigen::Vector2d translation() const { return {x, y}; }

  Eigen::Matrix2d rotation() const {
    const double c = std::cos(theta), s = std::sin(theta);
    Eigen::Matrix2d r;
    r << c, -s, s, c;
    return r;
  }

  /// this ⊕ p: a point of this pose's frame expressed in the parent frame.
  Eigen::Vector2d transform(const Eigen::Vector2d& p) const {
    const double c = std::cos(theta), s = std::sin(theta);
    return {c * p.x() - s * p.y() + x, s * p.x() + c * p.y() + y};
  }

  /// this ⊕ other (other expressed in this pose's frame).
  Pose2D operator*(const Pose2D& o) const {
    const double c = std::cos(theta), s = std::sin(theta);
    return {x + c * o.x - s * o.y, y + s * o.x + c * o.y, normalizeAngle(theta + o.theta)};
  }

  Pose2D inverse() const {
    const double c = std::cos(theta), s = std::sin(theta);
    return {-c * x - s * y, s * x - c * y, normalizeAngle(-theta)};
  }
};

/// The motion from a to b expressed in a's frame: a⁻¹ ⊕ b.
inline Pose2D between(const Pose2D& a, const Pose2D& b) { return a.inverse() * b; }

/// The pose a fraction f of the way from a to b (f outside [0, 1] extrapolates): position linearly, heading
/// along the shorter turn.
inline Pose2D interpolate(const Pose2D& a, const Pose2D& b, double f) {
  return Pose2D(a.x + f * (b.x - a.x), a.y + f * (b.y - a.y), normalizeAngle(a.theta + f * normalizeAngle(b.theta - a.theta)));
}

/// Jacobians of a ⊕ b with respect to a and b, for first-order propagation of pose covariances:
/// Σ(a ⊕ b) ≈ Ja·Σa·Jaᵀ + Jb·Σb·Jbᵀ.
inline void composeJacobians(const Pose2D& a, const Pose2D& b, Eigen::Matrix3d* Ja, Eigen::Matrix3d* Jb) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  *Ja << 1, 0, -s * b.x - c * b.y, 0, 1, c * b.x - s * b.y, 0, 0, 1;
  *Jb << c, -s, 0, s, c, 0, 0, 0, 1;
}

}  // namespace laser_dpslam
