// How obliquely each return of a scan meets its surface: |cos| of the angle between the beam and the
// normal of a line fitted to the neighbouring returns. The DP-SLAM map uses it to measure the distance a
// beam travels near the surface it ends on along that surface's normal (DpSlamMap::setSurfaceDepth). No ROS.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "laser_dpslam/scan/scan_preprocessor.h"

namespace laser_dpslam {

struct SurfaceIncidenceConfig {
  int half_window = 3;         ///< beams on each side of a return that may join its line fit
  double max_gap = 0.15;       ///< m; a neighbour farther than this from the return is another surface
  double min_cos = 0.35;       ///< lower bound of the result (grazing fits are unreliable)
};

/// One value per return of `scan` (same order as scan.points), in [config.min_cos, 1]: |d · n| for the
/// beam direction d and the normal n of the principal axis of the returns within half_window beams and
/// max_gap m of it (the return included). 1 (head-on, no correction) when fewer than 3 returns qualify.
/// Rotation-invariant, so it can be computed once per scan in the laser frame.
std::vector<double> surfaceIncidence(const PreprocessedScan& scan, const SurfaceIncidenceConfig& config);

/// surfaceIncidence and the fitted normals themselves: normals[i] is the unit normal of the line fitted at
/// return i in the laser frame (sign arbitrary), (0, 0) where there is no fit (incidence 1).
struct SurfaceFits {
  std::vector<double> incidence;
  std::vector<Eigen::Vector2d> normals;
};
SurfaceFits fitSurfaces(const PreprocessedScan& scan, const SurfaceIncidenceConfig& config);

}  // namespace laser_dpslam
