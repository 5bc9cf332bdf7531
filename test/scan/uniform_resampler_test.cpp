// Spatially uniform and every-k-th resampling (uniform_resampler.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "laser_dpslam/scan/scan_preprocessor.h"
#include "laser_dpslam/scan/uniform_resampler.h"

namespace laser_dpslam {
namespace {

// A URG-04LX (683 beams, 240°) facing a straight wall 0.5 m ahead: beams near the wall's foot land
// ~3 mm apart, those at grazing incidence ~10 cm apart: the dense cluster the thesis complains about.
PreprocessedScan wallScan(double wall_x = 0.5) {
  LaserScan s;
  s.angle_increment = 0.00613592315;
  s.angle_min = -341 * s.angle_increment;
  s.angle_max = 341 * s.angle_increment;
  s.range_min = 0.02;
  s.range_max = 5.6;
  for (int i = 0; i < 683; ++i) {
    const double a = s.angle_min + i * s.angle_increment;
    const double c = std::cos(a);
    s.ranges.push_back(c > 1e-6 ? static_cast<float>(wall_x / c) : std::numeric_limits<float>::infinity());
  }
  return preprocessScan(s, ScanPreprocessorConfig{});
}

// Random points on a few wall segments at different ranges (with jumps between them).
PreprocessedScan randomScan(std::uint64_t seed, std::size_t n) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  LaserScan s;
  s.angle_increment = 4.0 / static_cast<double>(n);
  s.angle_min = -2.0;
  s.angle_max = s.angle_min + (n - 1) * s.angle_increment;
  s.range_min = 0.02;
  s.range_max = 10.0;
  float level = 2.0f;
  for (std::size_t i = 0; i < n; ++i) {
    if (uni(rng) < 0.02) level = static_cast<float>(0.3 + 6.0 * uni(rng));
    s.ranges.push_back(level + static_cast<float>(0.01 * uni(rng)));
  }
  return preprocessScan(s, ScanPreprocessorConfig{});
}

void expectSortedUniqueInRange(const std::vector<int>& idx, std::size_t n) {
  for (std::size_t i = 0; i < idx.size(); ++i) {
    ASSERT_GE(idx[i], 0);
    ASSERT_LT(static_cast<std::size_t>(idx[i]), n);
    if (i > 0) {
      ASSERT_LT(idx[i - 1], idx[i]);
    }
  }
}

std::vector<double> keptGaps(const PreprocessedScan& p, const std::vector<int>& idx) {
  std::vector<double> gaps;
  for (std::size_t i = 1; i < idx.size(); ++i) gaps.push_back((p.points[idx[i]] - p.points[idx[i - 1]]).norm());
  return gaps;
}

TEST(UniformResampler, BudgetIsRespectedAndIndicesAreSortedUnique) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const PreprocessedScan p = randomScan(seed, 500 + 100 * seed);
    ASSERT_TRUE(p.ok());
    const std::size_t n = p.points.size();
    for (std::size_t budget : {std::size_t{1}, std::size_t{2}, std::size_t{7}, std::size_t{40}, std::size_t{85},
                               n / 2, n - 1}) {
      const std::vector<int> u = uniformResample(p, budget);
      const std::vector<int> k = everyKthResample(p, budget);
      EXPECT_LE(u.size(), budget);
      EXPECT_LE(k.size(), budget);
      EXPECT_FALSE(u.empty());
      EXPECT_FALSE(k.empty());
      expectSortedUniqueInRange(u, n);
      expectSortedUniqueInRange(k, n);
    }
  }
}

TEST(UniformResampler, KeepsAboutTheBudget) {
  const PreprocessedScan p = wallScan();
  for (std::size_t budget : {10u, 40u, 85u, 200u}) {
    const std::size_t kept = uniformResample(p, budget).size();
    EXPECT_LE(kept, budget);
    EXPECT_GE(kept, budget * 9 / 10) << "budget " << budget;
  }
}

TEST(UniformResampler, BudgetCoveringTheScanReturnsEverything) {
  const PreprocessedScan p = randomScan(9, 300);
  const std::size_t n = p.points.size();
  for (std::size_t budget : {n, n + 1, 10 * n}) {
    for (const auto& idx : {uniformResample(p, budget), everyKthResample(p, budget)}) {
      ASSERT_EQ(idx.size(), n);
      for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(idx[i], static_cast<int>(i));
    }
  }
  EXPECT_TRUE(uniformResample(p, 0).empty());
  EXPECT_TRUE(everyKthResample(p, 0).empty());
  EXPECT_TRUE(uniformResample(PreprocessedScan{}, 10).empty());
  EXPECT_TRUE(everyKthResample(PreprocessedScan{}, 10).empty());
}

TEST(UniformResampler, EveryKthTakesEveryCeilNOverBudgetPoint) {
  const PreprocessedScan p = randomScan(3, 683);
  const std::size_t n = p.points.size();
  for (std::size_t budget : {40u, 85u, 100u, 682u}) {
    const std::size_t k = (n + budget - 1) / budget;
    const std::vector<int> idx = everyKthResample(p, budget);
    ASSERT_EQ(idx.size(), (n + k - 1) / k);
    for (std::size_t i = 0; i < idx.size(); ++i) EXPECT_EQ(idx[i], static_cast<int>(i * k));
  }
}

// The point of uniform resampling: equal spacing in space, so the dense cluster at the wall's foot does
// not take the budget. Every-k-th keeps the beam density's imbalance.
TEST(UniformResampler, SpacingIsUniformWhereEveryKthIsNot) {
  const PreprocessedScan p = wallScan();
  ASSERT_GT(p.points.size(), 400u);  // out to ±85°, where the wall leaves the 5.6 m range
  const std::size_t budget = 30;
  const std::vector<int> iu = uniformResample(p, budget);
  const std::vector<double> gu = keptGaps(p, iu);
  const std::vector<double> gk = keptGaps(p, everyKthResample(p, budget));
  ASSERT_GT(gu.size(), 20u);
  ASSERT_GT(gk.size(), 20u);
  // Greedy spacing s: each kept point is the first at >= s from the previous kept one, so every gap lies
  // in [s, s + the beam step just before it). s <= the smallest gap.
  const double s_min = *std::min_element(gu.begin(), gu.end());
  for (std::size_t i = 1; i < iu.size(); ++i) {
    const double step = (p.points[iu[i]] - p.points[iu[i] - 1]).norm();
    EXPECT_LE(gu[i - 1], s_min + step + 1e-9) << "gap " << i;
  }
  const auto cv = [](const std::vector<double>& g) {  // coefficient of variation of the gaps
    double m = 0.0, v = 0.0;
    for (double x : g) m += x / g.size();
    for (double x : g) v += (x - m) * (x - m) / g.size();
    return std::sqrt(v) / m;
  };
  EXPECT_LT(cv(gu), 0.25);
  EXPECT_GT(cv(gk), 1.0);
  EXPECT_GT(*std::max_element(gk.begin(), gk.end()) / *std::min_element(gk.begin(), gk.end()), 10.0);

  // Points kept within 0.5 m of the wall's foot (|y| < 0.5): far fewer with uniform resampling.
  const auto nearCount = [&p](const std::vector<int>& idx) {
    return std::count_if(idx.begin(), idx.end(), [&p](int i) { return std::abs(p.points[i].y()) < 0.5; });
  };
  const auto near_u = nearCount(uniformResample(p, budget));
  const auto near_k = nearCount(everyKthResample(p, budget));
  EXPECT_LT(near_u, near_k);
  EXPECT_LE(near_u, 4);  // 1 m of ~11 m of wall, at 30 points
}

TEST(UniformResampler, JumpsDoNotEatTheBudgetAndEverySurfaceIsCovered) {
  // Two walls: a near one on the right half, a far one on the left half, joined by a 3 m jump.
  LaserScan s;
  s.angle_increment = 0.00613592315;
  s.angle_min = -1.0;
  s.angle_max = s.angle_min + 325 * s.angle_increment;
  s.range_min = 0.02;
  s.range_max = 10.0;
  for (int i = 0; i < 326; ++i) s.ranges.push_back(i < 163 ? 1.0f : 4.0f);
  const PreprocessedScan p = preprocessScan(s, ScanPreprocessorConfig{});
  ASSERT_TRUE(p.ok());
  const std::vector<int> idx = uniformResample(p, 20);
  ASSERT_LE(idx.size(), 20u);
  const auto on_near = std::count_if(idx.begin(), idx.end(), [&p](int i) { return p.ranges[i] < 2.0; });
  const auto on_far = static_cast<long>(idx.size()) - on_near;
  // Arc lengths 1 m : 4 m, so the far wall gets about four times the points.
  EXPECT_GE(on_near, 2);
  EXPECT_GE(on_far, 3 * on_near - 2);
  EXPECT_GE(idx.size(), 18u);
}

TEST(UniformResampler, Deterministic) {
  const PreprocessedScan p = randomScan(11, 700);
  EXPECT_EQ(uniformResample(p, 50), uniformResample(p, 50));
  EXPECT_EQ(everyKthResample(p, 50), everyKthResample(p, 50));
}

}  // namespace
}  // namespace laser_dpslam
