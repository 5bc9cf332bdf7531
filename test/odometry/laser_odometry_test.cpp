#include "laser_dpslam/odometry/laser_odometry.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include "laser_dpslam/odometry/wheel_motion.h"
#include "laser_dpslam/sim/scan_simulator.h"
#include "laser_dpslam/sim/sim_path.h"
#include "test_rooms.h"

using namespace laser_dpslam;

namespace {

// A loop around the furnished room at iRobot Create speeds, scanned at 10 Hz with URG-04LX noise.
struct SimRun {
  std::vector<TimedPose> truth;
  std::vector<LaserScan> scans;
};

SimRun simulateLoop(std::uint64_t seed) {
  static const FloorPlan room = test::furnishedRoom();
  const std::vector<Eigen::Vector2d> waypoints{{1.5, 2.5}, {3.2, 3.0}, {6.5, 2.0}, {7.0, 5.0}, {4.5, 5.0}, {1.5, 3.5}, {1.5, 2.5}};
  SimRun run;
  run.truth = samplePath(waypoints, 10.0, PathConfig());
  ScanSimulator sim(room, ScanSimulatorConfig(), seed);
  for (const auto& tp : run.truth) run.scans.push_back(sim.simulate(tp.pose, 100.0 + tp.stamp));
  return run;
}

// Drives `truth` through the loop building (plans/loop_building) and returns the odometry's final position
// error (m); `observe`, when given, sees every true pose with the odometry's update for it.
using UpdateObserver = std::function<void(const TimedPose&, const OdometryUpdate&)>;
double loopBuildingFinalError(const std::vector<TimedPose>& truth, const LaserOdometryConfig& config,
                              std::uint64_t seed, const UpdateObserver& observe = nullptr) {
  static const FloorPlan plan = FloorPlan::load("plans/loop_building.yaml");
  ScanSimulator sim(plan, ScanSimulatorConfig(), seed);
  LaserOdometry odom(config);
  for (const auto& tp : truth) {
    const OdometryUpdate u =
        odom.process(preprocessScan(sim.simulate(tp.pose, 100.0 + tp.stamp), ScanPreprocessorConfig()), LaserMount());
    if (observe) observe(tp, u);
  }
  const Pose2D end = between(truth.front().pose, truth.back().pose);
  return std::hypot(odom.pose().x - end.x, odom.pose().y - end.y);
}

// The loop building's west corridor as the loop drives it, from rest at its north end to its south end (17.1 m).
double westCorridorFinalError(const LaserOdometryConfig& config, std::uint64_t seed,
                              const UpdateObserver& observe = nullptr) {
  static const std::vector<TimedPose> truth = samplePath({{1.95, 19.05}, {1.95, 1.95}}, 10.0, PathConfig());
  return loopBuildingFinalError(truth, config, seed, observe);
}

}  // namespace

TEST(LaserOdometry, TracksASimulatedLoopWithSmallDrift) {
  const SimRun run = simulateLoop(1);
  LaserOdometry odom;
  double max_err = 0.0, travelled = 0.0;
  const Pose2D start = run.truth.front().pose;
  for (std::size_t i = 0; i < run.scans.size(); ++i) {
    const OdometryUpdate u = odom.process(preprocessScan(run.scans[i], ScanPreprocessorConfig()), LaserMount());
    ASSERT_TRUE(u.ok) << "scan " << i << ": " << toString(u.skip_reason);
    const Pose2D truth = between(start, run.truth[i].pose);  // odometry starts at the identity
    max_err = std::max(max_err, std::hypot(u.pose.x - truth.x, u.pose.y - truth.y));
    if (i > 0) {
      travelled += std::hypot(run.truth[i].pose.x - run.truth[i - 1].pose.x, run.truth[i].pose.y - run.truth[i - 1].pose.y);
    }
    EXPECT_TRUE(u.pose_covariance.allFinite());
    EXPECT_GE(u.delta_covariance(0, 0), 0.0);
  }
  const Pose2D end_truth = between(start, run.truth.back().pose);
  const double final_err = std::hypot(odom.pose().x - end_truth.x, odom.pose().y - end_truth.y);
  ASSERT_GT(travelled, 15.0);
  // Laser odometry drifts; on this small, well-structured room it must stay within 1 % of the path.
  EXPECT_LT(final_err, 0.01 * travelled) << "travelled " << travelled;
  EXPECT_LT(max_err, 0.15);
  EXPECT_LT(std::abs(normalizeAngle(odom.pose().theta - end_truth.theta)), 1.0 * M_PI / 180.0);
}

// align_to_walls: the match runs in a frame along the room's walls (the loop starts 16.4° off them), the
// outputs stay in the odom frame (the first pose), with the same accuracy as above.
TEST(LaserOdometry, AlignToWallsMatchesAlongTheWallsAndReportsInTheOdomFrame) {
  const SimRun run = simulateLoop(1);
  LaserOdometryConfig config;
  config.align_to_walls = true;
  LaserOdometry odom(config);
  double max_err = 0.0;
  const Pose2D start = run.truth.front().pose;
  for (std::size_t i = 0; i < run.scans.size(); ++i) {
    const OdometryUpdate u = odom.process(preprocessScan(run.scans[i], ScanPreprocessorConfig()), LaserMount());
    ASSERT_TRUE(u.ok) << "scan " << i << ": " << toString(u.skip_reason);
    if (i == 0) {
      EXPECT_NEAR(u.pose.x, 0.0, 1e-12);
      EXPECT_NEAR(u.pose.y, 0.0, 1e-12);
      EXPECT_NEAR(u.pose.theta, 0.0, 1e-12);
    }
    const Pose2D truth = between(start, run.truth[i].pose);
    max_err = std::max(max_err, std::hypot(u.pose.x - truth.x, u.pose.y - truth.y));
    const Pose2D p = odom.pose();
    EXPECT_NEAR(p.x, u.pose.x, 1e-9);
    EXPECT_NEAR(p.theta, u.pose.theta, 1e-9);
  }
  // The robot starts heading atan2(0.5, 1.7) = 16.4° in a room with axis-aligned walls.
  EXPECT_NEAR(odom.frameAngle(), std::atan2(0.5, 1.7), 1.0 * M_PI / 180.0);
  const Pose2D end_truth = between(start, run.truth.back().pose);
  EXPECT_LT(std::hypot(odom.pose().x - end_truth.x, odom.pose().y - end_truth.y), 0.15);
  EXPECT_LT(max_err, 0.15);
  EXPECT_LT(std::abs(normalizeAngle(odom.pose().theta - end_truth.theta)), 1.0 * M_PI / 180.0);
  // Off: the matching frame is the odom frame.
  LaserOdometryConfig off;
  off.align_to_walls = false;
  LaserOdometry plain(off);
  plain.process(preprocessScan(run.scans[0], ScanPreprocessorConfig()), LaserMount());
  EXPECT_EQ(plain.frameAngle(), 0.0);
}

TEST(LaserOdometry, SameSeedGivesIdenticalPoses) {
  const SimRun run = simulateLoop(2);
  LaserOdometry a, b;
  for (std::size_t i = 0; i < 80; ++i) {
    const PreprocessedScan s = preprocessScan(run.scans[i], ScanPreprocessorConfig());
    const Pose2D pa = a.process(s, LaserMount()).pose, pb = b.process(s, LaserMount()).pose;
    ASSERT_EQ(pa.x, pb.x);
    ASSERT_EQ(pa.y, pb.y);
    ASSERT_EQ(pa.theta, pb.theta);
  }
}

TEST(LaserOdometry, BadScansAreSkippedAndNeverCorruptThePose) {
  const SimRun run = simulateLoop(3);
  LaserOdometry odom;
  for (std::size_t i = 0; i < 60; ++i) {
    LaserScan s = run.scans[i];
    if (i % 10 == 5) {
      // Only NaN / ±inf / out-of-range values (REP-117): nothing to match.
      for (std::size_t k = 0; k < s.ranges.size(); ++k) {
        const float bad[4] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                              -std::numeric_limits<float>::infinity(), 100.0f};
        s.ranges[k] = bad[k % 4];
      }
    }
    if (i % 10 == 7) s.angle_increment = 0.0;  // malformed
    const OdometryUpdate u = odom.process(preprocessScan(s, ScanPreprocessorConfig()), LaserMount());
    EXPECT_TRUE(u.pose.vector().allFinite());
    EXPECT_TRUE(u.pose_covariance.allFinite());
    if (i % 10 == 5) {
      EXPECT_EQ(u.skip_reason, OdometrySkipReason::kTooFewPoints);
    } else if (i % 10 == 7) {
      EXPECT_EQ(u.skip_reason, OdometrySkipReason::kMalformedScan);
    } else {
      EXPECT_TRUE(u.ok) << i;
    }
  }
  // Still on track after the bad scans.
  const Pose2D truth = between(run.truth.front().pose, run.truth[59].pose);
  EXPECT_LT(std::hypot(odom.pose().x - truth.x, odom.pose().y - truth.y), 0.05);
}

TEST(LaserOdometry, TimeGoingBackwardsResetsAndDuplicatesAreSkipped) {
  const SimRun run = simulateLoop(4);
  LaserOdometry odom;
  for (std::size_t i = 0; i < 30; ++i) odom.process(preprocessScan(run.scans[i], ScanPreprocessorConfig()), LaserMount());
  EXPECT_GT(std::hypot(odom.pose().x, odom.pose().y), 0.05);
  const OdometryUpdate dup = odom.process(preprocessScan(run.scans[29], ScanPreprocessorConfig()), LaserMount());
  EXPECT_EQ(dup.skip_reason, OdometrySkipReason::kDuplicateStamp);
  const OdometryUpdate back = odom.process(preprocessScan(run.scans[0], ScanPreprocessorConfig()), LaserMount());
  EXPECT_EQ(back.skip_reason, OdometrySkipReason::kTimeBackwards);
  EXPECT_TRUE(back.reset);
  EXPECT_EQ(back.pose.x, 0.0);
  EXPECT_EQ(back.pose.y, 0.0);
}

TEST(LaserOdometry, MountedLaserGivesTheBasePose) {
  // Laser 0.2 m ahead of base_link and yawed 90°: the odometry must still report base_link's motion.
  const FloorPlan room = test::furnishedRoom();
  const Pose2D mount_pose(0.2, 0.0, M_PI / 2);
  ScanSimulator sim(room, ScanSimulatorConfig(), 9);
  const std::vector<Eigen::Vector2d> waypoints{{2.0, 2.5}, {5.0, 3.0}};
  const auto truth = samplePath(waypoints, 10.0, PathConfig());
  LaserOdometry odom;
  for (const auto& tp : truth) {
    odom.process(preprocessScan(sim.simulate(tp.pose * mount_pose, tp.stamp + 1.0), ScanPreprocessorConfig()),
                 LaserMount::fromPose(mount_pose));
  }
  const Pose2D expected = between(truth.front().pose, truth.back().pose);
  EXPECT_NEAR(odom.pose().x, expected.x, 0.03);
  EXPECT_NEAR(odom.pose().y, expected.y, 0.03);
  EXPECT_NEAR(odom.pose().theta, expected.theta, 0.01);
}

// kVelocityGain: the prior's translation velocity is an exponential smoothing of the matched motions
// (v ← (1 − g)·v + g·Δ/dt), its rotation the last motion. Taking the last motion as the velocity feeds each
// match's small bias along a corridor straight back into the next prior. Its effect is a distribution's,
// not one corridor's: on the generated buildings (scripts/benchmark_buildings.sh --odometry-only, bench
// list, search seeds 1 / 2) the laser odometry's drift median is 0.33 / 0.34 % with g = 0.3 and 0.54 /
// 0.65 % with g = 1, p90 0.93 / 1.32 % against 1.51 / 3.12 % (doc/experiments.md). Here: the rule itself,
// on the furnished-room loop, where every match constrains the pose (the corridor rules stay out).
TEST(LaserOdometry, VelocityIsTheSmoothedMatchedMotion) {
  const SimRun run = simulateLoop(2);
  LaserOdometryConfig c;
  const double g = LaserOdometry::kVelocityGain;
  ASSERT_GT(g, 0.0);
  ASSERT_LT(g, 1.0);
  LaserOdometry odom(c);
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  double last_stamp = 0.0;
  int checked = 0;
  for (std::size_t i = 0; i < run.scans.size(); ++i) {
    const OdometryUpdate u = odom.process(preprocessScan(run.scans[i], ScanPreprocessorConfig()), LaserMount());
    ASSERT_TRUE(u.ok) << "scan " << i;
    if (i > 0 && !u.match.degenerate) {
      const double dt = u.stamp - last_stamp;
      const Eigen::Vector3d measured = Eigen::Vector3d(u.delta.x, u.delta.y, u.delta.theta) / dt;
      const Eigen::Vector2d expected = (1.0 - g) * v.head<2>() + g * measured.head<2>();
      EXPECT_NEAR(u.velocity.x(), expected.x(), 1e-9) << "scan " << i;
      EXPECT_NEAR(u.velocity.y(), expected.y(), 1e-9) << "scan " << i;
      EXPECT_NEAR(u.velocity.z(), measured.z(), 1e-9) << "scan " << i;
      ++checked;
    }
    v = u.velocity;
    last_stamp = u.stamp;
  }
  EXPECT_GT(checked, static_cast<int>(run.scans.size()) / 2);
}

// degenerate_velocity_gain: where the match is degenerate, its motion along the weak direction is the prior
// plus the NDT score's ripple (the score of points on a wall varies with their place in the cells), and the
// velocity along that direction takes only that gain of it (v_w ← v_w + g_w·(Δ_w/dt − v_w)), across it
// kVelocityGain as everywhere. Its effect is a distribution's, not one corridor's: on the generated buildings
// (scripts/benchmark_buildings.sh --odometry-only, both lists, search seeds 1 and 2) switching it off changes
// 3-4 of ~30 runs per list and seed, among them the loop building, whose odometry ATE goes 0.042 / 0.094 m →
// 0.123 / 0.204 m (a heading error of up to 0.9° builds up); with the defaults' hold it changes nothing on
// the west corridor (doc/experiments.md, "The held speed fitted to the matches that measured it"). It acts
// until a match has fixed every direction (after that the hold keeps the velocity) and after a released
// prior. Here: the rule itself on that corridor, from rest 4 m south of its north end to its south end,
// without the flow (which moves the velocity by its own rule).
TEST(LaserOdometry, DegenerateVelocityGainSmoothsAlongTheWeakDirection) {
  LaserOdometryConfig c;
  c.align_to_walls = false;  // the updates' poses in the frame the matches are made in
  c.range_flow_gain = 0.0;   // the flow moves the velocity by its own rule
  const double g = LaserOdometry::kVelocityGain, gw = c.degenerate_velocity_gain;
  ASSERT_GT(gw, 0.0);
  ASSERT_LT(gw, g);
  static const std::vector<TimedPose> truth = samplePath({{1.95, 15.0}, {1.95, 1.95}}, 10.0, PathConfig());
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Pose2D previous;
  double last_stamp = 0.0;
  int smoothed = 0, held = 0;
  bool was_blank = false;
  loopBuildingFinalError(truth, c, 1, [&](const TimedPose&, const OdometryUpdate& u) {
    // (A blank stretch's first scan sets the speed it holds by its own rule: HeldSpeedCarriesAFortyMetre….)
    const bool fitted = u.velocity_held_blank && !was_blank;
    was_blank = u.velocity_held_blank;
    if (u.ok && !u.reset && u.match.degenerate && !fitted) {
      const Eigen::Vector2d w = previous.rotation().transpose() * u.match.weak_direction;  // base frame
      const Eigen::Vector2d measured = Eigen::Vector2d(u.delta.x, u.delta.y) / (u.stamp - last_stamp);
      const Eigen::Vector2d across(-w.y(), w.x());
      // Held (a match has fixed every direction since the start or the last released prior): unchanged
      // along the corridor; else smoothed with the degenerate gain. Across it: kVelocityGain.
      const double along = u.velocity_held ? w.dot(v.head<2>()) : w.dot(v.head<2>()) + gw * w.dot(measured - v.head<2>());
      EXPECT_NEAR(w.dot(u.velocity.head<2>()), along, 1e-9);
      EXPECT_NEAR(across.dot(u.velocity.head<2>()), across.dot((1.0 - g) * v.head<2>() + g * measured), 1e-9);
      ++(u.velocity_held ? held : smoothed);
    }
    v = u.velocity;
    previous = u.pose;
    last_stamp = u.stamp;
  });
  // Started from rest inside the corridor, the first matches fix nothing along it: the gain smooths the
  // velocity until a match fixes every direction (70 scans), the hold keeps it from then on.
  EXPECT_GT(smoothed, 0);
  EXPECT_GT(held, static_cast<int>(truth.size()) / 4);
  RecordProperty("smoothed_scans", smoothed);
  RecordProperty("held_scans", held);
  // Only for short-range lasers: with a laser longer than degenerate_velocity_max_range the gain is not used
  // (nor the hold, which the same range gates: both configs are gated here).
  LaserOdometryConfig gated = c, gated_without = c;
  gated_without.degenerate_velocity_gain = -1.0;
  gated.degenerate_velocity_max_range = gated_without.degenerate_velocity_max_range = 5.0;  // the URG-04LX: 5.6 m
  EXPECT_EQ(westCorridorFinalError(gated, 1), westCorridorFinalError(gated_without, 1));
}

// The same corridor, hold and all: south of the niche nothing along the corridor is in range for 3-6 s, and
// every match there pulls a little back towards the local map; even smoothed (degenerate_velocity_gain) that
// slowed the estimated speed scan after scan (the loop's odometry lost 0.10-0.36 m there in every run,
// scripts/benchmark_loop.sh). The hold keeps the speed measured where the last match fixed every direction,
// and where no surface faces along the corridor the match keeps the motion prior along it. Measured in the
// frame along the walls (the corridor's walls lie on the plan's 5 cm lattice, where align_to_walls' frame,
// ~0.3° off them, costs: doc/tuning.md). Final error, seeds 1-3 (m): 0.010, 0.007, 0.025 (without the hold
// 0.011, 0.021, 0.034).
TEST(LaserOdometry, DegenerateHoldKeepsTheSpeedThroughTheCorridor) {
  LaserOdometryConfig hold;
  hold.align_to_walls = false;
  double e_hold = 0.0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const double e = westCorridorFinalError(hold, seed);
    RecordProperty("seed" + std::to_string(seed) + "_mm", static_cast<int>(1000.0 * e));
    e_hold += e;
  }
  EXPECT_LT(e_hold / 3.0, 0.03);
  RecordProperty("hold_mean_mm", static_cast<int>(1000.0 * e_hold / 3.0));
  // The range gate holds for it too: with a laser longer than degenerate_velocity_max_range nothing is held.
  LaserOdometryConfig gated = hold;
  gated.degenerate_velocity_max_range = 5.0;
  int held = 0;
  westCorridorFinalError(gated, 1, [&](const TimedPose&, const OdometryUpdate& u) {
    held += u.velocity_held || u.velocity_held_blank ? 1 : 0;
  });
  EXPECT_EQ(held, 0);
}

// A robot that stops in a corridor: the west corridor from its north end to y = 11 m (1.2 m before the niche
// comes alongside, its faces ahead in view), then 15 s standing. The match against the local map cannot tell
// standing still from driving on, and the hold keeps the speed measured before: without the range
// flow the estimate drove on, final error seeds 1-3 2.275, 0.783, 0.064 m. The niche's faces, which face the
// corridor, show from one scan to the next that the robot stopped: 0.030, 0.019, 0.064 m with it. Braking to
// a stop there and driving on at once costs: 0.081, 0.058, 0.036 m without, 0.199, 0.161, 0.036 m with (the
// flow slows the velocity while the robot brakes, and what it leaves of the speed afterwards, within its
// noise band, the hold carries through the featureless stretch south of the niche); it must stay under
// 0.15 m more than without.
TEST(LaserOdometry, RangeFlowStopsTheEstimateWhereTheRobotStops) {
  PathConfig stop;
  stop.end_pause = 15.0;
  const std::vector<TimedPose> stopping = samplePath({{1.95, 19.05}, {1.95, 11.0}}, 10.0, stop);
  const std::vector<TimedPose> passing = samplePath({{1.95, 19.05}, {1.95, 11.0}, {1.95, 1.95}}, 10.0, PathConfig());
  LaserOdometryConfig with, without;
  without.range_flow_gain = 0.0;
  ASSERT_GT(with.range_flow_gain, 0.0);
  double e_with = 0.0, e_without = 0.0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    int measured = 0;
    const double a = loopBuildingFinalError(stopping, without, seed),
                 b = loopBuildingFinalError(stopping, with, seed, [&](const TimedPose&, const OdometryUpdate& u) {
                   measured += u.range_flow.valid ? 1 : 0;
                 });
    EXPECT_LT(b, 0.2) << "seed " << seed;
    EXPECT_GT(measured, 10) << "seed " << seed;
    e_without += a;
    e_with += b;
    EXPECT_LT(loopBuildingFinalError(passing, with, seed), loopBuildingFinalError(passing, without, seed) + 0.15)
        << "seed " << seed;
    RecordProperty("seed" + std::to_string(seed) + "_mm",
                   std::to_string(static_cast<int>(1000.0 * a)) + " -> " + std::to_string(static_cast<int>(1000.0 * b)));
  }
  EXPECT_LT(e_with, 0.2 * e_without);
}

// The loop building's start: from rest in the south corridor (x = 15 m), 6 m east. Walls run along both sides
// and only a pillar ahead shows motion along the corridor; the soft motion prior says "at rest" and the
// smoothed velocity catches up slowly, so the estimate falls 0.6-1.2 m behind in the first 5 s and never
// recovers it (scripts/benchmark_loop.sh, before prior_release_speed). Dropping the prior while the estimate
// is slow and the scan fits clearly better without it keeps the start. Final error, seeds 1-3 (m): without
// 2.071, 0.914, 0.658; with 0.056, 0.037, 0.060. While the robot stands still first (3 s) the release must add
// no motion (the estimate wanders 3.5-4.4 cm along the corridor then, with or without it: a bounded
// offset within the first second, not a creep; 10 s at rest stay within 5 cm).
TEST(LaserOdometry, PriorReleaseKeepsAStartFromRestInACorridor) {
  PathConfig path;
  path.start_pause = 3.0;
  static const std::vector<TimedPose> truth = samplePath({{15.0, 1.95}, {21.0, 1.95}}, 10.0, path);
  LaserOdometryConfig off, on;
  off.prior_release_speed = 0.0;
  off.range_flow_gain = on.range_flow_gain = 0.0;  // measured before it (RangeFlowStopsTheEstimateWhereTheRobotStops)
  double e_off = 0.0, e_on = 0.0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    // The largest position error while the robot has not yet moved.
    double still = 0.0, still_off = 0.0;
    auto stillError = [&](double* worst) {
      return [worst](const TimedPose& tp, const OdometryUpdate& u) {
        if (between(truth.front().pose, tp.pose).vector().norm() == 0.0) *worst = std::max(*worst, std::hypot(u.pose.x, u.pose.y));
      };
    };
    const double a = loopBuildingFinalError(truth, off, seed, stillError(&still_off)),
                 b = loopBuildingFinalError(truth, on, seed, stillError(&still));
    EXPECT_LT(b, 0.3 * a) << "seed " << seed;
    EXPECT_LE(still, still_off + 1e-3) << "seed " << seed;
    e_off += a;
    e_on += b;
  }
  EXPECT_GT(e_off / 3.0, 0.3);  // the case is still hard without it
  EXPECT_LT(e_on / 3.0, 0.1);
  RecordProperty("without_mean_mm", static_cast<int>(1000.0 * e_off / 3.0));
  RecordProperty("with_mean_mm", static_cast<int>(1000.0 * e_on / 3.0));
}

// A released match's step also takes back the lag the soft prior let build up during a start from rest: a
// position correction, not a speed. Its change of velocity is bounded by prior_acceleration · dt, the prior's
// own model. The loop building's start shifted 0.5 m east and 0.1 m south, seed 3, is one where a release
// would change it by more (with the matching frame 0.04° closer to the walls, one 0.2 m catch-up reads as
// 2.1 m/s taken whole, and the hold carries 0.69 m/s on for a robot driving 0.3 m/s: 5 m off after 6 m).
TEST(LaserOdometry, ReleasedMatchChangesTheVelocityWithinThePriorsAcceleration) {
  PathConfig path;
  path.start_pause = 3.0;
  const std::vector<TimedPose> truth = samplePath({{15.5, 1.85}, {21.5, 1.85}}, 10.0, path);
  LaserOdometryConfig c;
  c.range_flow_gain = 0.0;  // as PriorReleaseKeepsAStartFromRestInACorridor
  Eigen::Vector2d v = Eigen::Vector2d::Zero();
  double last_stamp = 0.0, largest = 0.0;
  int released = 0;
  const double e = loopBuildingFinalError(truth, c, 3, [&](const TimedPose&, const OdometryUpdate& u) {
    if (u.ok && !u.reset && u.match.prior_released) {
      ++released;
      const double change = (u.velocity.head<2>() - v).norm(), limit = c.prior_acceleration * (u.stamp - last_stamp);
      EXPECT_LE(change, limit + 1e-9) << "at " << u.stamp;
      largest = std::max(largest, change / limit);
    }
    v = u.velocity.head<2>();
    last_stamp = u.stamp;
  });
  EXPECT_GT(released, 0);
  EXPECT_GE(largest, 1.0 - 1e-9);  // the bound acted here
  EXPECT_LT(e, 0.1);
  RecordProperty("final_error_mm", static_cast<int>(1000.0 * e));
}

// Standing still where the corridor shows least (the loop building's west corridor south of its niche, 30 s,
// seeds 1-3): the prior release must not fire on the scan noise. With a release margin
// (ScanMatcher::kPriorReleaseMargin) of 0.004 it fired twice with seed 3 and moved the estimate 0.124 m
// (0.078 m without the release); 0.005 keeps it out.
// Standing exactly parallel to walls on the plan's lattice with align_to_walls on (the default), the frame is
// ~0.3° off them and the release fires 3 times with seed 2 — without moving the estimate further than it
// drifts with the release off (checked below); with the frame along the walls it must not fire at all.
TEST(LaserOdometry, PriorReleaseDoesNotFireWhileStandingStill) {
  PathConfig path;
  path.start_pause = 30.0;
  std::vector<TimedPose> truth = samplePath({{1.95, 7.0}, {1.95, 2.0}}, 10.0, path);
  truth.erase(std::find_if(truth.begin(), truth.end(), [](const TimedPose& tp) { return tp.stamp > 30.0; }), truth.end());
  ASSERT_GE(truth.size(), 300u);
  LaserOdometryConfig along;
  along.align_to_walls = false;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    int released = 0;
    loopBuildingFinalError(truth, along, seed,
                           [&](const TimedPose&, const OdometryUpdate& u) { released += u.match.prior_released ? 1 : 0; });
    EXPECT_EQ(released, 0) << "seed " << seed;
    LaserOdometryConfig no_release;
    no_release.prior_release_speed = 0.0;
    const double with = loopBuildingFinalError(truth, LaserOdometryConfig(), seed),
                 without = loopBuildingFinalError(truth, no_release, seed);
    EXPECT_LE(with, without + 0.01) << "seed " << seed;
  }
}

TEST(LaserOdometry, PoseCovarianceDoesNotGrowWhileStandingStill) {
  // Every scan is matched against the local map, not the previous scan: a robot standing in the furnished
  // room for a minute is no less sure where it is than after its first second (summed per scan, the pose
  // σ grew with the square root of the scan count: ×5.6 from 1 s to 60 s here).
  static const FloorPlan room = test::furnishedRoom();
  ScanSimulator sim(room, ScanSimulatorConfig(), 5);
  const Pose2D still(3.0, 3.0, 0.3);
  LaserOdometry odom;
  Eigen::Matrix3d after_1s = Eigen::Matrix3d::Zero(), after_60s = Eigen::Matrix3d::Zero();
  for (int i = 0; i <= 600; ++i) {
    const OdometryUpdate u = odom.process(preprocessScan(sim.simulate(still, 100.0 + 0.1 * i), ScanPreprocessorConfig()),
                                          LaserMount());
    ASSERT_TRUE(u.ok) << i;
    if (i == 10) after_1s = u.pose_covariance;
    if (i == 600) after_60s = u.pose_covariance;
  }
  ASSERT_GT(after_1s.trace(), 0.0);
  for (int k = 0; k < 3; ++k) EXPECT_LT(after_60s(k, k), 2.0 * after_1s(k, k)) << "axis " << k;
}

TEST(LaserOdometry, PoseCovarianceCoversTheErrorWithoutOverstatingIt) {
  // Along the simulated room loop the true error should mostly lie within the pose's σ (z = e/σ: no
  // more than a few beyond 3σ) while σ stays of the error's order: rms z over x, y, θ 0.43, 0.34, 0.79
  // (summing every scan's match instead: 0.15, 0.12, 0.27, i.e. σ three to eight times the error).
  const SimRun run = simulateLoop(1);
  LaserOdometry odom;
  const Pose2D start = run.truth.front().pose;
  double z2[3] = {0, 0, 0};
  int beyond3 = 0, n = 0;
  for (std::size_t i = 0; i < run.scans.size(); ++i) {
    const OdometryUpdate u = odom.process(preprocessScan(run.scans[i], ScanPreprocessorConfig()), LaserMount());
    ASSERT_TRUE(u.ok) << i;
    if (i < 10) continue;
    const Pose2D truth = between(start, run.truth[i].pose);
    const double e[3] = {u.pose.x - truth.x, u.pose.y - truth.y, normalizeAngle(u.pose.theta - truth.theta)};
    for (int k = 0; k < 3; ++k) {
      const double z = e[k] * e[k] / u.pose_covariance(k, k);
      z2[k] += z;
      beyond3 += z > 9.0 ? 1 : 0;
    }
    ++n;
  }
  ASSERT_GT(n, 100);
  EXPECT_LT(beyond3, 0.01 * 3 * n);
  double mean_rms_z = 0.0;
  for (int k = 0; k < 3; ++k) mean_rms_z += std::sqrt(z2[k] / n) / 3.0;
  EXPECT_GT(mean_rms_z, 0.4);
}

namespace {

// Wheel odometry integrated from the true motion with every translation scaled by `scale` (an encoder
// scale error common to both wheels), sampled at the truth's stamps.
std::vector<Pose2D> scaledWheelPoses(const std::vector<TimedPose>& truth, double scale) {
  std::vector<Pose2D> wheels{Pose2D()};
  for (std::size_t i = 1; i < truth.size(); ++i) {
    const Pose2D d = between(truth[i - 1].pose, truth[i].pose);
    wheels.push_back(wheels.back() * Pose2D(scale * d.x, scale * d.y, d.theta));
  }
  return wheels;
}

// Runs the odometry over `truth` in `plan` with wheel odometry of the given scale (≤ 0: none); returns the
// final along-/across-track errors as the final position error. `observe` sees each true pose and update.
double runWithWheels(const FloorPlan& plan, const std::vector<TimedPose>& truth, double wheel_scale,
                     std::uint64_t seed, const UpdateObserver& observe = nullptr) {
  ScanSimulator sim(plan, ScanSimulatorConfig(), seed);
  LaserOdometry odom;
  const std::vector<Pose2D> wheels = scaledWheelPoses(truth, wheel_scale);
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const double stamp = 100.0 + truth[i].stamp;
    if (wheel_scale > 0.0) odom.addWheelOdometry(stamp, wheels[i]);
    const OdometryUpdate u =
        odom.process(preprocessScan(sim.simulate(truth[i].pose, stamp), ScanPreprocessorConfig()), LaserMount());
    if (observe) observe(truth[i], u);
  }
  const Pose2D end = between(truth.front().pose, truth.back().pose);
  return std::hypot(odom.pose().x - end.x, odom.pose().y - end.y);
}

// A corridor 2.5 m wide and 50 m long, closed at both ends, with two boxes on its walls within 3 m of each
// end: between x ≈ 9 and 41 m nothing along it is within the URG-04LX's 5.6 m.
const FloorPlan& blankCorridor() {
  static const FloorPlan plan = test::planFromBoxes(
      50.0, 2.5, 0.05,
      {{0.0, 0.0, 50.0, 0.1}, {0.0, 2.4, 50.0, 2.5}, {0.0, 0.0, 0.1, 2.5}, {49.9, 0.0, 50.0, 2.5},
       {2.5, 0.1, 2.9, 0.5}, {3.5, 2.0, 3.8, 2.4}, {46.2, 0.1, 46.5, 0.5}, {47.1, 2.0, 47.5, 2.4}});
  return plan;
}

// A corridor 2.5 m wide and 72 m long, closed at both ends, with boxes on both walls every 1.5 m over its
// first and last 10 m: a robot driving its middle passes the first boxes at cruise speed, and between
// x ≈ 15.6 and 56.4 m nothing that faces along the corridor is within the URG-04LX's 5.6 m ahead.
const FloorPlan& longBlankCorridor() {
  static const FloorPlan plan = [] {
    std::vector<test::Box> boxes{{0.0, 0.0, 72.0, 0.1}, {0.0, 2.4, 72.0, 2.5}, {0.0, 0.0, 0.1, 2.5}, {71.9, 0.0, 72.0, 2.5}};
    for (double x = 1.0; x <= 10.0; x += 1.5) {
      boxes.push_back({x, 0.1, x + 0.3, 0.5});
      boxes.push_back({x + 0.7, 2.0, x + 1.0, 2.4});
    }
    for (double x = 62.0; x <= 70.0; x += 1.5) {
      boxes.push_back({x, 0.1, x + 0.3, 0.5});
      boxes.push_back({x + 0.7, 2.0, x + 1.0, 2.4});
    }
    return test::planFromBoxes(72.0, 2.5, 0.05, boxes);
  }();
  return plan;
}

}  // namespace

// A 40.8 m blank corridor at 0.3 m/s, laser only, entered at speed: the along-track error gained between
// x = 15.6 and 56.4 m stays within 1 % of that length, and the pose's 3σ covers the error at every scan.
// Three placements of the path a few millimetres apart and two simulator seeds: which matches come out
// degenerate near the stretch's ends depends on both, and one placement alone passes or fails by its luck
// (doc/experiments.md, "The held speed fitted to the matches that measured it").
TEST(LaserOdometry, HeldSpeedCarriesAFortyMetreBlankCorridorWithinOnePercent) {
  for (const double shift : {0.0, 0.013, 0.031}) {
    const std::vector<TimedPose> truth =
        samplePath({{3.0 + shift, 1.25 + shift}, {69.0 + shift, 1.25 + shift}}, 10.0, PathConfig());
    for (std::uint64_t seed = 1; seed <= 2; ++seed) {
      double enter = std::numeric_limits<double>::quiet_NaN(), leave = enter;
      int uncovered = 0;
      runWithWheels(longBlankCorridor(), truth, 0.0, seed, [&](const TimedPose& tp, const OdometryUpdate& u) {
        const double error = u.pose.x - (tp.pose.x - truth.front().pose.x);
        if (std::isnan(enter) && tp.pose.x >= 15.6 + shift) enter = error;
        if (std::isnan(leave) && tp.pose.x >= 56.4 + shift) leave = error;
        uncovered += std::abs(error) <= 3.0 * std::sqrt(u.pose_covariance(0, 0)) ? 0 : 1;
      });
      const std::string at = "shift " + std::to_string(shift) + " seed " + std::to_string(seed);
      EXPECT_LE(std::abs(leave - enter), 0.01 * 40.8) << at;
      EXPECT_EQ(uncovered, 0) << at;
      RecordProperty("shift" + std::to_string(static_cast<int>(1000 * shift)) + "_seed" + std::to_string(seed) +
                         "_blank_drift_mm",
                     static_cast<int>(1000.0 * std::abs(leave - enter)));
    }
  }
}

// Where the scan constrains the motion the laser decides: wheels reporting 10 % more distance than was
// driven move the final estimate of the furnished-room loop (every scan constrained) by under 1 % of the
// path, and its error stays within 1 % of the path.
TEST(LaserOdometry, WheelScaleErrorDoesNotPullAConstrainedMatch) {
  static const FloorPlan room = test::furnishedRoom();
  const std::vector<TimedPose> truth =
      samplePath({{1.5, 2.5}, {3.2, 3.0}, {6.5, 2.0}, {7.0, 5.0}, {4.5, 5.0}, {1.5, 3.5}, {1.5, 2.5}}, 10.0, PathConfig());
  double travelled = 0.0;
  for (std::size_t i = 1; i < truth.size(); ++i) {
    travelled += std::hypot(truth[i].pose.x - truth[i - 1].pose.x, truth[i].pose.y - truth[i - 1].pose.y);
  }
  ASSERT_GT(travelled, 15.0);
  for (std::uint64_t seed = 1; seed <= 2; ++seed) {
    std::vector<Pose2D> without, with;
    int wheel_priors = 0;
    const double e_without = runWithWheels(room, truth, 0.0, seed, [&](const TimedPose&, const OdometryUpdate& u) {
      without.push_back(u.pose);
    });
    const double e_with = runWithWheels(room, truth, 1.10, seed, [&](const TimedPose&, const OdometryUpdate& u) {
      with.push_back(u.pose);
      wheel_priors += u.wheel_prior ? 1 : 0;
    });
    EXPECT_GT(wheel_priors, static_cast<int>(truth.size()) - 3) << "seed " << seed;
    EXPECT_LT(std::hypot(with.back().x - without.back().x, with.back().y - without.back().y), 0.01 * travelled)
        << "seed " << seed;
    EXPECT_LT(e_with, 0.01 * travelled) << "seed " << seed << " (without wheels " << e_without << " m)";
    RecordProperty("seed" + std::to_string(seed) + "_mm",
                   std::to_string(static_cast<int>(1000.0 * e_without)) + " -> " + std::to_string(static_cast<int>(1000.0 * e_with)));
  }
}

// Where the laser sees nothing along a corridor the wheels carry the estimate: 44 m through the blank
// corridor at 0.3 m/s with a 10 s stop in its middle, wheels 0.5 % long. The laser alone cannot tell the stop
// from driving on (the estimate falls 31–34 m behind, seeds 1–2); with the wheels the along-track error stays
// within the wheels' own 0.5 % (plus 5 cm) at every scan (0.20, 0.22 m worst). The delta's covariance (what
// the SLAM's proposal samples) never says more than the wheels' error on any axis, down the corridor too.
TEST(LaserOdometry, WheelsCarryTheEstimateThroughABlankCorridorWithAStop) {
  std::vector<Waypoint> waypoints = toWaypoints({{3.0, 1.25}, {25.0, 1.25}, {47.0, 1.25}});
  waypoints[1].pause = 10.0;
  const std::vector<TimedPose> truth = samplePath(waypoints, 10.0, PathConfig());
  const double bound = 0.005 * 44.0 + 0.05;
  for (std::uint64_t seed = 1; seed <= 2; ++seed) {
    double worst = 0.0, last = 0.0;
    int above_wheels = 0;
    runWithWheels(blankCorridor(), truth, 1.005, seed, [&](const TimedPose& tp, const OdometryUpdate& u) {
      last = u.pose.x - (tp.pose.x - truth.front().pose.x);  // the odometry starts at the first true pose
      worst = std::max(worst, std::abs(last));
      if (!u.wheel_prior) return;
      const Eigen::Vector3d w = wheelMotionSigma(u.delta);
      for (int k = 0; k < 3; ++k) above_wheels += u.delta_covariance(k, k) > 1.000001 * w(k) * w(k) ? 1 : 0;
    });
    EXPECT_LT(worst, bound) << "seed " << seed;
    EXPECT_EQ(above_wheels, 0) << "seed " << seed;
    RecordProperty("seed" + std::to_string(seed) + "_worst_mm", static_cast<int>(1000.0 * worst));
  }
}

// The skip reasons keep the words the logs, the match log and stats.json have always used.
TEST(LaserOdometry, SkipReasonsPrintAsTheirLogWords) {
  EXPECT_STREQ(toString(OdometrySkipReason::kNone), "");
  EXPECT_STREQ(toString(OdometrySkipReason::kTooFewPoints), "too_few_points");
  EXPECT_STREQ(toString(OdometrySkipReason::kMalformedScan), "malformed_scan");
  EXPECT_STREQ(toString(OdometrySkipReason::kTimeBackwards), "time_backwards");
  EXPECT_STREQ(toString(OdometrySkipReason::kDuplicateStamp), "duplicate_stamp");
  EXPECT_STREQ(toString(OdometrySkipReason::kMatchFailed), "match_failed");
  EXPECT_EQ(OdometryUpdate().skip_reason, OdometrySkipReason::kNone);
}

// Laser only, from rest 1 m before the blank corridor (32 m of it with nothing along it in range) and then
// at a constant 0.3 m/s: the velocity of the first metre is kept for as long as nothing contradicts it, so the
// estimate keeps moving: worst along-track error 0.64 / 0.24 m (seeds 1 / 2) where a 10 s hold ended 31-34 m
// behind. The robot reaches its speed within the first 0.1 m, but the boxes there are seen obliquely and the
// matches turn degenerate while the smoothed velocity still lags the acceleration (0.21-0.22 m/s for 0.30 where traced): no
// constant-speed window of constrained matches is there to fit, and a path a few millimetres to the side
// ends metres off (doc/experiments.md, "The held speed fitted to the matches that measured it"). The
// corridor entered at speed is HeldSpeedCarriesAFortyMetreBlankCorridorWithinOnePercent.
// The published pose covariance along the corridor grows with the time held, as a held velocity's error
// does (σ 1.49 / 1.47 m at the end, seeds 1 / 2), and its 3σ covers the along-track error at every held scan
// here (not at every scan: during the start from rest, before the hold, the error exceeds 3σ at one scan).
TEST(LaserOdometry, HoldKeepsTheLaserOnlyEstimateMovingThroughABlankCorridor) {
  const std::vector<TimedPose> truth = samplePath({{3.0, 1.25}, {47.0, 1.25}}, 10.0, PathConfig());
  for (std::uint64_t seed = 1; seed <= 2; ++seed) {
    double worst = 0.0, sigma = 0.0;
    int held = 0, held_uncovered = 0, uncovered = 0, held_for_slam = 0, held_elsewhere = 0;
    runWithWheels(blankCorridor(), truth, 0.0, seed, [&](const TimedPose& tp, const OdometryUpdate& u) {
      // The blank stretch's held speed goes to the SLAM (held_direction along the corridor), nothing else.
      if (u.velocity_held && u.velocity_held_blank) {
        held_for_slam += u.held_speed_sigma > 0.0 && std::abs(u.held_direction.x()) > 0.99 ? 1 : 0;
      } else {
        held_elsewhere += u.held_speed_sigma > 0.0 ? 1 : 0;
      }
      const double error = u.pose.x - (tp.pose.x - truth.front().pose.x);
      worst = std::max(worst, std::abs(error));
      sigma = std::sqrt(u.pose_covariance(0, 0));
      const bool covered = std::abs(error) <= 3.0 * sigma;
      uncovered += covered ? 0 : 1;
      held += u.velocity_held ? 1 : 0;
      held_uncovered += u.velocity_held && !covered ? 1 : 0;
    });
    EXPECT_LT(worst, 3.0) << "seed " << seed;
    EXPECT_GT(held, static_cast<int>(truth.size()) / 2) << "seed " << seed;
    EXPECT_EQ(held_uncovered, 0) << "seed " << seed;
    EXPECT_LE(uncovered, 2) << "seed " << seed;
    EXPECT_GT(held_for_slam, static_cast<int>(truth.size()) / 2) << "seed " << seed;
    EXPECT_EQ(held_elsewhere, 0) << "seed " << seed;
    RecordProperty("seed" + std::to_string(seed) + "_worst_mm", static_cast<int>(1000.0 * worst));
    RecordProperty("seed" + std::to_string(seed) + "_sigma_end_mm", static_cast<int>(1000.0 * sigma));
    RecordProperty("seed" + std::to_string(seed) + "_uncovered_scans", uncovered);
  }
}
