// How much of a scan's surface faces along a direction. Along a corridor only such surfaces (an end wall, a
// door jamb, a box, a niche's back) fix the position along it; the side walls do not. The laser odometry
// uses it to tell a blank stretch of corridor, where a degenerate match's position along the corridor is
// the NDT's bias and not a measurement, from one with something along it in view (doc/algorithms.md §6).
// No ROS.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace laser_dpslam {

/// Length (m) of the surface, through points in scan order (consecutive beams), whose direction lies more
/// than 60° from `direction` (unit). A point's surface direction is the principal axis of the points within
/// 0.1 m of it on the same surface (neighbouring points at most 0.15 m apart), and a point counts half its
/// two gaps. Fitted over 0.1 m rather than taken from the next point, the direction is not the range noise
/// (1 cm on the URG-04LX) near the laser, where neighbouring returns are millimetres apart. Points at a
/// surface's end (less than 0.1 m of surface on one side) and surfaces with fewer than 5 points count
/// nothing: an edge seen at the range's end or a single stray return says nothing about the direction.
double facingLength(const std::vector<Eigen::Vector2d>& ordered_points, const Eigen::Vector2d& direction);

}  // namespace laser_dpslam
