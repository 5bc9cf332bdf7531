#include "laser_dpslam/matching/ndt_score_raster.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace laser_dpslam;

namespace {
// Noisy points on an L-shaped pair of walls.
std::vector<Eigen::Vector2d> wallPoints() {
  std::mt19937_64 rng(4);
  std::normal_distribution<double> n(0.0, 0.01);
  std::vector<Eigen::Vector2d> pts;
  for (double x = -2.0; x <= 3.0; x += 0.02) pts.emplace_back(x, 2.0 + n(rng));
  for (double y = -1.0; y <= 2.0; y += 0.02) pts.emplace_back(3.0 + n(rng), y);
  return pts;
}

NdtGrid wallGrid() {
  NdtGridConfig c;
  c.cell_size = 0.5;
  return NdtGrid(wallPoints(), c);
}

// The raster's sample lattice starts at the lowest corner of the grid's four layers.
Eigen::Vector2d rasterOrigin(const NdtGrid& grid) {
  Eigen::Vector2d lo = grid.layers()[0].origin;
  for (const auto& layer : grid.layers()) lo = lo.cwiseMin(layer.origin);
  return lo;
}

bool nearCellEdge(double offset, double half_cell) {
  const double r = std::fmod(offset, half_cell);
  return r < 1e-6 || half_cell - r < 1e-6;
}
}  // namespace

TEST(NdtScoreRaster, AnEmptyGridOrABadResolutionGivesAnEmptyRaster) {
  NdtScoreRaster raster;
  EXPECT_TRUE(raster.empty());
  raster.build(NdtGrid(), 0.05);
  EXPECT_TRUE(raster.empty());
  EXPECT_EQ(raster.cost(Pose2D(), wallPoints()), 0.0);
  raster.build(wallGrid(), 0.0);
  EXPECT_TRUE(raster.empty());
  raster.build(wallGrid(), 0.05);
  EXPECT_FALSE(raster.empty());
}

// At its samples the raster holds the grid's density (to float precision).
TEST(NdtScoreRaster, SamplesEqualTheGridsDensity) {
  const NdtGrid grid = wallGrid();
  const double res = 0.03;
  NdtScoreRaster raster;
  raster.build(grid, res);
  const Eigen::Vector2d lo = rasterOrigin(grid);
  int compared = 0, nonzero = 0;
  for (int iy = 0; iy < 120; iy += 3) {
    for (int ix = 0; ix < 200; ix += 3) {
      if (nearCellEdge(ix * res, 0.25) || nearCellEdge(iy * res, 0.25)) continue;
      const Eigen::Vector2d p = lo + Eigen::Vector2d(ix * res, iy * res);
      const double want = grid.density(p);
      EXPECT_NEAR(raster.density(p), want, 1e-5 + 1e-5 * want) << p.transpose();
      ++compared;
      nonzero += want > 0.1 ? 1 : 0;
    }
  }
  EXPECT_GT(compared, 1000);
  EXPECT_GT(nonzero, 50);  // the comparison covered the walls, not only empty space
}

// Between samples the value is bilinear: the midpoint of two samples is their mean.
TEST(NdtScoreRaster, BetweenSamplesTheValueIsBilinear) {
  const NdtGrid grid = wallGrid();
  const double res = 0.03;
  NdtScoreRaster raster;
  raster.build(grid, res);
  const Eigen::Vector2d lo = rasterOrigin(grid);
  const Eigen::Vector2d a = lo + Eigen::Vector2d(101 * res, 131 * res), b = a + Eigen::Vector2d(res, 0.0);
  EXPECT_NEAR(raster.density(0.5 * (a + b)), 0.5 * (raster.density(a) + raster.density(b)), 1e-6);
  // Anywhere, the value lies between those of the four samples around it.
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> ux(-1.5, 2.9), uy(1.8, 2.2);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector2d p(ux(rng), uy(rng));
    const Eigen::Vector2d corner = lo + res * ((p - lo) / res).array().floor().matrix();
    double lowest = 1e9, highest = -1e9;
    for (const Eigen::Vector2d& d : {Eigen::Vector2d(0, 0), Eigen::Vector2d(res, 0), Eigen::Vector2d(0, res),
                                     Eigen::Vector2d(res, res)}) {
      const double v = raster.density(corner + d);
      lowest = std::min(lowest, v);
      highest = std::max(highest, v);
    }
    const double v = raster.density(p);
    EXPECT_GE(v, lowest - 1e-6) << p.transpose();
    EXPECT_LE(v, highest + 1e-6) << p.transpose();
  }
}

TEST(NdtScoreRaster, CostIsMinusTheDensityOfTheMovedPointsAndLowestAtTheTruePose) {
  const NdtGrid grid = wallGrid();
  NdtScoreRaster raster;
  raster.build(grid, 0.03);
  std::vector<Eigen::Vector2d> scan;
  for (double x = -1.0; x <= 2.5; x += 0.1) scan.emplace_back(x, 2.0);
  for (double y = -0.5; y <= 1.5; y += 0.1) scan.emplace_back(3.0, y);
  // The scan in a frame moved by `truth`: cost must be lowest when the pose undoes it.
  const Pose2D truth(0.2, -0.1, 0.05);
  std::vector<Eigen::Vector2d> moved;
  for (const auto& p : scan) moved.push_back(truth.inverse().transform(p));
  const double best = raster.cost(truth, moved);
  double sum = 0.0;
  for (const auto& p : moved) sum += raster.density(truth.transform(p));
  EXPECT_NEAR(best, -sum, 1e-9);
  EXPECT_LT(best, -10.0);
  for (const Pose2D& off : {Pose2D(0.15, 0, 0), Pose2D(0, 0.15, 0), Pose2D(0, 0, 0.1), Pose2D(-0.15, 0.1, -0.05)}) {
    EXPECT_LT(best, raster.cost(truth * off, moved)) << off.x << " " << off.y << " " << off.theta;
  }
  // Points outside the raster add nothing.
  EXPECT_EQ(raster.cost(Pose2D(100.0, 100.0, 0.0), moved), 0.0);
  EXPECT_EQ(raster.density(Eigen::Vector2d(-50.0, 0.0)), 0.0);
}
