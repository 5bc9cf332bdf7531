// REP-117 handling and malformed-scan rejection of preprocessScan (scan_preprocessor.h).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "laser_dpslam/scan/scan_preprocessor.h"

namespace laser_dpslam {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// A URG-04LX-like scan (its datasheet: 683 beams over 240°, 0.02–5.6 m) with every range set to `r`.
LaserScan urgScan(std::size_t n = 683, float r = 1.0f) {
  LaserScan s;
  s.stamp = 12.5;
  s.frame_id = "laser";
  s.angle_increment = 0.00613592315;
  s.angle_min = -0.5 * static_cast<double>(n - 1) * s.angle_increment;
  s.angle_max = s.angle_min + static_cast<double>(n - 1) * s.angle_increment;
  s.range_min = 0.02;
  s.range_max = 5.6;
  s.ranges.assign(n, r);
  return s;
}

std::size_t countSum(const BeamCounts& c) {
  return c.valid + c.nan + c.pos_inf + c.neg_inf + c.below_min + c.above_max + c.outside_window;
}

void expectAllFinite(const PreprocessedScan& p) {
  for (const auto& q : p.points) ASSERT_TRUE(std::isfinite(q.x()) && std::isfinite(q.y()));
  for (double v : p.ranges) ASSERT_TRUE(std::isfinite(v));
  for (double v : p.angles) ASSERT_TRUE(std::isfinite(v));
  for (double v : p.no_return_angles) ASSERT_TRUE(std::isfinite(v));
  ASSERT_TRUE(std::isfinite(p.range_max));
}

TEST(ScanPreprocessor, Rep117BeamClassification) {
  LaserScan s = urgScan(11);
  //           NaN   +inf  -inf   zero  neg    <min   >max  =max  =min   ok    ok
  s.ranges = {kNaN, kInf, -kInf, 0.0f, -1.0f, 0.01f, 6.0f, 5.6f, 0.02f, 1.0f, 2.5f};
  const PreprocessedScan p = preprocessScan(s, ScanPreprocessorConfig{});
  ASSERT_TRUE(p.ok()) << p.error;
  EXPECT_EQ(p.stamp, 12.5);
  EXPECT_EQ(p.counts.total, 11u);
  EXPECT_EQ(p.counts.nan, 1u);
  EXPECT_EQ(p.counts.pos_inf, 1u);
  EXPECT_EQ(p.counts.neg_inf, 1u);
  EXPECT_EQ(p.counts.below_min, 3u);  // 0, negative, 0.01 < 0.02
  EXPECT_EQ(p.counts.above_max, 1u);
  EXPECT_EQ(p.counts.valid, 4u);
  EXPECT_EQ(countSum(p.counts), p.counts.total);
  EXPECT_DOUBLE_EQ(p.range_max, 5.6);
  ASSERT_EQ(p.points.size(), 4u);
  EXPECT_EQ(p.beams, (std::vector<int>{7, 8, 9, 10}));
  // +inf (beam 1) and the above-max reading (beam 6) are both "no return within range".
  ASSERT_EQ(p.no_return_angles.size(), 2u);
  EXPECT_DOUBLE_EQ(p.no_return_angles[0], s.angle_min + 1 * s.angle_increment);
  EXPECT_DOUBLE_EQ(p.no_return_angles[1], s.angle_min + 6 * s.angle_increment);
  for (std::size_t i = 0; i < p.points.size(); ++i) {
    const double a = s.angle_min + p.beams[i] * s.angle_increment;
    const double r = s.ranges[p.beams[i]];
    EXPECT_DOUBLE_EQ(p.angles[i], a);
    EXPECT_DOUBLE_EQ(p.ranges[i], r);
    EXPECT_NEAR(p.points[i].x(), r * std::cos(a), 1e-12);
    EXPECT_NEAR(p.points[i].y(), r * std::sin(a), 1e-12);
  }
}

TEST(ScanPreprocessor, ConfigTightensButNeverLoosensRangeWindow) {
  LaserScan s = urgScan(5);
  s.ranges = {0.3f, 1.0f, 2.9f, 4.0f, 5.5f};
  ScanPreprocessorConfig cfg;
  cfg.min_range = 0.5;
  cfg.max_range = 3.0;
  PreprocessedScan p = preprocessScan(s, cfg);
  ASSERT_TRUE(p.ok()) << p.error;
  EXPECT_DOUBLE_EQ(p.range_max, 3.0);
  EXPECT_EQ(p.counts.below_min, 1u);
  EXPECT_EQ(p.counts.above_max, 2u);
  EXPECT_EQ(p.counts.valid, 2u);
  EXPECT_EQ(p.no_return_angles.size(), 2u);  // beams beyond the config's max saw free space up to it

  cfg.min_range = 0.0;  // looser than the scan's 0.02: the scan's limit applies
  cfg.max_range = 10.0;  // looser than the scan's 5.6: likewise
  s.ranges = {0.01f, 1.0f, 5.0f, 5.59f, 5.7f};
  p = preprocessScan(s, cfg);
  ASSERT_TRUE(p.ok()) << p.error;
  EXPECT_DOUBLE_EQ(p.range_max, 5.6);
  EXPECT_EQ(p.counts.below_min, 1u);
  EXPECT_EQ(p.counts.above_max, 1u);
  EXPECT_EQ(p.counts.valid, 3u);

  cfg.max_range = 0.0;  // 0 = the scan's
  p = preprocessScan(s, cfg);
  EXPECT_DOUBLE_EQ(p.range_max, 5.6);
  EXPECT_EQ(p.counts.valid, 3u);
}

TEST(ScanPreprocessor, AngleWindow) {
  LaserScan s = urgScan(683, 2.0f);
  ScanPreprocessorConfig cfg;
  cfg.angle_min = -0.5;
  cfg.angle_max = 1.0;
  const PreprocessedScan p = preprocessScan(s, cfg);
  ASSERT_TRUE(p.ok()) << p.error;
  std::size_t expected = 0;
  for (std::size_t i = 0; i < s.ranges.size(); ++i) {
    const double a = s.angle_min + i * s.angle_increment;
    if (a >= cfg.angle_min && a <= cfg.angle_max) ++expected;
  }
  EXPECT_GT(expected, 0u);
  EXPECT_LT(expected, s.ranges.size());
  EXPECT_EQ(p.counts.valid, expected);
  EXPECT_EQ(p.counts.outside_window, s.ranges.size() - expected);
  EXPECT_EQ(countSum(p.counts), p.counts.total);
  for (double a : p.angles) {
    EXPECT_GE(a, cfg.angle_min);
    EXPECT_LE(a, cfg.angle_max);
  }
}

TEST(ScanPreprocessor, UpsideDownLaserWithNegativeIncrementIsAccepted) {
  LaserScan s = urgScan(100, 1.5f);
  std::swap(s.angle_min, s.angle_max);
  s.angle_increment = -s.angle_increment;
  const PreprocessedScan p = preprocessScan(s, ScanPreprocessorConfig{});
  ASSERT_TRUE(p.ok()) << p.error;
  ASSERT_EQ(p.points.size(), 100u);
  EXPECT_DOUBLE_EQ(p.angles.front(), s.angle_min);
  EXPECT_LT(p.angles.back(), p.angles.front());
  EXPECT_NEAR(p.angles.back(), s.angle_max, 1e-9);
}

TEST(ScanPreprocessor, IntensitiesOfMismatchedLengthAreIgnored) {
  LaserScan s = urgScan(50, 1.0f);
  s.intensities = {1.0f, 2.0f, 3.0f};
  const PreprocessedScan p = preprocessScan(s, ScanPreprocessorConfig{});
  ASSERT_TRUE(p.ok()) << p.error;
  EXPECT_EQ(p.points.size(), 50u);
}

TEST(ScanPreprocessor, MalformedScansGiveAnErrorAndNoPoints) {
  struct Case {
    std::string name;
    std::function<void(LaserScan&, ScanPreprocessorConfig&)> spoil;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<Case> cases = {
      {"empty ranges", [](LaserScan& s, ScanPreprocessorConfig&) { s.ranges.clear(); }},
      {"too many beams", [](LaserScan& s, ScanPreprocessorConfig&) { s.ranges.assign(100001, 1.0f); }},
      {"NaN angle_min", [nan](LaserScan& s, ScanPreprocessorConfig&) { s.angle_min = nan; }},
      {"inf angle_min", [inf](LaserScan& s, ScanPreprocessorConfig&) { s.angle_min = -inf; }},
      {"NaN angle_max", [nan](LaserScan& s, ScanPreprocessorConfig&) { s.angle_max = nan; }},
      {"inf angle_max", [inf](LaserScan& s, ScanPreprocessorConfig&) { s.angle_max = inf; }},
      {"NaN increment", [nan](LaserScan& s, ScanPreprocessorConfig&) { s.angle_increment = nan; }},
      {"inf increment", [inf](LaserScan& s, ScanPreprocessorConfig&) { s.angle_increment = inf; }},
      {"zero increment", [](LaserScan& s, ScanPreprocessorConfig&) { s.angle_increment = 0.0; }},
      {"absurd increment", [](LaserScan& s, ScanPreprocessorConfig&) { s.angle_increment = 7.0; }},
      {"negative increment, max > min",
       [](LaserScan& s, ScanPreprocessorConfig&) { s.angle_increment = -s.angle_increment; }},
      {"positive increment, max < min", [](LaserScan& s, ScanPreprocessorConfig&) { std::swap(s.angle_min, s.angle_max); }},
      {"zero range_max", [](LaserScan& s, ScanPreprocessorConfig&) { s.range_max = 0.0; }},
      {"negative range_max", [](LaserScan& s, ScanPreprocessorConfig&) { s.range_max = -5.6; }},
      {"NaN range_max", [nan](LaserScan& s, ScanPreprocessorConfig&) { s.range_max = nan; }},
      {"inf range_max", [inf](LaserScan& s, ScanPreprocessorConfig&) { s.range_max = inf; }},
      {"NaN range_min", [nan](LaserScan& s, ScanPreprocessorConfig&) { s.range_min = nan; }},
      {"range_min > range_max", [](LaserScan& s, ScanPreprocessorConfig&) { s.range_min = 6.0; }},
      {"config min_range NaN", [nan](LaserScan&, ScanPreprocessorConfig& c) { c.min_range = nan; }},
      {"config max_range NaN", [nan](LaserScan&, ScanPreprocessorConfig& c) { c.max_range = nan; }},
      {"config window reversed", [](LaserScan&, ScanPreprocessorConfig& c) { c.angle_min = 1.0, c.angle_max = -1.0; }},
      {"config window NaN", [nan](LaserScan&, ScanPreprocessorConfig& c) { c.angle_max = nan; }},
      {"config range window empty", [](LaserScan&, ScanPreprocessorConfig& c) { c.min_range = 10.0; }},
  };
  for (const Case& c : cases) {
    LaserScan s = urgScan(683, 1.0f);
    ScanPreprocessorConfig cfg;
    ASSERT_TRUE(preprocessScan(s, cfg).ok()) << "baseline for " << c.name;
    c.spoil(s, cfg);
    const PreprocessedScan p = preprocessScan(s, cfg);
    EXPECT_FALSE(p.ok()) << c.name;
    EXPECT_FALSE(p.error.empty()) << c.name;
    EXPECT_TRUE(p.points.empty()) << c.name;
    EXPECT_TRUE(p.ranges.empty() && p.angles.empty() && p.beams.empty()) << c.name;
    EXPECT_TRUE(p.no_return_angles.empty()) << c.name;
    EXPECT_EQ(p.counts.valid, 0u) << c.name;
  }
}

TEST(ScanPreprocessor, BeamCountMayChangeBetweenCalls) {
  for (std::size_t n : {683u, 100u, 1081u, 1u, 683u}) {
    LaserScan s = urgScan(n, 2.0f);
    s.ranges[0] = kNaN;  // keeps one beam out so a stale count would show
    const PreprocessedScan p = preprocessScan(s, ScanPreprocessorConfig{});
    ASSERT_TRUE(p.ok()) << n << ": " << p.error;
    EXPECT_EQ(p.counts.total, n);
    EXPECT_EQ(p.points.size(), n - 1);
    EXPECT_EQ(p.beams.size(), n - 1);
    EXPECT_EQ(p.counts.nan, 1u);
  }
}

TEST(ScanPreprocessor, RandomScanPointsArePolarToCartesian) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    LaserScan s = urgScan(200 + trial * 13);
    s.angle_min = -3.0 + uni(rng);
    s.angle_increment = 0.001 + 0.01 * uni(rng);
    s.angle_max = s.angle_min + (s.ranges.size() - 1) * s.angle_increment;
    for (float& r : s.ranges) r = static_cast<float>(0.05 + 5.5 * uni(rng));
    const PreprocessedScan p = preprocessScan(s, ScanPreprocessorConfig{});
    ASSERT_TRUE(p.ok()) << p.error;
    ASSERT_EQ(p.points.size(), s.ranges.size());
    for (std::size_t i = 0; i < p.points.size(); ++i) {
      ASSERT_EQ(p.beams[i], static_cast<int>(i));
      const double a = s.angle_min + static_cast<double>(i) * s.angle_increment;
      const double r = s.ranges[i];
      ASSERT_NEAR(p.points[i].x(), r * std::cos(a), 1e-9);
      ASSERT_NEAR(p.points[i].y(), r * std::sin(a), 1e-9);
      ASSERT_NEAR(p.points[i].norm(), r, 1e-9);
    }
  }
}

// 10^4 garbage scans: every field is sometimes NaN, ±inf, zero, negative or huge. Nothing may throw,
// no output may be non-finite, a rejected scan has no points, an accepted one counts every beam once.
TEST(ScanPreprocessor, RandomGarbageNeverProducesNonFiniteOutput) {
  std::mt19937_64 rng(20130101);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const double specials[] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity(), 0.0, -1.0, 1e300, -1e300, 1e-300};
  auto field = [&](double good) {
    return uni(rng) < 0.9 ? good : specials[static_cast<std::size_t>(uni(rng) * 8) % 8];
  };
  const float range_specials[] = {kNaN, kInf, -kInf, 0.0f, -3.0f, 1e30f, 1e-30f, 5.6f, 0.02f};
  std::size_t accepted = 0, rejected = 0, points = 0;
  for (int trial = 0; trial < 10000; ++trial) {
    LaserScan s;
    const std::size_t n = uni(rng) < 0.02 ? 0 : 1 + static_cast<std::size_t>(uni(rng) * 1100);
    const double inc = (uni(rng) < 0.5 ? 1.0 : -1.0) * (0.0005 + 0.01 * uni(rng));
    s.angle_min = field(-M_PI + 2 * M_PI * uni(rng));
    s.angle_increment = field(inc);
    s.angle_max = field(s.angle_min + inc * static_cast<double>(n > 0 ? n - 1 : 0));
    s.range_min = field(0.02 * uni(rng));
    s.range_max = field(1.0 + 10.0 * uni(rng));
    s.ranges.resize(n);
    for (float& r : s.ranges)
      r = uni(rng) < 0.8 ? static_cast<float>(12.0 * uni(rng)) : range_specials[static_cast<std::size_t>(uni(rng) * 9) % 9];
    if (uni(rng) < 0.3) s.intensities.resize(static_cast<std::size_t>(uni(rng) * 50));
    ScanPreprocessorConfig cfg;
    if (uni(rng) < 0.2) cfg.min_range = field(0.5 * uni(rng));
    if (uni(rng) < 0.2) cfg.max_range = field(8.0 * uni(rng));
    if (uni(rng) < 0.2) cfg.angle_min = field(-2.0 * uni(rng)), cfg.angle_max = field(2.0 * uni(rng));

    PreprocessedScan p;
    ASSERT_NO_THROW(p = preprocessScan(s, cfg));
    expectAllFinite(p);
    ASSERT_EQ(p.points.size(), p.beams.size());
    ASSERT_EQ(p.points.size(), p.ranges.size());
    ASSERT_EQ(p.points.size(), p.angles.size());
    if (p.ok()) {
      ++accepted;
      points += p.points.size();
      ASSERT_EQ(countSum(p.counts), n);
      ASSERT_EQ(p.counts.valid, p.points.size());
      for (double r : p.ranges) ASSERT_LE(r, p.range_max);
    } else {
      ++rejected;
      ASSERT_TRUE(p.points.empty());
      ASSERT_TRUE(p.no_return_angles.empty());
    }
  }
  // Both branches were exercised (otherwise the test proves nothing).
  EXPECT_GT(accepted, 2000u);
  EXPECT_GT(rejected, 1000u);
  EXPECT_GT(points, 100000u);
}

}  // namespace
}  // namespace laser_dpslam
