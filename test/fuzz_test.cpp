// Fuzz (issue 6): 10^5 randomly malformed scans through preprocessing → laser odometry, and a shorter
// stream through preprocessing → odometry → DP-SLAM. Nothing may crash or throw, and no pose,
// covariance, velocity, particle weight or map value may ever be non-finite or out of range.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>

#include "laser_dpslam/odometry/laser_odometry.h"
#include "laser_dpslam/scan/scan_preprocessor.h"
#include "laser_dpslam/slam/dpslam.h"

using namespace laser_dpslam;

namespace {

float pick(std::mt19937_64& rng) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  std::uniform_real_distribution<float> range(0.0f, 6.0f);
  switch (rng() % 10) {
    case 0: return nan;
    case 1: return inf;
    case 2: return -inf;
    case 3: return -range(rng);
    case 4: return 1e30f;
    case 5: return 0.0f;
    case 6: return std::numeric_limits<float>::denorm_min();
    default: return range(rng);
  }
}

double pickField(std::mt19937_64& rng, double sane) {
  switch (rng() % 12) {
    case 0: return std::numeric_limits<double>::quiet_NaN();
    case 1: return std::numeric_limits<double>::infinity();
    case 2: return -sane;
    case 3: return 0.0;
    case 4: return 1e12;
    default: return sane;
  }
}

LaserScan randomScan(std::mt19937_64& rng, double stamp) {
  LaserScan s;
  s.stamp = stamp;
  s.frame_id = "laser";
  const std::size_t n = rng() % 4 == 0 ? rng() % 8 : 100 + rng() % 700;  // empty, tiny or ordinary
  s.angle_min = pickField(rng, -2.09);
  s.angle_increment = pickField(rng, 0.00614);
  s.angle_max = rng() % 5 == 0 ? pickField(rng, -3.0) : s.angle_min + s.angle_increment * (n ? n - 1 : 0);
  s.range_min = pickField(rng, 0.02);
  s.range_max = pickField(rng, 5.6);
  s.ranges.resize(n);
  // Mostly-plausible scans: a room-like shape with garbage sprinkled in, so the matcher is exercised.
  const bool structured = rng() % 2 == 0;
  for (std::size_t i = 0; i < n; ++i) {
    s.ranges[i] = structured && rng() % 8 != 0 ? 2.0f + 0.5f * std::sin(0.02f * i) : pick(rng);
  }
  s.intensities.resize(rng() % 3 == 0 ? rng() % 50 : 0);
  return s;
}

}  // namespace

TEST(Fuzz, MalformedScansNeverCrashOrPoisonTheOdometry) {
  std::mt19937_64 rng(20261122);
  LaserOdometryConfig config;
  config.matcher.de_generations = 5;  // keep the run short: the matcher's inputs are what is fuzzed
  LaserOdometry odometry(config);
  double stamp = 1000.0;
  int processed = 0, rejected = 0, matched = 0;
  for (int i = 0; i < 100000; ++i) {
    // Time mostly moves on, sometimes repeats, jumps back (bag loop) or leaps forward.
    const auto r = rng() % 50;
    stamp += r == 0 ? -30.0 : r == 1 ? 0.0 : r == 2 ? 500.0 : 0.1;
    const LaserScan scan = randomScan(rng, stamp);
    PreprocessedScan pre;
    ASSERT_NO_THROW(pre = preprocessScan(scan, ScanPreprocessorConfig())) << "scan " << i;
    for (const auto& p : pre.points) ASSERT_TRUE(p.allFinite()) << "scan " << i;
    if (!pre.ok()) ++rejected;
    const LaserMount mount = LaserMount::fromPose(Pose2D(0.1, 0.0, 0.0));
    OdometryUpdate u;
    ASSERT_NO_THROW(u = odometry.process(pre, mount)) << "scan " << i;
    ASSERT_TRUE(u.pose.vector().allFinite()) << "scan " << i;
    ASSERT_TRUE(u.pose_covariance.allFinite()) << "scan " << i;
    ASSERT_TRUE(u.delta_covariance.allFinite()) << "scan " << i;
    ASSERT_TRUE(u.velocity.allFinite()) << "scan " << i;
    ++processed;
    if (u.ok && u.match.valid) ++matched;
  }
  EXPECT_EQ(processed, 100000);
  // The fuzzer must reach both the rejection paths and the matcher, or it tests nothing.
  EXPECT_GT(rejected, 10000);
  EXPECT_GT(matched, 1000);
  RecordProperty("rejected", rejected);
  RecordProperty("matched", matched);
}

namespace {

/// The exported map: consistent size, finite origin, every value -1 (unknown) or 0..100.
::testing::AssertionResult mapIsSane(const OccupancyGridData& g) {
  if (g.width < 0 || g.height < 0 || g.data.size() != static_cast<std::size_t>(g.width) * g.height)
    return ::testing::AssertionFailure() << "map size " << g.width << "x" << g.height << " with " << g.data.size() << " cells";
  if (!std::isfinite(g.origin_x) || !std::isfinite(g.origin_y) || !(g.resolution > 0.0))
    return ::testing::AssertionFailure() << "map origin or resolution not finite";
  for (std::int8_t v : g.data) {
    if (v < -1 || v > 100) return ::testing::AssertionFailure() << "map value " << int(v);
  }
  return ::testing::AssertionSuccess();
}

}  // namespace

TEST(Fuzz, MalformedScansThroughOdometryAndSlamNeverPoisonTheSlam) {
  // Glue as in the nodes: every scan goes to the SLAM (malformed ones too: it must skip them), the motion
  // is the odometry's delta and covariance, and time going backwards resets both.
  std::mt19937_64 rng(20261123);
  LaserOdometryConfig odom_config;
  odom_config.matcher.de_generations = 5;
  LaserOdometry odometry(odom_config);
  DpSlamConfig slam_config;
  slam_config.particles = 8;  // small: what is fuzzed is the input, and 10^5 scans must stay quick (~2 min)
  slam_config.threads = 2;
  slam_config.seed = 7;
  DpSlam slam(slam_config);
  const LaserMount mount = LaserMount::fromPose(Pose2D(0.1, 0.0, 0.0));
  double stamp = 1000.0, previous = -1.0;
  Pose2D last_odom;
  bool has_last = false;
  int slam_used = 0, slam_skipped = 0, resets = 0;
  const int n = 100000;  // issue 6: >= 10^5 malformed scans through the whole chain
  for (int i = 0; i < n; ++i) {
    const auto r = rng() % 50;
    stamp += r == 0 ? -30.0 : r == 1 ? 0.0 : r == 2 ? 500.0 : 0.1;
    const PreprocessedScan pre = preprocessScan(randomScan(rng, stamp), ScanPreprocessorConfig());
    if (previous >= 0.0 && stamp < previous) {
      slam.reset();
      has_last = false;
      ++resets;
    }
    previous = stamp;
    OdometryUpdate u;
    ASSERT_NO_THROW(u = odometry.process(pre, mount)) << "scan " << i;
    if (u.skip_reason == OdometrySkipReason::kDuplicateStamp) continue;  // nothing new for this time
    const Pose2D delta = has_last && !u.reset ? between(last_odom, u.pose) : Pose2D();
    last_odom = u.pose;
    has_last = true;
    DpSlamUpdate s;
    ASSERT_NO_THROW(s = slam.process(stamp, pre, mount, delta, u.delta_covariance)) << "scan " << i;
    ASSERT_TRUE(s.pose.vector().allFinite()) << "scan " << i;
    ASSERT_TRUE(s.covariance.allFinite()) << "scan " << i;
    ASSERT_TRUE(std::isfinite(s.neff)) << "scan " << i;
    ASSERT_LE(s.tree_nodes, static_cast<std::size_t>(2 * slam_config.particles - 1)) << "scan " << i;
    for (const Pose2D& p : slam.particlePoses()) {
      ASSERT_TRUE(p.vector().allFinite()) << "scan " << i;
    }
    for (double w : slam.logWeights()) {
      ASSERT_TRUE(std::isfinite(w)) << "scan " << i;
    }
    (s.ok ? slam_used : slam_skipped)++;
    if (i % 500 == 499) {
      ASSERT_TRUE(mapIsSane(slam.bestMap())) << "scan " << i;
    }
  }
  EXPECT_TRUE(mapIsSane(slam.bestMap()));
  for (const StampedPose& p : slam.bestTrajectory()) {
    ASSERT_TRUE(p.pose.vector().allFinite() && std::isfinite(p.stamp));
  }
  // Both the SLAM's skip paths and its filter must have been reached, and resets must have happened.
  EXPECT_GT(slam_used, 10000);
  EXPECT_GT(slam_skipped, 10000);
  EXPECT_GT(resets, 500);
  std::printf("[ Fuzz     ] SLAM: %d scans used, %d skipped, %d time resets\n", slam_used, slam_skipped, resets);
  RecordProperty("slam_used", slam_used);
  RecordProperty("slam_skipped", slam_skipped);
}
