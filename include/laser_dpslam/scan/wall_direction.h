// The dominant wall direction of a scan, modulo 90° (indoor walls mostly meet at right angles). The laser
// odometry turns its local map's grid to it: NDT's cells are axis-aligned, and the same scans matched in a
// frame whose axes run along the walls drift half as much on the simulated loop building as in one turned
// by a few degrees (doc/benchmarks.md, doc/experiments.md). No ROS.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace laser_dpslam {

struct WallDirection {
  double angle = 0.0;     ///< rad in (−π/4, π/4]: the walls run along this angle or at 90° to it
  double strength = 0.0;  ///< [0, 1]: length of the mean resultant of the chords' 4·angle (1 = all chords agree)
  int chords = 0;         ///< chords used
};

/// From points in scan order (consecutive beams, in the scanner's or the robot's frame): a chord from each
/// point p to the first following point at least L(p) = min_chord + chord_per_metre·|p| away, dropped when
/// longer than 2·L(p) (a gap, another surface) or when the point halfway between them lies more than 0.15·L(p)
/// off it (a corner). Short chords carry the range noise (URG-04LX: 1 % of the
/// range, so ±0.6 rad per 0.1 m chord at 4 m), hence chords that grow with the range. Each chord votes with
/// its angle times 4 (so directions 90° apart agree) on the unit circle; the angle of the mean resultant over
/// 4 is the dominant direction: on one URG-04LX scan within ~1.2° of the walls (refineWallAngle sharpens it
/// to ~0.1°). angle 0, strength 0 when there is no chord.
WallDirection dominantWallDirection(const std::vector<Eigen::Vector2d>& ordered_points, double min_chord = 0.1,
                                    double chord_per_metre = 0.1);

/// The angle within ±3° of `coarse` at which the points' projections on the two axes it defines pile up most
/// sharply: Σ h² of histograms (1 cm bins, linear binning) of the points' coordinates along and across it,
/// searched in 0.01° steps. A wall's points then share one bin across it; a frame turned by δ spreads a wall
/// of length l over l·δ. Uses every return of every straight wall, not chords between neighbours, whose
/// angles carry the range noise (one scan, 60 generated buildings: 0.04° median and 0.15° worst error,
/// against 0.36° and 1.14° for the chords' vote). Non-finite points and points beyond 30 m are left out;
/// fewer than two points: `coarse`.
double refineWallAngle(const std::vector<Eigen::Vector2d>& points, double coarse);

}  // namespace laser_dpslam
