// A lookup raster of the NDT density: the cheap cost that Differential Evolution evaluates hundreds of
// times per scan (doc/algorithms.md §3). Bilinear interpolation
// between samples; the exact h (NdtGrid::score) is used afterwards for the Newton polish.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "laser_dpslam/common/pose2d.h"
#include "laser_dpslam/matching/ndt_grid.h"

namespace laser_dpslam {

class NdtScoreRaster {
 public:
  /// Samples NdtGrid::density every `resolution` metres over the grid's extent.
  void build(const NdtGrid& grid, double resolution);

  /// −Σ_i density(pose ⊕ p_i), bilinearly interpolated; points outside the raster add 0.
  double cost(const Pose2D& pose, const std::vector<Eigen::Vector2d>& points) const;

  /// Interpolated density at one point (for tests).
  double density(const Eigen::Vector2d& p) const;

  bool empty() const { return values_.empty(); }

 private:
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();  ///< position of sample (0, 0)
  double resolution_ = 0.05;
  double inv_resolution_ = 20.0;
  int nx_ = 0, ny_ = 0;
  std::vector<float> values_;  ///< row-major, (iy, ix)
};

}  // namespace laser_dpslam
