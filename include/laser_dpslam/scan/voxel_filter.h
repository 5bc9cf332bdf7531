// Voxel-grid downsampling: one point (the centroid) per occupied square voxel, so that the dense point
// clusters a low-cost laser produces near walls do not outweigh distant structure in the local map.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace laser_dpslam {

/// Centroids of the occupied voxels of side `voxel` (m), in first-seen order (deterministic).
std::vector<Eigen::Vector2d> voxelFilter(const std::vector<Eigen::Vector2d>& points, double voxel);

}  // namespace laser_dpslam
