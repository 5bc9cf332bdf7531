#include "laser_dpslam/matching/ndt_grid.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>

using namespace laser_dpslam;

namespace {
// Noisy points on an L-shaped pair of walls plus a blob, in the reference frame.
std::vector<Eigen::Vector2d> referencePoints(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 0.01);
  std::vector<Eigen::Vector2d> pts;
  for (double x = -2.0; x <= 3.0; x += 0.02) pts.emplace_back(x, 2.0 + n(rng));
  for (double y = -1.0; y <= 2.0; y += 0.02) pts.emplace_back(3.0 + n(rng), y);
  for (double a = 0; a < 2 * M_PI; a += 0.1) pts.emplace_back(-1.0 + 0.2 * std::cos(a), -0.5 + 0.2 * std::sin(a));
  return pts;
}

std::vector<Eigen::Vector2d> scanPoints() {
  std::vector<Eigen::Vector2d> pts;
  for (double x = -1.5; x <= 2.5; x += 0.1) pts.emplace_back(x, 1.97);
  for (double y = -0.5; y <= 1.5; y += 0.1) pts.emplace_back(2.96, y);
  pts.emplace_back(-0.8, -0.45);
  return pts;
}
}  // namespace

TEST(NdtGrid, CellsNeedThreePointsAndLayersAreShiftedByHalfACell) {
  NdtGridConfig c;
  c.cell_size = 1.0;
  // Two points in one cell, three in another (far apart so the shifted layers separate them too).
  NdtGrid g({{0.2, 0.2}, {0.3, 0.25}, {5.2, 5.2}, {5.3, 5.25}, {5.25, 5.3}}, c);
  EXPECT_EQ(g.validCells(), 4u);  // the triple is one valid cell in each of the four layers
  const auto& L = g.layers();
  EXPECT_NEAR(L[1].origin.x() - L[0].origin.x(), 0.5, 1e-12);
  EXPECT_NEAR(L[1].origin.y() - L[0].origin.y(), 0.0, 1e-12);
  EXPECT_NEAR(L[2].origin.y() - L[0].origin.y(), 0.5, 1e-12);
  EXPECT_NEAR(L[3].origin.x() - L[0].origin.x(), 0.5, 1e-12);
  EXPECT_NEAR(L[3].origin.y() - L[0].origin.y(), 0.5, 1e-12);
  EXPECT_GT(g.density(Eigen::Vector2d(5.25, 5.25)), 3.0);  // near the mean in all four layers
  EXPECT_EQ(g.density(Eigen::Vector2d(0.25, 0.22)), 0.0);   // only two points there: no Gaussian
}

TEST(NdtGrid, CovarianceIsRegularisedFromItsEigenvectors) {
  // Perfectly collinear points along a 30° line: the raw covariance is singular.
  std::vector<Eigen::Vector2d> pts;
  const Eigen::Vector2d d(std::cos(0.5236), std::sin(0.5236));
  for (int i = 0; i < 20; ++i) pts.push_back(Eigen::Vector2d(0.1, 0.1) + 0.02 * i * d);
  NdtGridConfig c;
  c.cell_size = 4.0;
  c.min_eigen = 1e-12;
  NdtGrid g(pts, c);
  ASSERT_GT(g.validCells(), 0u);
  for (const auto& layer : g.layers()) {
    for (const auto& cell : layer.cells) {
      if (!cell.valid) continue;
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es;
      es.computeDirect(cell.covariance);
      const Eigen::Vector2d ev = es.eigenvalues();
      EXPECT_NEAR(ev(0) / ev(1), c.eigen_ratio, 1e-9);
      // The major axis keeps the line's direction (rebuilt, not rescaled isotropically).
      EXPECT_NEAR(std::abs(es.eigenvectors().col(1).dot(d)), 1.0, 1e-9);
      EXPECT_TRUE((cell.covariance * cell.information).isApprox(Eigen::Matrix2d::Identity(), 1e-9));
    }
  }
}

TEST(NdtGrid, GradientAndHessianMatchFiniteDifferences) {
  for (double L : {1.0, 0.5}) {
    NdtGridConfig c;
    c.cell_size = L;
    const NdtGrid g(referencePoints(3), c);
    const auto pts = scanPoints();
    for (const Pose2D& p : {Pose2D(0.03, -0.02, 0.02), Pose2D(-0.05, 0.04, -0.05), Pose2D(0.01, 0.01, 0.1)}) {
      const NdtScore s = g.score(p, pts, true);
      ASSERT_GT(s.matched, 10);
      const double e = 1e-6;
      for (int k = 0; k < 3; ++k) {
        Eigen::Vector3d d = Eigen::Vector3d::Zero();
        d(k) = e;
        const NdtScore sp = g.score(Pose2D(p.vector() + d), pts, true);
        const NdtScore sm = g.score(Pose2D(p.vector() - d), pts, true);
        // Central differences of h and of the gradient (points stay in their cells for such small steps).
        EXPECT_NEAR(s.gradient(k), (sp.h - sm.h) / (2 * e), 1e-4 * (1 + std::abs(s.gradient(k)))) << "L=" << L << " k=" << k;
        const Eigen::Vector3d hk = (sp.gradient - sm.gradient) / (2 * e);
        for (int l = 0; l < 3; ++l) {
          EXPECT_NEAR(s.hessian(l, k), hk(l), 1e-3 * (1 + std::abs(hk(l)))) << "L=" << L << " k=" << k << " l=" << l;
        }
      }
      EXPECT_TRUE(s.hessian.isApprox(s.hessian.transpose(), 1e-12));
    }
  }
}

TEST(NdtGrid, ScoreIsLowestAtTheTrueAlignment) {
  NdtGridConfig c;
  const NdtGrid g(referencePoints(5), c);
  std::vector<Eigen::Vector2d> pts;
  for (double x = -1.5; x <= 2.5; x += 0.1) pts.emplace_back(x, 2.0);
  for (double y = -0.5; y <= 1.5; y += 0.1) pts.emplace_back(3.0, y);
  const double h0 = g.score(Pose2D(), pts, false).h;
  EXPECT_LT(h0, g.score(Pose2D(0.05, 0, 0), pts, false).h);
  EXPECT_LT(h0, g.score(Pose2D(0, 0.05, 0), pts, false).h);
  EXPECT_LT(h0, g.score(Pose2D(0, 0, 0.03), pts, false).h);
}

TEST(NdtGrid, NonFinitePointsAreIgnored) {
  auto pts = referencePoints(7);
  const NdtGrid clean(pts, NdtGridConfig());
  pts.emplace_back(std::nan(""), 1.0);
  pts.emplace_back(1.0, std::numeric_limits<double>::infinity());
  const NdtGrid dirty(pts, NdtGridConfig());
  EXPECT_EQ(clean.validCells(), dirty.validCells());
  const NdtScore s = dirty.score(Pose2D(), {{std::nan(""), 0.0}, {1.0, 2.0}}, true);
  EXPECT_TRUE(std::isfinite(s.h));
  EXPECT_TRUE(s.gradient.allFinite());
}

// ndt_point_sigma: a point with that noise at its cell's mean scores 1 on average in a thin and in a fat
// cell alike (weight = det(I + σ²Σ⁻¹)^½); the plain score gives the thin cell much less.
TEST(NdtGrid, PointSigmaWeightEqualisesTheExpectedScoreOfNoisyPoints) {
  NdtGridConfig c;
  c.cell_size = 1.0;
  c.point_sigma = 0.01;
  std::vector<Eigen::Vector2d> pts;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0.0, 0.002), noise(0.0, c.point_sigma);
  for (double x = 0.05; x < 0.95; x += 0.01) pts.emplace_back(x, 0.5 + n(rng));                 // a thin wall
  for (double a = 0; a < 2 * M_PI; a += 0.05) pts.emplace_back(5.5 + 0.3 * std::cos(a), 5.5 + 0.3 * std::sin(a));  // a fat ring
  NdtGrid g(pts, c);
  NdtGridConfig plain_config = c;
  plain_config.point_sigma = 0.0;
  NdtGrid plain(pts, plain_config);
  int thin = 0, fat = 0;
  for (const auto& layer : g.layers()) {
    for (std::size_t i = 0; i < layer.cells.size(); ++i) {
      const NdtCell& cell = layer.cells[i];
      if (!cell.valid) continue;
      EXPECT_GE(cell.weight, 1.0);
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(cell.covariance);
      const double ev0 = es.eigenvalues()(0), ev1 = es.eigenvalues()(1);
      EXPECT_NEAR(cell.weight, std::sqrt((1 + 1e-4 / ev0) * (1 + 1e-4 / ev1)), 1e-9);
      // Monte Carlo: the weighted exp() term of noisy points at the mean averages 1.
      double mean = 0.0, mean_plain = 0.0;
      const int N = 20000;
      for (int k = 0; k < N; ++k) {
        const Eigen::Vector2d q(noise(rng), noise(rng));
        const double e = std::exp(-0.5 * q.dot(cell.information * q));
        mean += cell.weight * e / N;
        mean_plain += e / N;
      }
      EXPECT_NEAR(mean, 1.0, 0.02);
      if (ev0 < 1e-4) {
        EXPECT_LT(mean_plain, 0.8);  // a thin cell: the plain term loses > 20 %
        ++thin;
      } else {
        ++fat;
      }
      EXPECT_EQ(plain.layers()[&layer - &g.layers()[0]].cells[i].weight, 1.0);
    }
  }
  EXPECT_GT(thin, 0);
  EXPECT_GT(fat, 0);
}

namespace {
// A straight wall along x at y = 1 from x = −3 m on, seen by a laser at (x0, 0) with range 5 m: returns every
// 2 cm from the wall's end up to where the range ends (x0 + √24 ≈ x0 + 4.9 m).
std::vector<Eigen::Vector2d> wallSeenFrom(double x0) {
  std::vector<Eigen::Vector2d> pts;
  for (double x = -3.0; x <= x0 + 6.0; x += 0.02) {
    if (std::hypot(x - x0, 1.0) <= 5.0) pts.emplace_back(x, 1.0);
  }
  return pts;
}
}  // namespace

// The wall seen from x = 0 ends where the range did. A scan of it from 0.2 m farther along reaches 0.2 m
// past that end: the plain NDT's last cells, holding only part of their wall, pull it back along the wall
// (a corridor's along-track loss); with the view the cells cut by the range keep no information along
// their line, and the pull all but vanishes. Cells the view saw whole are untouched.
TEST(NdtGrid, CellsCutByTheRangeDoNotPullAlongTheirWall) {
  NdtGridConfig c;
  c.cell_size = 0.5;
  const std::vector<Eigen::Vector2d> map = wallSeenFrom(0.0);
  std::vector<Eigen::Vector2d> scan;  // in the scan's frame, which sits at (0.2, 0) in the map
  for (const auto& p : wallSeenFrom(0.2)) scan.emplace_back(p.x() - 0.2, p.y());
  const NdtGrid plain(map, c);
  const NdtGrid cut(map, c, {NdtView{Eigen::Vector2d::Zero(), 5.0}});
  int truncated = 0, whole = 0;
  for (const auto& layer : cut.layers()) {
    for (int i = 0; i < layer.nx * layer.ny; ++i) {
      const NdtCell& cell = layer.cells[static_cast<std::size_t>(i)];
      if (!cell.valid) continue;
      const double far_corner = layer.origin.x() + (i % layer.nx + 1) * c.cell_size;
      if (cell.truncated) {
        ++truncated;
        EXPECT_GT(far_corner, 4.3);  // only cells reaching to the range's end
      } else if (far_corner < 4.0) {
        ++whole;
        EXPECT_LT(cell.covariance(0, 0), 0.05);  // ≈ L²/12: a wall segment's own extent
      }
    }
  }
  EXPECT_GT(truncated, 0);
  EXPECT_GT(whole, 20);
  const Pose2D truth(0.2, 0.0, 0.0);
  const double pull_plain = plain.score(truth, scan, true).gradient.x();
  const double pull_cut = cut.score(truth, scan, true).gradient.x();
  EXPECT_GT(pull_plain, 0.0);  // h grows forward: the plain score prefers the pose farther back
  EXPECT_LT(std::abs(pull_cut), 0.1 * pull_plain);
  RecordProperty("pull_plain_x1000", static_cast<int>(1000.0 * pull_plain));
  RecordProperty("pull_cut_x1000", static_cast<int>(1000.0 * pull_cut));
}
