// The speed a blank stretch of corridor keeps along the corridor, as one estimate per straight run: each
// fit of the constrained matches before a blank stretch is a measurement of it with its own variance (a
// scalar Kalman update), so that a fit over a few constrained matches inside a long blank stretch weighs
// what it measured (little) against the fit over the metres before it, instead of replacing it. While the
// scan measures the motion the speed may change (its variance grows with that time, a random walk); a fit
// that disagrees beyond a gate is a new speed; a turn starts a new run. No ROS.
#pragma once

#include <Eigen/Core>
#include <limits>

namespace laser_dpslam {

class HeldSpeed {
 public:
  // m: a constrained match's position error along the corridor (their positions jitter by 1-2 cm); a fit
  // over T s has a speed variance of 2·(kFitPositionSigma / T)².
  static constexpr double kFitPositionSigma = 0.015;
  // m/s per √s: how fast the speed may wander while the scan measures it, between two fits of one run.
  static constexpr double kWalk = 0.005;
  // σ: a fit this far from the estimate is a new speed, not a noisy measurement of the same one.
  static constexpr double kGate = 3.0;
  // rad: a heading this far from the one of the last fit is another straight run (as the fit's own window).
  static constexpr double kStraightRunHeading = 0.05;

  /// Headings `a` and `b` (rad) lie on one straight run: within kStraightRunHeading of each other.
  static bool sameRun(double a, double b);
  /// The variance of a speed fitted over `span` s of constrained matches.
  static double fitVariance(double span) { return 2.0 * (kFitPositionSigma / span) * (kFitPositionSigma / span); }

  /// A constrained match at `heading` (rad) measured the motion for `dt` s: a turn ends the run, and the
  /// speed may have changed meanwhile.
  void observe(double heading, double dt);
  /// A fit of speed `v` (m/s along `direction`, whose sign is arbitrary) with `variance`, at `heading`:
  /// returns the speed to hold along `direction`.
  double fuse(double v, double variance, double heading, const Eigen::Vector2d& direction);
  /// Forget the run (a gap, a reset).
  void reset() { *this = HeldSpeed(); }

  bool valid() const { return variance_ < std::numeric_limits<double>::infinity(); }
  double variance() const { return variance_; }

 private:
  double speed_ = 0.0;  ///< m/s along direction_
  double variance_ = std::numeric_limits<double>::infinity();  ///< (m/s)²; infinite: no fit on this run
  double heading_ = 0.0;  ///< rad, the pose's heading at the last fit
  Eigen::Vector2d direction_ = Eigen::Vector2d::UnitX();
};

}  // namespace laser_dpslam
