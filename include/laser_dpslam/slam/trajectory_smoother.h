// Smooths a SLAM path against the motion it was propagated by. A particle filter's output path is one
// particle's lineage: every step carries the proposal noise drawn for it (a random walk of ~1 cm and a few
// mrad per scan), which the map corrects only over many scans, while the laser odometry is locally far
// smoother. So the path keeps the low frequencies of the SLAM (its drift corrections, loop closures) and
// takes the high ones from the motion: each pose becomes the weighted mean of its neighbours' SLAM poses,
// each carried to its time by the motion between them (a Gaussian window in time). No ROS.
#pragma once

#include <vector>

#include "laser_dpslam/common/trajectory_io.h"

namespace laser_dpslam {

/// `path` and `motion`: the same length, the same stamps (sorted); `motion` is the odometry the path was
/// propagated by, in any frame. `sigma_s`: the Gaussian window's σ in seconds (≤ 0: `path` unchanged); poses
/// further than 4σ apart do not mix. Throws std::invalid_argument when the lengths or stamps differ.
std::vector<StampedPose> smoothTrajectory(const std::vector<StampedPose>& path, const std::vector<StampedPose>& motion,
                                          double sigma_s);

}  // namespace laser_dpslam
