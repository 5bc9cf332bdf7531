#include "laser_dpslam/scan/wall_direction.h"

#include <algorithm>
#include <cmath>

namespace laser_dpslam {

namespace {
// The chords' vote is within ~1.2° of the walls on one URG-04LX scan (60 generated buildings: median 0.36°,
// worst 1.14°); the projections search around it, ±3°, in steps well below what they resolve (~0.05°).
constexpr double kRefineHalfWindow = 3.0 * M_PI / 180.0;
constexpr double kRefineStep = 0.01 * M_PI / 180.0;
// Histogram bin of the projections: about the range noise of near returns (URG-04LX: 1 cm). Coarser bins
// blur the peaks of the walls (5 cm: median error 0.16°), finer ones gain nothing.
constexpr double kProjectionBin = 0.01;
// Returns farther than this are left out of the refinement: far returns are sparse and their range noise large,
// and the histograms stay small whatever the range_max (a stray far point would size them).
constexpr double kRefineMaxRange = 30.0;

// Σ h² of a histogram of v (linear binning, so that the sum moves smoothly with v): the more points share a
// line across v, the larger. `h` is scratch space.
double sharpness(const std::vector<double>& v, std::vector<double>& h) {
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  h.assign(static_cast<std::size_t>((*hi - *lo) / kProjectionBin) + 2, 0.0);
  for (double x : v) {
    const double u = (x - *lo) / kProjectionBin;
    const std::size_t k = static_cast<std::size_t>(u);
    const double f = u - static_cast<double>(k);
    h[k] += 1.0 - f;
    h[k + 1] += f;
  }
  double s = 0.0;
  for (double c : h) s += c * c;
  return s;
}
}  // namespace

double refineWallAngle(const std::vector<Eigen::Vector2d>& points, double coarse) {
  std::vector<Eigen::Vector2d> p;
  p.reserve(points.size());
  for (const auto& q : points) {
    if (q.allFinite() && q.norm() <= kRefineMaxRange) p.push_back(q);
  }
  if (p.size() < 2 || !std::isfinite(coarse)) return coarse;
  std::vector<double> along(p.size()), across(p.size()), h;
  double best = -1.0, best_angle = coarse;
  const int steps = static_cast<int>(std::round(kRefineHalfWindow / kRefineStep));
  for (int i = -steps; i <= steps; ++i) {
    const double a = coarse + i * kRefineStep;
    const double c = std::cos(a), s = std::sin(a);
    for (std::size_t k = 0; k < p.size(); ++k) {
      along[k] = c * p[k].x() + s * p[k].y();
      across[k] = -s * p[k].x() + c * p[k].y();
    }
    const double score = sharpness(along, h) + sharpness(across, h);
    if (score > best) {
      best = score;
      best_angle = a;
    }
  }
  return best_angle;
}

WallDirection dominantWallDirection(const std::vector<Eigen::Vector2d>& p, double min_chord, double chord_per_metre) {
  WallDirection w;
  double c = 0.0, s = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double len = min_chord + chord_per_metre * p[i].norm();
    std::size_t j = i + 1;
    while (j < p.size() && (p[j] - p[i]).norm() < len) ++j;
    if (j >= p.size()) break;
    const Eigen::Vector2d d = p[j] - p[i];
    if (d.norm() > 2.0 * len) continue;
    // A corner between i and j: its middle point is off the chord.
    const Eigen::Vector2d m = p[(i + j) / 2] - p[i];
    if (std::abs(d.x() * m.y() - d.y() * m.x()) > 0.15 * len * d.norm()) continue;
    const double a = 4.0 * std::atan2(d.y(), d.x());
    c += std::cos(a);
    s += std::sin(a);
    ++w.chords;
  }
  if (w.chords == 0) return w;
  w.strength = std::hypot(c, s) / w.chords;
  w.angle = 0.25 * std::atan2(s, c);
  if (w.angle <= -0.25 * M_PI) w.angle += 0.5 * M_PI;  // atan2 gives (−π, π]: angle in (−π/4, π/4]
  return w;
}

}  // namespace laser_dpslam
