// The robot's speed along one direction, measured from how the ranges of two consecutive scans changed
// (range flow, as rf2o uses it: Jaimez et al. 2016), on the surfaces that face that direction. The laser
// odometry uses it along the weak direction of a corridor match, where the NDT match against the local map
// cannot tell motion from standing still but a door frame or a niche face ahead still can. No ROS.
#pragma once

#include <Eigen/Core>

#include "laser_dpslam/common/laser_mount.h"
#include "laser_dpslam/common/pose2d.h"
#include "laser_dpslam/scan/scan_preprocessor.h"

namespace laser_dpslam {

struct RangeFlowConfig {
  double reference_step = 0.03;   ///< m, the motion along the direction the ranges are compared against
  double min_sensitivity = 0.25;  ///< m/m, a beam counts when its range changes at least this much per metre
                                  ///< of that motion (walls along the direction, ~0, cannot tell)
  double range_noise = 0.01;      ///< m, σ of one range (URG-04LX: 10 mm ...)
  double range_noise_fraction = 0.01;  ///< ... or 1 % of the range, whichever is larger
  double max_sigma = 0.3;         ///< σ of the measured motion as a fraction of reference_step: above it, no measurement
  int min_beams = 10;             ///< fewer sensitive beams: no measurement (a few beams at an edge can agree on anything)
  /// The line through each return of the previous scan: fitted to the returns within this many beams and
  /// metres of it (neighbouring returns a few mm apart with 1 cm noise give a normal good to tens of degrees
  /// only; the flow needs a few) that lie within 2.5σ of the range noise of the line through the return that
  /// most of them lie on (a corner's other surface is left out).
  int fit_half_window = 20;
  double fit_radius = 0.3;
  double min_cos = 0.5;            ///< |cos| of a beam's incidence on its line, at least: obliquely a few degrees of error
                                   ///< in the fitted normal change the predicted range change by tens of per cent
  int fit_min_side = 4;            ///< returns on that line needed on each side of the return (none at a corner)
  double max_normal_error = 0.05;  ///< rad, a line is used when its normal's error (noise over length and count) is below this
};

struct RangeFlow {
  bool valid = false;  ///< false: too few beams see motion along the direction (a plain corridor), or the scans differ in layout
  double speed = 0.0;  ///< m/s along the direction
  double sigma = 0.0;  ///< m/s, its standard deviation from the range noise
  int beams = 0;       ///< beams used
};

/// `previous` and `current` are consecutive preprocessed scans (laser frame, the same beam layout) `dt`
/// seconds apart, `mount` the laser on the robot, `motion` the robot's motion between them (current base in
/// the previous base frame, e.g. the scan match's) and `direction` a unit vector in the previous base frame.
/// Keeps `motion` across `direction` and its rotation, and finds the motion along `direction` that best
/// explains the change of each range on the surfaces fitted to the previous scan (weighted least squares,
/// one outlier pass). Never throws.
RangeFlow measureRangeFlow(const PreprocessedScan& previous, const PreprocessedScan& current, const LaserMount& mount,
                           const Pose2D& motion, const Eigen::Vector2d& direction, double dt,
                           const RangeFlowConfig& config = RangeFlowConfig());

}  // namespace laser_dpslam
