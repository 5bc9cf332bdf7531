#include "laser_dpslam/matching/ndt_score_raster.h"

#include <algorithm>
#include <cmath>

#include "laser_dpslam/common/fast_exp.h"

namespace laser_dpslam {

void NdtScoreRaster::build(const NdtGrid& grid, double resolution) {
  values_.clear();
  nx_ = ny_ = 0;
  if (grid.empty() || !(resolution > 0.0)) return;
  resolution_ = resolution;
  inv_resolution_ = 1.0 / resolution;
  const double L = grid.cellSize();

  // Extent: the union of the four layers.
  Eigen::Vector2d lo = grid.layers()[0].origin, hi = lo;
  for (const auto& layer : grid.layers()) {
    lo = lo.cwiseMin(layer.origin);
    hi = hi.cwiseMax(layer.origin + Eigen::Vector2d(layer.nx * L, layer.ny * L));
  }
  origin_ = lo;
  nx_ = static_cast<int>(std::ceil((hi.x() - lo.x()) * inv_resolution_)) + 1;
  ny_ = static_cast<int>(std::ceil((hi.y() - lo.y()) * inv_resolution_)) + 1;
  values_.assign(static_cast<std::size_t>(nx_) * ny_, 0.0f);

  // Only the samples inside valid cells get a contribution: cost ∝ number of valid cells.
  for (const auto& layer : grid.layers()) {
    for (int cy = 0; cy < layer.ny; ++cy) {
      for (int cx = 0; cx < layer.nx; ++cx) {
        const NdtCell& cell = layer.cells[static_cast<std::size_t>(cy) * layer.nx + cx];
        if (!cell.valid) continue;
        const double x0 = layer.origin.x() + cx * L, y0 = layer.origin.y() + cy * L;
        // Samples with x0 ≤ origin + i·res < x0 + L belong to this cell.
        const int ix0 = std::max(0, static_cast<int>(std::ceil((x0 - origin_.x()) * inv_resolution_ - 1e-9)));
        const int ix1 = std::min(nx_ - 1, static_cast<int>(std::ceil((x0 + L - origin_.x()) * inv_resolution_ - 1e-9)) - 1);
        const int iy0 = std::max(0, static_cast<int>(std::ceil((y0 - origin_.y()) * inv_resolution_ - 1e-9)));
        const int iy1 = std::min(ny_ - 1, static_cast<int>(std::ceil((y0 + L - origin_.y()) * inv_resolution_ - 1e-9)) - 1);
        const double a = cell.information(0, 0), b = cell.information(0, 1), c = cell.information(1, 1);
        for (int iy = iy0; iy <= iy1; ++iy) {
          const double qy = origin_.y() + iy * resolution_ - cell.mean.y();
          float* row = &values_[static_cast<std::size_t>(iy) * nx_];
          for (int ix = ix0; ix <= ix1; ++ix) {
            const double qx = origin_.x() + ix * resolution_ - cell.mean.x();
            const double m2 = a * qx * qx + 2.0 * b * qx * qy + c * qy * qy;
            if (m2 < 50.0) row[ix] += static_cast<float>(cell.weight * negExp(0.5 * m2));
          }
        }
      }
    }
  }
}

double NdtScoreRaster::density(const Eigen::Vector2d& p) const {
  const double fx = (p.x() - origin_.x()) * inv_resolution_;
  const double fy = (p.y() - origin_.y()) * inv_resolution_;
  if (!(fx >= 0.0 && fy >= 0.0)) return 0.0;
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
  if (ix >= nx_ - 1 || iy >= ny_ - 1) return 0.0;
  const double tx = fx - ix, ty = fy - iy;
  const float* r0 = &values_[static_cast<std::size_t>(iy) * nx_ + ix];
  const float* r1 = r0 + nx_;
  return (1.0 - ty) * ((1.0 - tx) * r0[0] + tx * r0[1]) + ty * ((1.0 - tx) * r1[0] + tx * r1[1]);
}

double NdtScoreRaster::cost(const Pose2D& pose, const std::vector<Eigen::Vector2d>& points) const {
  if (values_.empty()) return 0.0;
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  double sum = 0.0;
  for (const auto& a : points) {
    sum += density(Eigen::Vector2d(c * a.x() - s * a.y() + pose.x, s * a.x() + c * a.y() + pose.y));
  }
  return -sum;
}

}  // namespace laser_dpslam
