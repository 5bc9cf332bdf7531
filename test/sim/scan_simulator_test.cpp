#include "laser_dpslam/sim/scan_simulator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

namespace laser_dpslam {
namespace {

struct Box {
  double x0, y0, x1, y1;
};

// A 6 m x 4 m room (interior [0, 6] x [0, 4], 0.2 m walls) with a 0.5 m x 0.6 m box in it.
const std::vector<Box> kRoom = {
    {-0.2, -0.2, 6.2, 0.0},  // bottom wall
    {-0.2, 4.0, 6.2, 4.2},   // top wall
    {-0.2, -0.2, 0.0, 4.2},  // left wall
    {6.0, -0.2, 6.2, 4.2},   // right wall
    {3.0, 1.0, 3.5, 1.6},    // box
};
constexpr double kRes = 0.1;
const Eigen::Vector2d kOrigin(-1.0, -0.5);
constexpr int kWidth = 80, kHeight = 60;

FloorPlan rasterizeRoom() {
  std::vector<std::uint8_t> occ(kWidth * kHeight, 0);
  for (int iy = 0; iy < kHeight; ++iy) {
    for (int ix = 0; ix < kWidth; ++ix) {
      const double cx = kOrigin.x() + (ix + 0.5) * kRes, cy = kOrigin.y() + (iy + 0.5) * kRes;
      for (const Box& b : kRoom)
        if (cx > b.x0 && cx < b.x1 && cy > b.y0 && cy < b.y1) occ[iy * kWidth + ix] = 1;
    }
  }
  return FloorPlan::fromOccupancy(kWidth, kHeight, kRes, kOrigin, occ);
}

/// Independent analytic reference: nearest entry of the ray into any box (slab method), +inf if none.
/// `face` gets 0 for a face normal to x, 1 for one normal to y.
double analyticRange(const Eigen::Vector2d& p, double angle, int* face = nullptr) {
  const double dx = std::cos(angle), dy = std::sin(angle);
  double best = std::numeric_limits<double>::infinity();
  for (const Box& b : kRoom) {
    double tx0 = (b.x0 - p.x()) / dx, tx1 = (b.x1 - p.x()) / dx;
    double ty0 = (b.y0 - p.y()) / dy, ty1 = (b.y1 - p.y()) / dy;
    if (tx0 > tx1) std::swap(tx0, tx1);
    if (ty0 > ty1) std::swap(ty0, ty1);
    const double t_in = std::max(tx0, ty0), t_out = std::min(tx1, ty1);
    if (t_in <= t_out && t_in >= 0.0 && t_in < best) {
      best = t_in;
      if (face) *face = tx0 > ty0 ? 0 : 1;
    }
  }
  return best;
}

ScanSimulatorConfig noiseFree() {
  ScanSimulatorConfig c;
  c.noise_min_stddev = 0.0;
  c.noise_range_fraction = 0.0;
  c.dropout_probability = 0.0;
  c.grazing_dropout_probability = 0.0;
  c.outlier_probability = 0.0;
  return c;
}

const std::vector<Pose2D> kPoses = {{1.234, 2.345, 0.3}, {4.71, 0.83, -2.0}, {5.5, 3.6, 2.9}, {2.2, 1.3, -0.01}};

TEST(ScanSimulator, Urg04lxDefaults) {
  const FloorPlan plan = rasterizeRoom();
  ScanSimulator sim(plan, ScanSimulatorConfig(), 1);
  const LaserScan s = sim.simulate({1.0, 1.0, 0.0}, 1000.5);
  EXPECT_EQ(s.ranges.size(), 683u);
  EXPECT_DOUBLE_EQ(s.stamp, 1000.5);
  EXPECT_EQ(s.frame_id, "laser");
  EXPECT_NEAR(s.angle_min, -120.0 * M_PI / 180.0, 1e-12);
  EXPECT_NEAR(s.angle_max, 120.0 * M_PI / 180.0, 1e-12);
  EXPECT_NEAR(s.angle_increment, (240.0 / 682.0) * M_PI / 180.0, 1e-12);
  EXPECT_NEAR(s.angle_min + 682 * s.angle_increment, s.angle_max, 1e-12);
  EXPECT_DOUBLE_EQ(s.range_min, 0.02);
  EXPECT_DOUBLE_EQ(s.range_max, 5.6);
  EXPECT_DOUBLE_EQ(s.scan_time, 0.1);
}

TEST(ScanSimulator, NoiseFreeRangesMatchAnalyticRayBoxIntersection) {
  const FloorPlan plan = rasterizeRoom();
  ScanSimulatorConfig c = noiseFree();
  c.range_max = 10.0;
  ScanSimulator sim(plan, c, 7);
  int checked = 0;
  for (const Pose2D& pose : kPoses) {
    const LaserScan s = sim.simulate(pose, 1000.0);
    ASSERT_EQ(s.ranges.size(), 683u);
    for (std::size_t i = 0; i < s.ranges.size(); ++i) {
      const double expected = analyticRange(pose.translation(), pose.theta + s.angle_min + i * s.angle_increment);
      ASSERT_TRUE(std::isfinite(expected));  // the room is closed
      ASSERT_NEAR(s.ranges[i], expected, 1e-6) << "pose " << pose.x << "," << pose.y << " beam " << i;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 4 * 683);
}

TEST(ScanSimulator, BeyondRangeMaxIsPositiveInfinity) {
  const FloorPlan plan = rasterizeRoom();
  ScanSimulatorConfig c = noiseFree();
  c.range_max = 2.0;
  ScanSimulator sim(plan, c, 7);
  int inf = 0, finite = 0;
  for (const Pose2D& pose : kPoses) {
    const LaserScan s = sim.simulate(pose, 1000.0);
    for (std::size_t i = 0; i < s.ranges.size(); ++i) {
      const double expected = analyticRange(pose.translation(), pose.theta + s.angle_min + i * s.angle_increment);
      if (std::abs(expected - c.range_max) < 1e-6) continue;
      if (expected > c.range_max) {
        EXPECT_TRUE(std::isinf(s.ranges[i]) && s.ranges[i] > 0) << "beam " << i << ": " << s.ranges[i];
        ++inf;
      } else {
        EXPECT_NEAR(s.ranges[i], expected, 1e-6);
        ++finite;
      }
    }
  }
  EXPECT_GT(inf, 100);
  EXPECT_GT(finite, 100);

  // With range noise, no finite reading lies outside [range_min, range_max].
  ScanSimulatorConfig noisy;
  noisy.range_max = 2.0;
  noisy.noise_min_stddev = 0.05;
  ScanSimulator noisy_sim(plan, noisy, 9);
  int near_max = 0;
  for (int k = 0; k < 40; ++k) {
    const Pose2D& pose = kPoses[k % kPoses.size()];
    const LaserScan s = noisy_sim.simulate(pose, 1000.0);
    for (std::size_t i = 0; i < s.ranges.size(); ++i) {
      if (!std::isfinite(s.ranges[i])) continue;
      EXPECT_LE(s.ranges[i], noisy.range_max);
      EXPECT_GE(s.ranges[i], noisy.range_min);
      near_max += s.ranges[i] > noisy.range_max - 0.05;
    }
  }
  EXPECT_GT(near_max, 10);  // the check above was exercised
}

TEST(ScanSimulator, DropoutsAreNaNAtTheConfiguredRate) {
  const FloorPlan plan = rasterizeRoom();
  ScanSimulatorConfig c;  // default noise
  c.dropout_probability = 0.1;
  c.grazing_dropout_probability = 0.0;
  ScanSimulator sim(plan, c, 3);
  long nan = 0, total = 0;
  for (int k = 0; k < 30; ++k) {
    const LaserScan s = sim.simulate(kPoses[k % kPoses.size()], 1000.0 + 0.1 * k);
    for (float r : s.ranges) {
      nan += std::isnan(r);
      ++total;
    }
  }
  EXPECT_NEAR(static_cast<double>(nan) / total, 0.1, 0.015);

  c.dropout_probability = 0.0;
  ScanSimulator clean(plan, c, 3);
  const LaserScan s = clean.simulate(kPoses[0], 1000.0);
  EXPECT_EQ(std::count_if(s.ranges.begin(), s.ranges.end(), [](float r) { return std::isnan(r); }), 0);
}

TEST(ScanSimulator, GrazingDropoutsOnlyAtGrazingIncidence) {
  const FloorPlan plan = rasterizeRoom();
  ScanSimulatorConfig c = noiseFree();
  c.range_max = 10.0;
  c.grazing_dropout_probability = 1.0;
  ScanSimulator sim(plan, c, 5);
  int grazing = 0;
  for (const Pose2D& pose : kPoses) {
    const LaserScan s = sim.simulate(pose, 1000.0);
    for (std::size_t i = 0; i < s.ranges.size(); ++i) {
      const double a = pose.theta + s.angle_min + i * s.angle_increment;
      int face = -1;
      analyticRange(pose.translation(), a, &face);
      const double cos_inc = face == 0 ? std::abs(std::cos(a)) : std::abs(std::sin(a));
      if (std::abs(cos_inc - std::cos(c.grazing_angle)) < 1e-6) continue;
      const bool expect_nan = cos_inc < std::cos(c.grazing_angle);
      EXPECT_EQ(std::isnan(s.ranges[i]), expect_nan) << "beam " << i;
      grazing += expect_nan;
    }
  }
  EXPECT_GT(grazing, 10);
}

TEST(ScanSimulator, RangeNoiseHasTheDatasheetSpread) {
  const FloorPlan plan = rasterizeRoom();
  ScanSimulatorConfig c;
  c.range_max = 10.0;
  c.dropout_probability = 0.0;
  c.grazing_dropout_probability = 0.0;
  ScanSimulator sim(plan, c, 11);
  double sum = 0.0, sum_sq = 0.0;
  long n = 0;
  for (int k = 0; k < 20; ++k) {
    const Pose2D& pose = kPoses[k % kPoses.size()];
    const LaserScan s = sim.simulate(pose, 1000.0);
    for (std::size_t i = 0; i < s.ranges.size(); ++i) {
      const double expected = analyticRange(pose.translation(), pose.theta + s.angle_min + i * s.angle_increment);
      ASSERT_TRUE(std::isfinite(s.ranges[i]));
      const double z = (s.ranges[i] - expected) / std::max(0.01, 0.01 * expected);
      sum += z;
      sum_sq += z * z;
      ++n;
    }
  }
  const double mean = sum / n;
  EXPECT_NEAR(mean, 0.0, 0.05);
  EXPECT_NEAR(std::sqrt(sum_sq / n - mean * mean), 1.0, 0.05);
}

TEST(ScanSimulator, OutliersAreShorterThanTheWall) {
  const FloorPlan plan = rasterizeRoom();
  ScanSimulatorConfig c = noiseFree();
  c.range_max = 10.0;
  c.outlier_probability = 1.0;
  ScanSimulator sim(plan, c, 5);
  const LaserScan s = sim.simulate(kPoses[0], 1000.0);
  int shorter = 0;
  for (std::size_t i = 0; i < s.ranges.size(); ++i) {
    const double expected = analyticRange(kPoses[0].translation(), kPoses[0].theta + s.angle_min + i * s.angle_increment);
    EXPECT_LE(s.ranges[i], expected + 1e-6);
    EXPECT_GE(s.ranges[i], c.range_min);
    shorter += s.ranges[i] < expected - 0.05;
  }
  EXPECT_GT(shorter, 500);
}

bool bitwiseEqual(const LaserScan& a, const LaserScan& b) {
  return a.ranges.size() == b.ranges.size() &&
         std::memcmp(a.ranges.data(), b.ranges.data(), a.ranges.size() * sizeof(float)) == 0;
}

TEST(ScanSimulator, SameSeedGivesIdenticalScans) {
  const FloorPlan plan = rasterizeRoom();
  ScanSimulatorConfig c;
  c.outlier_probability = 0.05;
  ScanSimulator a(plan, c, 42), b(plan, c, 42), other(plan, c, 43);
  bool any_difference = false;
  for (int k = 0; k < 5; ++k) {
    const Pose2D& pose = kPoses[k % kPoses.size()];
    const LaserScan sa = a.simulate(pose, 1000.0 + k), sb = b.simulate(pose, 1000.0 + k);
    const LaserScan so = other.simulate(pose, 1000.0 + k);
    EXPECT_TRUE(bitwiseEqual(sa, sb)) << "scan " << k;
    any_difference |= !bitwiseEqual(sa, so);
  }
  EXPECT_TRUE(any_difference);
}

TEST(ScanSimulator, RejectsBadConfig) {
  const FloorPlan plan = rasterizeRoom();
  ScanSimulatorConfig c;
  c.dropout_probability = 1.5;
  EXPECT_THROW(ScanSimulator(plan, c, 1), std::invalid_argument);
  c = ScanSimulatorConfig();
  c.range_max = 0.01;
  EXPECT_THROW(ScanSimulator(plan, c, 1), std::invalid_argument);
  c = ScanSimulatorConfig();
  c.beams = 0;
  EXPECT_THROW(ScanSimulator(plan, c, 1), std::invalid_argument);
}

}  // namespace
}  // namespace laser_dpslam
