#include "laser_dpslam/scan/wall_direction.h"

#include <cmath>

namespace laser_dpslam {

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
