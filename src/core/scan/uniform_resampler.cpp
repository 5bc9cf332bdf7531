#include "laser_dpslam/scan/uniform_resampler.h"

#include <Eigen/Core>
#include <algorithm>
#include <numeric>

namespace laser_dpslam {

namespace {

// Steps longer than this are range jumps (occlusions, gaps), not surface: they do not add to the length
// that the budget is spread over.
constexpr double kMaxSurfaceStep = 0.5;  // m

std::vector<int> allIndices(std::size_t n) {
  std::vector<int> idx(n);
  std::iota(idx.begin(), idx.end(), 0);
  return idx;
}

// Greedy pass: keep a point when it is at least `spacing` from the last kept one. Stops early (returning
// limit + 1 indices) once more than `limit` are kept, since the caller then rejects this spacing anyway.
void greedySpacing(const std::vector<Eigen::Vector2d>& pts, double spacing, std::size_t limit,
                   std::vector<int>& kept) {
  kept.clear();
  const double s2 = spacing * spacing;
  kept.push_back(0);
  Eigen::Vector2d last = pts[0];
  for (std::size_t i = 1; i < pts.size(); ++i) {
    if ((pts[i] - last).squaredNorm() >= s2) {
      kept.push_back(static_cast<int>(i));
      if (kept.size() > limit) return;
      last = pts[i];
    }
  }
}

}  // namespace

std::vector<int> uniformResample(const PreprocessedScan& scan, std::size_t budget) {
  const std::vector<Eigen::Vector2d>& pts = scan.points;
  const std::size_t n = pts.size();
  if (budget >= n) return allIndices(n);
  if (budget == 0) return {};

  double length = 0.0;
  Eigen::Vector2d lo = pts[0], hi = pts[0];
  for (std::size_t i = 1; i < n; ++i) {
    const double step = (pts[i] - pts[i - 1]).norm();
    if (step <= kMaxSurfaceStep) length += step;
    lo = lo.cwiseMin(pts[i]);
    hi = hi.cwiseMax(pts[i]);
  }

  // The kept count falls (almost always monotonically) as the spacing grows, and the points after each
  // jump are always kept, so length / budget alone overshoots the budget. Bisect the spacing between 0
  // (keeps all n > budget) and the bounding-box diagonal (keeps only the first point), keeping the best
  // feasible selection (most points <= budget). 40 O(n) passes: ~30 µs for a URG-04LX scan.
  std::vector<int> best{0}, kept;
  kept.reserve(budget + 1);
  double s_lo = 0.0, s_hi = (hi - lo).norm() + 1e-9;
  double s = std::min(length / static_cast<double>(budget), s_hi);
  for (int it = 0; it < 40; ++it) {
    greedySpacing(pts, s, budget, kept);
    if (kept.size() <= budget) {
      if (kept.size() > best.size()) best = kept;
      if (kept.size() == budget) break;
      s_hi = s;
    } else {
      s_lo = s;
    }
    s = 0.5 * (s_lo + s_hi);
  }
  return best;
}

std::vector<int> everyKthResample(const PreprocessedScan& scan, std::size_t budget) {
  const std::size_t n = scan.points.size();
  if (budget >= n) return allIndices(n);
  if (budget == 0) return {};
  const std::size_t k = (n + budget - 1) / budget;  // ceil(n / budget) => ceil(n / k) <= budget
  std::vector<int> idx;
  idx.reserve(budget);
  for (std::size_t i = 0; i < n; i += k) idx.push_back(static_cast<int>(i));
  return idx;
}

}  // namespace laser_dpslam
