#include "laser_dpslam/scan/surface_incidence.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace laser_dpslam;

namespace {
// Beams every 0.01 rad from a0; beam k ends at range r(angle), or is dropped (no point) when r <= 0.
template <class R>
PreprocessedScan scanOf(double a0, int n, R r) {
  PreprocessedScan s;
  for (int k = 0; k < n; ++k) {
    const double a = a0 + 0.01 * k, range = r(a);
    if (range <= 0.0) continue;
    s.points.emplace_back(range * std::cos(a), range * std::sin(a));
    s.beams.push_back(k);
    s.ranges.push_back(range);
    s.angles.push_back(a);
  }
  return s;
}
}  // namespace

TEST(SurfaceIncidence, FlatWallGivesTheCosineOfEachBeamToItsNormal) {
  // Wall x = 2 (normal along x): beam at angle a meets it at |cos a|.
  const PreprocessedScan s = scanOf(-0.6, 121, [](double a) { return 2.0 / std::cos(a); });
  SurfaceIncidenceConfig c;
  c.min_cos = 0.1;
  const std::vector<double> inc = surfaceIncidence(s, c);
  ASSERT_EQ(inc.size(), s.points.size());
  for (std::size_t i = 0; i < inc.size(); ++i) EXPECT_NEAR(inc[i], std::cos(s.angles[i]), 1e-9) << i;
  // A wall seen along its length: the bound applies.
  const PreprocessedScan g = scanOf(0.2, 40, [](double a) { return 0.3 / std::sin(a); });  // wall y = 0.3
  c.min_cos = 0.35;
  for (double v : surfaceIncidence(g, c)) {
    EXPECT_GE(v, 0.35);
    EXPECT_LE(v, 1.0);
  }
  EXPECT_NEAR(surfaceIncidence(g, c).back(), std::max(0.35, std::sin(0.2 + 0.01 * 39)), 1e-9);
}

TEST(SurfaceIncidence, FitsGiveTheNormalsToo) {
  const PreprocessedScan s = scanOf(-0.6, 121, [](double a) { return 2.0 / std::cos(a); });  // wall x = 2
  const SurfaceFits f = fitSurfaces(s, SurfaceIncidenceConfig());
  ASSERT_EQ(f.normals.size(), s.points.size());
  EXPECT_EQ(f.incidence, surfaceIncidence(s, SurfaceIncidenceConfig()));
  for (const Eigen::Vector2d& n : f.normals) {
    EXPECT_NEAR(std::abs(n.x()), 1.0, 1e-9);
    EXPECT_NEAR(n.y(), 0.0, 1e-9);
  }
  PreprocessedScan lone = scanOf(0.0, 1, [](double) { return 1.0; });  // no fit: no normal
  EXPECT_EQ(fitSurfaces(lone, SurfaceIncidenceConfig()).normals.at(0), Eigen::Vector2d::Zero());
}

TEST(SurfaceIncidence, NoFitWithoutThreeNearbyReturns) {
  // Alternate ranges 1 m and 3 m: no neighbour within max_gap in the window → 1 (no correction).
  int k = 0;
  const PreprocessedScan s = scanOf(0.0, 20, [&](double) { return (k++ % 2) ? 3.0 : 1.0; });
  SurfaceIncidenceConfig c;
  c.half_window = 1;
  for (double v : surfaceIncidence(s, c)) EXPECT_EQ(v, 1.0);
  // Dropped beams break the window: two returns 5 beams apart are not neighbours with half_window 3.
  const PreprocessedScan gaps = scanOf(0.0, 30, [](double a) {
    const int b = static_cast<int>(std::lround(a / 0.01));
    return b % 5 == 0 ? 2.0 : -1.0;
  });
  for (double v : surfaceIncidence(gaps, SurfaceIncidenceConfig())) EXPECT_EQ(v, 1.0);
  EXPECT_TRUE(surfaceIncidence(PreprocessedScan(), SurfaceIncidenceConfig()).empty());
}
