#include "laser_dpslam/scan/facing_surfaces.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace laser_dpslam;

namespace {
// A corridor 1.6 m wide along x ("scanned" from its middle, 683 beams over 240°, URG-04LX spacing, returns
// beyond 5.6 m dropped, range noise 1 cm + 1 %, seeded); optionally closed by an end wall at x = end_x and
// with a box on the left wall whose face towards the laser lies at x = box_x (0.3 m deep).
std::vector<Eigen::Vector2d> scanCorridor(std::uint64_t seed, double end_x = 1e9, double box_x = 1e9) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<Eigen::Vector2d> points;
  for (int k = 0; k < 683; ++k) {
    const double a = -2.0 * M_PI / 3.0 + k * (4.0 * M_PI / 3.0) / 682.0;
    const Eigen::Vector2d d(std::cos(a), std::sin(a));
    double t = 1e9;
    if (d.y() != 0.0) t = std::min(t, (d.y() > 0 ? 0.8 : -0.8) / d.y());
    if (d.x() > 0.0) t = std::min(t, end_x / d.x());
    if (d.x() > 0.0 && d.y() > 0.0) {  // the box's face: x = box_x, 0.5 <= y <= 0.8
      const double tb = box_x / d.x();
      if (tb * d.y() >= 0.5 && tb * d.y() <= 0.8) t = std::min(t, tb);
    }
    if (t > 5.6) continue;
    const double r = t + (0.01 + 0.01 * t) * noise(rng);
    points.push_back(r * d);
  }
  return points;
}
}  // namespace

TEST(FacingSurfaces, ABlankCorridorShowsNothingFacingAlongIt) {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    EXPECT_LT(facingLength(scanCorridor(seed), Eigen::Vector2d(1.0, 0.0)), 0.1) << "seed " << seed;
  }
}

TEST(FacingSurfaces, TheSideWallsFaceAcrossIt) {
  // Both walls, to the range's end either way: about 2 × 2 × 5.5 m, less the stretches behind the laser.
  EXPECT_GT(facingLength(scanCorridor(1), Eigen::Vector2d(0.0, 1.0)), 10.0);
}

TEST(FacingSurfaces, AnEndWallAndABoxFaceAlongIt) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    // The end wall, 1.6 m wide at 4 m: its returns are 2.4 cm apart with 5 cm of range noise, so the fitted
    // directions scatter and only part of it counts, but far more than a blank corridor's nothing.
    EXPECT_GT(facingLength(scanCorridor(seed, 4.0), Eigen::Vector2d(1.0, 0.0)), 0.5) << "seed " << seed;
    // The box's 0.3 m face at 2 m (with the corner it makes with the wall).
    const double box = facingLength(scanCorridor(seed, 1e9, 2.0), Eigen::Vector2d(1.0, 0.0));
    EXPECT_GT(box, 0.1) << "seed " << seed;
    EXPECT_LT(box, 0.6) << "seed " << seed;
  }
}

TEST(FacingSurfaces, FewOrNoPointsCountNothing) {
  EXPECT_EQ(facingLength({}, Eigen::Vector2d(1.0, 0.0)), 0.0);
  EXPECT_EQ(facingLength({{1.0, 0.0}, {1.0, 0.05}, {1.0, 0.1}}, Eigen::Vector2d(1.0, 0.0)), 0.0);
}
