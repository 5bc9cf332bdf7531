#include "laser_dpslam/scan/surface_incidence.h"

#include <algorithm>
#include <cmath>

namespace laser_dpslam {

std::vector<double> surfaceIncidence(const PreprocessedScan& scan, const SurfaceIncidenceConfig& config) {
  return fitSurfaces(scan, config).incidence;
}

SurfaceFits fitSurfaces(const PreprocessedScan& scan, const SurfaceIncidenceConfig& config) {
  const std::size_t n = scan.points.size();
  SurfaceFits fits;
  fits.incidence.assign(n, 1.0);
  fits.normals.assign(n, Eigen::Vector2d::Zero());
  const double gap2 = config.max_gap * config.max_gap;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& p = scan.points[i];
    // Returns are in beam order; neighbours are the returns within half_window beam indices.
    const std::size_t lo = i >= static_cast<std::size_t>(config.half_window) ? i - config.half_window : 0;
    const std::size_t hi = std::min(n - 1, i + config.half_window);
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    Eigen::Matrix2d sum2 = Eigen::Matrix2d::Zero();
    int count = 0;
    for (std::size_t j = lo; j <= hi; ++j) {
      if (std::abs(scan.beams[j] - scan.beams[i]) > config.half_window) continue;
      const Eigen::Vector2d q = scan.points[j] - p;  // relative to p: better conditioned
      if (q.squaredNorm() > gap2) continue;
      sum += q;
      sum2 += q * q.transpose();
      ++count;
    }
    if (count < 3) continue;
    const Eigen::Vector2d mean = sum / count;
    const Eigen::Matrix2d cov = sum2 / count - mean * mean.transpose();
    // Principal axis of a symmetric 2×2 matrix at angle ½·atan2(2b, a − c); the normal is across it.
    const double phi = 0.5 * std::atan2(2.0 * cov(0, 1), cov(0, 0) - cov(1, 1));
    const Eigen::Vector2d normal(-std::sin(phi), std::cos(phi));
    const Eigen::Vector2d dir(std::cos(scan.angles[i]), std::sin(scan.angles[i]));
    fits.incidence[i] = std::clamp(std::abs(normal.dot(dir)), config.min_cos, 1.0);
    fits.normals[i] = normal;
  }
  return fits;
}

}  // namespace laser_dpslam
