// Timed robot trajectories through waypoints at iRobot Create speeds, for the laser simulator. No ROS.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "laser_dpslam/common/pose2d.h"
#include "laser_dpslam/sim/floor_plan.h"

namespace laser_dpslam {

/// Motion limits. Defaults suit an iRobot Create (its firmware allows 0.5 m/s; people drive it slower).
struct PathConfig {
  double cruise_speed = 0.3;           ///< m/s, forward speed on straight segments
  double max_speed = 0.5;              ///< m/s, hard limit (cruise_speed must not exceed it)
  double turn_rate = 1.0;              ///< rad/s, turn-in-place rate
  double max_turn_rate = 1.5;          ///< rad/s, hard limit (turn_rate must not exceed it)
  double linear_acceleration = 0.5;    ///< m/s², trapezoidal speed profile on each segment
  double angular_acceleration = 2.0;   ///< rad/s², trapezoidal turn-rate profile on each turn
  double start_pause = 0.0;            ///< s standing still at the first waypoint before moving
  double end_pause = 0.0;              ///< s standing still at the last waypoint after arriving

  /// Throws std::invalid_argument on non-positive or inconsistent limits.
  void validate() const;
};

/// The robot's (base_link's) pose and velocity at one instant.
struct TimedPose {
  double stamp = 0.0;  ///< s from the start of the path
  Pose2D pose;         ///< map-frame pose of base_link
  double v = 0.0;      ///< m/s, forward speed (base_link x)
  double w = 0.0;      ///< rad/s, turn rate (counter-clockwise positive)
};

/// A waypoint with what the robot does there. pause: seconds standing still after arriving (at the first
/// waypoint: before leaving it; after start_pause); speed: cruise speed [m/s] of the segment that leaves
/// it, 0 for PathConfig::cruise_speed. A waypoint on a straight line between its neighbours makes the robot
/// stop there (and go on without turning): that is how a stop or a speed change inside a corridor is written.
struct Waypoint {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double pause = 0.0;  ///< s, >= 0
  double speed = 0.0;  ///< m/s; 0: the config's cruise_speed; else in (0, max_speed]
};

/// Waypoints with no pause at the default speed.
std::vector<Waypoint> toWaypoints(const std::vector<Eigen::Vector2d>& positions);
/// The positions of the waypoints.
std::vector<Eigen::Vector2d> positionsOf(const std::vector<Waypoint>& waypoints);

/// Drives the waypoints (map frame, metres) in order: the robot starts at the first facing the second,
/// and at each waypoint it stops and turns in place towards the next one (no turn after the last).
/// Straight segments and turns use trapezoidal profiles (accelerate, cruise, decelerate to a stop).
/// Consecutive duplicate waypoints are skipped. Samples at stamps k / rate_hz, k = 0, 1, …, up to and
/// including the first sample at or after arrival (clamped to the final pose, so the last sample is
/// exactly the last waypoint, standing still).
/// Throws std::invalid_argument with fewer than two distinct waypoints or rate_hz ≤ 0.
std::vector<TimedPose> samplePath(const std::vector<Eigen::Vector2d>& waypoints, double rate_hz,
                                  const PathConfig& config = PathConfig());
/// As above, with a pause and a speed per waypoint (see Waypoint). Consecutive duplicates are merged
/// (their pauses add up, the last one's speed applies). Throws std::invalid_argument also for a negative
/// or non-finite pause or a speed above config.max_speed.
std::vector<TimedPose> samplePath(const std::vector<Waypoint>& waypoints, double rate_hz,
                                  const PathConfig& config = PathConfig());

/// Total duration [s] of the path samplePath() would drive (from the start to arrival).
double pathDuration(const std::vector<Eigen::Vector2d>& waypoints, const PathConfig& config = PathConfig());
double pathDuration(const std::vector<Waypoint>& waypoints, const PathConfig& config = PathConfig());

/// Reads a waypoint file: one `x y` per line (metres), `#` starts a comment, blank lines ignored.
/// Throws std::runtime_error naming the file (and the line number for a malformed line), or when the
/// file is missing or holds fewer than two waypoints.
std::vector<Eigen::Vector2d> loadWaypoints(const std::string& path);

/// Reads a waypoint file whose lines are `x y [pause_s [speed_mps]]` (see Waypoint; `x y` lines get no
/// pause and the default speed). Same comments, errors and minimum as loadWaypoints(), and a line's pause
/// must be >= 0 and its speed > 0 (or 0 for the default).
std::vector<Waypoint> loadTimedWaypoints(const std::string& path);

/// Whether the path ends where it starts (within `tolerance` metres).
bool isClosedLoop(const std::vector<Eigen::Vector2d>& waypoints, double tolerance = 1e-3);

/// `laps` times around a loop: the waypoints repeated, closing the loop first if it is open.
std::vector<Eigen::Vector2d> repeatLoop(const std::vector<Eigen::Vector2d>& loop, int laps);
/// As above; the closing waypoint (added when the loop is open) is a copy of the first, pause and speed.
std::vector<Waypoint> repeatLoop(const std::vector<Waypoint>& loop, int laps);

/// The built-in paths of a floor plan: `PLAN_DIR/<stem>_<name>.txt` next to PLAN.yaml (e.g.
/// plans/office.yaml, "loop" → plans/office_loop.txt). Returns the path; does not check it exists.
std::string builtinPathFile(const std::string& plan_yaml, const std::string& name);

/// Checks that the robot (a disc of `robot_radius` metres) can drive the waypoints on the plan: every
/// point along every segment has at least that much clearance from occupied cells. Returns an empty
/// string when it can, else a message naming the first offending segment and point.
std::string checkPathClearance(const FloorPlan& plan, const std::vector<Eigen::Vector2d>& waypoints,
                               double robot_radius);
/// As above, for any plan: `clearance(p, max_radius)` is the distance from p to the nearest obstacle,
/// searched up to max_radius; `step` [m] is the spacing of the points checked along each segment.
std::string checkPathClearance(const std::function<double(const Eigen::Vector2d&, double)>& clearance,
                               double step, const std::vector<Eigen::Vector2d>& waypoints, double robot_radius);

}  // namespace laser_dpslam
