#include "laser_dpslam/scan/facing_surfaces.h"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace laser_dpslam {

namespace {
constexpr double kHalfSpan = 0.1;  ///< m of surface on each side of a point that its direction is fitted over
constexpr double kMaxGap = 0.15;   ///< m between neighbouring returns of one surface
constexpr int kMinNeighbours = 4;  ///< besides the point itself
constexpr double kMaxCos = 0.5;    ///< |cos| between the surface and the direction: more than 60° apart

// Principal axis of the points within kHalfSpan of p[i] on its surface; false at a surface's end or with
// too few points.
bool surfaceAxis(const std::vector<Eigen::Vector2d>& p, long i, Eigen::Vector2d* axis) {
  const long n = static_cast<long>(p.size());
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  Eigen::Matrix2d sq = Eigen::Matrix2d::Zero();
  int count = 0;
  for (long step : {-1L, 1L}) {
    long j = i + step;
    for (; j >= 0 && j < n && (p[j] - p[j - step]).norm() <= kMaxGap && (p[j] - p[i]).norm() <= kHalfSpan; j += step) {
      const Eigen::Vector2d d = p[j] - p[i];  // centred on p[i] for numerical stability
      sum += d;
      sq += d * d.transpose();
      ++count;
    }
    // The surface must go on past the span on both sides.
    if (j < 0 || j >= n || (p[j] - p[j - step]).norm() > kMaxGap) return false;
  }
  if (count < kMinNeighbours) return false;
  ++count;  // p[i] itself, at d = 0
  const Eigen::Vector2d mean = sum / count;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es;
  es.computeDirect(Eigen::Matrix2d(sq / count - mean * mean.transpose()));
  *axis = es.eigenvectors().col(1);
  return true;
}
}  // namespace

double facingLength(const std::vector<Eigen::Vector2d>& p, const Eigen::Vector2d& direction) {
  double length = 0.0;
  for (long i = 1; i + 1 < static_cast<long>(p.size()); ++i) {
    Eigen::Vector2d axis;
    if (!surfaceAxis(p, i, &axis) || std::abs(axis.dot(direction)) >= kMaxCos) continue;
    length += 0.5 * ((p[i + 1] - p[i]).norm() + (p[i] - p[i - 1]).norm());
  }
  return length;
}

}  // namespace laser_dpslam
