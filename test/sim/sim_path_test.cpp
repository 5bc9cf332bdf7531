#include "laser_dpslam/sim/sim_path.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace laser_dpslam {
namespace {

namespace fs = std::filesystem;

const std::vector<Eigen::Vector2d> kWaypoints = {
    {1.0, 1.0}, {4.0, 1.0}, {4.0, 3.5}, {4.05, 3.5}, {1.0, 3.0}, {2.0, 2.0}, {1.0, 1.0}};

TEST(SimPath, NeverExceedsSpeedAndTurnRateLimits) {
  PathConfig config;
  const double rate = 50.0;
  const std::vector<TimedPose> path = samplePath(kWaypoints, rate, config);
  ASSERT_GT(path.size(), 100u);
  double max_v = 0.0, max_w = 0.0;
  for (std::size_t k = 0; k < path.size(); ++k) {
    const TimedPose& p = path[k];
    EXPECT_NEAR(p.stamp, k / rate, 1e-9);
    EXPECT_GE(p.v, 0.0);
    EXPECT_LE(p.v, config.cruise_speed + 1e-9);
    EXPECT_LE(std::abs(p.w), config.turn_rate + 1e-9);
    EXPECT_TRUE(p.v == 0.0 || p.w == 0.0) << "drives and turns at once at " << p.stamp;
    if (k == 0) continue;
    const TimedPose& q = path[k - 1];
    const double dt = p.stamp - q.stamp;
    const Eigen::Vector2d dp = p.pose.translation() - q.pose.translation();
    const double v = dp.norm() / dt;
    const double w = std::abs(normalizeAngle(p.pose.theta - q.pose.theta)) / dt;
    max_v = std::max(max_v, v);
    max_w = std::max(max_w, w);
    EXPECT_LE(v, config.max_speed) << "at " << p.stamp;
    EXPECT_LE(w, config.max_turn_rate) << "at " << p.stamp;
    EXPECT_LE(v, config.cruise_speed + 1e-6) << "at " << p.stamp;
    EXPECT_LE(w, config.turn_rate + 1e-6) << "at " << p.stamp;
    // Speed changes stay within the acceleration limits.
    EXPECT_LE(std::abs(p.v - q.v) / dt, config.linear_acceleration + 1e-6);
    EXPECT_LE(std::abs(p.w - q.w) / dt, config.angular_acceleration + 1e-6);
    // Non-holonomic: any translation is along the heading.
    if (dp.norm() > 1e-9) {
      // (Heading of whichever of the two samples is driving: the other may be finishing/starting a turn.)
      const double theta = p.v > 0.0 ? p.pose.theta : q.pose.theta;
      const Eigen::Vector2d heading(std::cos(theta), std::sin(theta));
      EXPECT_NEAR(heading.x() * dp.y() - heading.y() * dp.x(), 0.0, 1e-9) << "sideways at " << p.stamp;
      EXPECT_GT(dp.dot(heading), 0.0) << "backwards at " << p.stamp;
    }
  }
  // The long segments reach cruise speed; the turns reach the turn rate.
  EXPECT_GT(max_v, 0.95 * config.cruise_speed);
  EXPECT_GT(max_w, 0.9 * config.turn_rate);
}

TEST(SimPath, StartsAtFirstWaypointFacingTheSecondAndEndsAtTheLast) {
  const std::vector<TimedPose> path = samplePath(kWaypoints, 10.0);
  ASSERT_FALSE(path.empty());
  EXPECT_DOUBLE_EQ(path.front().stamp, 0.0);
  EXPECT_NEAR(path.front().pose.x, 1.0, 1e-12);
  EXPECT_NEAR(path.front().pose.y, 1.0, 1e-12);
  EXPECT_NEAR(path.front().pose.theta, 0.0, 1e-12);  // facing (4, 1)
  EXPECT_NEAR(path.back().pose.x, 1.0, 1e-9);
  EXPECT_NEAR(path.back().pose.y, 1.0, 1e-9);
  // Final heading: that of the last segment, from (2, 2) to (1, 1).
  EXPECT_NEAR(normalizeAngle(path.back().pose.theta - std::atan2(-1.0, -1.0)), 0.0, 1e-9);
  EXPECT_EQ(path.back().v, 0.0);
  EXPECT_EQ(path.back().w, 0.0);
  // Sampled up to the first stamp at or after arrival.
  const double duration = pathDuration(kWaypoints);
  EXPECT_GE(path.back().stamp, duration - 1e-9);
  EXPECT_LT(path[path.size() - 2].stamp, duration);

  const std::vector<Eigen::Vector2d> diagonal = {{0.0, 0.0}, {-1.0, 1.0}};
  const std::vector<TimedPose> d = samplePath(diagonal, 10.0);
  EXPECT_NEAR(d.front().pose.theta, 3.0 * M_PI / 4.0, 1e-12);
}

TEST(SimPath, PassesEveryWaypointAndTurnsInPlaceThere) {
  const std::vector<TimedPose> path = samplePath(kWaypoints, 100.0);
  std::size_t k = 0;
  for (std::size_t i = 0; i < kWaypoints.size(); ++i) {
    // In order: the first sample from k on that comes within 2 mm of waypoint i.
    bool found = false;
    for (; k < path.size(); ++k) {
      if ((path[k].pose.translation() - kWaypoints[i]).norm() < 2e-3) {
        found = true;
        break;
      }
    }
    EXPECT_TRUE(found) << "waypoint " << i << " never reached in order";
    if (!found) break;
    if (i == 0 || i + 1 == kWaypoints.size()) continue;
    // While at the waypoint, the robot turns to face the next one before leaving.
    const Eigen::Vector2d d = kWaypoints[i + 1] - kWaypoints[i];
    const double heading = std::atan2(d.y(), d.x());
    std::size_t leave = k;
    while (leave < path.size() && (path[leave].pose.translation() - kWaypoints[i]).norm() < 2e-3) ++leave;
    ASSERT_LT(leave, path.size());
    EXPECT_NEAR(normalizeAngle(path[leave].pose.theta - heading), 0.0, 1e-9) << "waypoint " << i;
  }
}

TEST(SimPath, CustomLimitsAndPauses) {
  PathConfig config;
  config.cruise_speed = 0.5;
  config.turn_rate = 1.5;
  config.start_pause = 1.0;
  config.end_pause = 2.0;
  const std::vector<TimedPose> path = samplePath(kWaypoints, 10.0, config);
  for (const TimedPose& p : path) {
    EXPECT_LE(p.v, 0.5 + 1e-9);
    EXPECT_LE(std::abs(p.w), 1.5 + 1e-9);
    if (p.stamp <= 1.0) {
      EXPECT_NEAR((p.pose.translation() - kWaypoints[0]).norm() + std::abs(p.pose.theta), 0.0, 1e-12);
    }
  }
  PathConfig no_pauses = config;
  no_pauses.start_pause = no_pauses.end_pause = 0.0;
  EXPECT_NEAR(pathDuration(kWaypoints, config), pathDuration(kWaypoints, no_pauses) + 3.0, 1e-9);
  EXPECT_LT(pathDuration(kWaypoints, no_pauses), pathDuration(kWaypoints));  // faster than the defaults
  config.cruise_speed = 0.6;  // above max_speed
  EXPECT_THROW(samplePath(kWaypoints, 10.0, config), std::invalid_argument);
}

TEST(SimPath, RejectsDegenerateInput) {
  EXPECT_THROW(samplePath({{1.0, 1.0}}, 10.0), std::invalid_argument);
  EXPECT_THROW(samplePath({{1.0, 1.0}, {1.0, 1.0}}, 10.0), std::invalid_argument);
  EXPECT_THROW(samplePath(kWaypoints, 0.0), std::invalid_argument);
}

TEST(SimPath, LoopsRepeat) {
  const std::vector<Eigen::Vector2d> open = {{0, 0}, {1, 0}, {1, 1}};
  EXPECT_FALSE(isClosedLoop(open));
  const auto twice = repeatLoop(open, 2);
  ASSERT_EQ(twice.size(), 7u);
  EXPECT_TRUE(isClosedLoop(twice));
  EXPECT_TRUE(twice[3].isApprox(Eigen::Vector2d(0, 0)));
  EXPECT_TRUE(twice[4].isApprox(Eigen::Vector2d(1, 0)));
  EXPECT_EQ(repeatLoop(twice, 1).size(), 7u);
  EXPECT_THROW(repeatLoop(open, 0), std::invalid_argument);
}

TEST(SimPath, WaypointFilesAndBuiltins) {
  std::string tmpl = (fs::temp_directory_path() / "sim_path_test_XXXXXX").string();
  ASSERT_NE(mkdtemp(tmpl.data()), nullptr);
  const fs::path dir(tmpl);
  {
    std::ofstream(dir / "ok.txt") << "# a comment\n1.5 -2\n\n  3 4e-1   # trailing\n-1 0\n";
    std::ofstream(dir / "bad.txt") << "1 2\n3 4\n5 six\n";
    std::ofstream(dir / "three.txt") << "1 2\n3 4 5\n";
  }
  const auto wps = loadWaypoints((dir / "ok.txt").string());
  ASSERT_EQ(wps.size(), 3u);
  EXPECT_TRUE(wps[1].isApprox(Eigen::Vector2d(3.0, 0.4)));
  try {
    loadWaypoints((dir / "bad.txt").string());
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.txt:3"), std::string::npos) << e.what();
  }
  try {
    loadWaypoints((dir / "three.txt").string());
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("three.txt:2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(loadWaypoints((dir / "missing.txt").string()), std::runtime_error);
  EXPECT_EQ(builtinPathFile("/a/plans/office.yaml", "loop"), "/a/plans/office_loop.txt");
  fs::remove_all(dir);
}

TEST(SimPath, ClearanceCheckFindsWalls) {
  // 2 m x 2 m of 0.1 m cells with a wall along x = 1.0 .. 1.1 for y < 1.5.
  std::vector<std::uint8_t> occ(400, 0);
  for (int iy = 0; iy < 15; ++iy) occ[iy * 20 + 10] = 1;
  const FloorPlan plan = FloorPlan::fromOccupancy(20, 20, 0.1, Eigen::Vector2d::Zero(), occ);
  EXPECT_EQ(checkPathClearance(plan, {{0.5, 1.8}, {1.5, 1.8}}, 0.2), "");
  EXPECT_NE(checkPathClearance(plan, {{0.5, 0.5}, {1.5, 0.5}}, 0.2), "");
  EXPECT_NE(checkPathClearance(plan, {{0.5, 1.8}, {1.5, 1.6}}, 0.2), "");
}

TEST(SimPath, WaypointPausesAndSegmentSpeeds) {
  // Straight east: a 2 s dwell at the start, 0.2 m/s to the middle, 3 s stop there (no turn), 0.4 m/s on.
  std::vector<Waypoint> wps(3);
  wps[0].position = {0.0, 0.0};
  wps[0].pause = 2.0;
  wps[0].speed = 0.2;
  wps[1].position = {3.0, 0.0};
  wps[1].pause = 3.0;
  wps[1].speed = 0.4;
  wps[2].position = {7.0, 0.0};
  const double rate = 50.0;
  const std::vector<TimedPose> path = samplePath(wps, rate);
  double max_v_first = 0.0, max_v_second = 0.0, still_at_middle = 0.0, still_at_start = 0.0;
  for (const TimedPose& p : path) {
    EXPECT_EQ(p.w, 0.0) << "turns at " << p.stamp;
    if (p.pose.x < 3.0 - 1e-9) max_v_first = std::max(max_v_first, p.v);
    if (p.pose.x > 3.0 + 1e-9) max_v_second = std::max(max_v_second, p.v);
    if (p.v == 0.0 && std::abs(p.pose.x - 3.0) < 1e-9) still_at_middle += 1.0 / rate;
    if (p.v == 0.0 && p.pose.x == 0.0) still_at_start += 1.0 / rate;
  }
  EXPECT_NEAR(max_v_first, 0.2, 1e-9);
  EXPECT_NEAR(max_v_second, 0.4, 1e-9);
  EXPECT_NEAR(still_at_middle, 3.0, 0.05);
  EXPECT_NEAR(still_at_start, 2.0, 0.05);
  // Accelerate / cruise / brake at 0.5 m/s² on each segment, plus the pauses.
  const double expected = 2.0 + (3.0 / 0.2 + 0.2 / 0.5) + 3.0 + (4.0 / 0.4 + 0.4 / 0.5);
  EXPECT_NEAR(pathDuration(wps), expected, 1e-9);
  EXPECT_NEAR(path.back().pose.x, 7.0, 1e-12);

  // Without pauses and speeds, the same path as the plain waypoints (byte-identical bags for old files).
  const std::vector<Eigen::Vector2d> plain = positionsOf(wps);
  const auto a = samplePath(plain, 10.0), b = samplePath(toWaypoints(plain), 10.0);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) EXPECT_EQ(a[k].pose.x, b[k].pose.x);

  wps[1].speed = 0.6;  // above PathConfig::max_speed
  EXPECT_THROW(samplePath(wps, rate), std::invalid_argument);
  wps[1].speed = 0.3;
  wps[1].pause = -1.0;
  EXPECT_THROW(samplePath(wps, rate), std::invalid_argument);
}

TEST(SimPath, TimedWaypointFiles) {
  const fs::path dir = fs::temp_directory_path() / "sim_path_timed_test";
  fs::create_directories(dir);
  std::ofstream(dir / "ok.txt") << "# x y pause speed\n0 0 1.5\n4 0 0 0.25  # stop\n4 3\n";
  std::ofstream(dir / "five.txt") << "0 0\n1 1 1 1 1\n";
  std::ofstream(dir / "negative.txt") << "0 0\n1 1 -2\n";
  const std::vector<Waypoint> wps = loadTimedWaypoints((dir / "ok.txt").string());
  ASSERT_EQ(wps.size(), 3u);
  EXPECT_EQ(wps[0].pause, 1.5);
  EXPECT_EQ(wps[0].speed, 0.0);
  EXPECT_EQ(wps[1].speed, 0.25);
  EXPECT_TRUE(wps[2].position.isApprox(Eigen::Vector2d(4.0, 3.0)));
  for (const char* bad : {"five.txt:2", "negative.txt:2"}) {
    const std::string file = std::string(bad).substr(0, std::string(bad).find(':'));
    try {
      loadTimedWaypoints((dir / file).string());
      ADD_FAILURE() << "no exception for " << file;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
  // The plain loader still takes `x y` only.
  EXPECT_THROW(loadWaypoints((dir / "ok.txt").string()), std::runtime_error);
  const std::vector<Waypoint> laps = repeatLoop(wps, 2);
  ASSERT_EQ(laps.size(), 7u);
  EXPECT_EQ(laps[3].pause, 1.5);  // the closing waypoint is the first, with its dwell
  fs::remove_all(dir);
}

}  // namespace
}  // namespace laser_dpslam
