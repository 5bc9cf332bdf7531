// simulate_scans: a Hokuyo URG-04LX on an iRobot Create driving through a floor plan, written to a bag.
//
//   simulate_scans --floorplan {PLAN.yaml,PLAN.txt} --path {loop,explore,WAYPOINTS.txt} --out DIR [--seed N]
//                  [--duration S] [--rate HZ] [--laps N] [--start-time S] [--laser-x M] [--laser-y M]
//                  [--laser-yaw RAD] [--dropout P] [--outliers P] [--range-noise M]
//                  [--range-noise-fraction F] [--no-noise] [--robot-radius M]
//                  [--wheel-odometry] [--wheel-rate HZ] [--wheel-scale-error E] [--wheel-slip S]
//
// Writes DIR/sim.bag (/scan, /tf_static, /ground_truth, with --wheel-odometry /wheel_odom) and
// DIR/ground_truth.tum. `--path loop` and
// `--path explore` are the waypoint files next to the plan: PLAN_DIR/<plan stem>_loop.txt and
// <plan stem>_explore.txt (e.g. plans/office.yaml → plans/office_loop.txt).
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include <boost/make_shared.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "laser_dpslam/ros/msg_conversion.h"
#include "laser_dpslam/sim/floor_plan.h"
#include "laser_dpslam/sim/scan_simulator.h"
#include "laser_dpslam/sim/sim_path.h"
#include "laser_dpslam/sim/vector_plan.h"
#include "laser_dpslam/sim/wheel_odometry_sim.h"

namespace fs = std::filesystem;
using namespace laser_dpslam;

namespace {

const char* kUsage =
    "usage: simulate_scans --floorplan {PLAN.yaml,PLAN.txt} --path {loop,explore,WAYPOINTS.txt} --out DIR\n"
    "                      [--seed N] [--duration S] [options]\n"
    "\n"
    "Simulates a Hokuyo URG-04LX (683 beams, 240 deg, 0.02-5.6 m, 10 Hz, datasheet noise, dropouts as NaN,\n"
    "no return as +inf) on an iRobot Create driving the waypoints through the floor plan: a map_server YAML\n"
    "(walls on its cell lattice) or a geometry plan PLAN.txt (walls, polygons and pillars at any angle, cast\n"
    "exactly; format in doc/simulation.md).\n"
    "Writes DIR/sim.bag (/scan sensor_msgs/LaserScan frame 'laser'; /tf_static base_link->laser;\n"
    "/ground_truth nav_msgs/Odometry map->base_link) and DIR/ground_truth.tum (true base_link pose at every\n"
    "scan stamp: 'stamp x y z qx qy qz qw').\n"
    "\n"
    "  --path loop|explore  the built-in paths of the plan: <plan dir>/<plan stem>_loop.txt / _explore.txt\n"
    "  --path FILE          waypoints, one 'x y [pause_s [speed_mps]]' per line (metres, map frame), '#'\n"
    "                       comments; the robot starts at rest at the first facing the second, stops and\n"
    "                       turns in place at each, stands still pause_s there (default 0) and drives the\n"
    "                       segment leaving it at speed_mps (default, or 0: 0.3 m/s; at most 0.5)\n"
    "  --seed N             random seed (default 1): same seed, same bag\n"
    "  --duration S         stop after S seconds; a closed loop is repeated as often as needed\n"
    "  --laps N             drive a closed loop N times (default 1)\n"
    "  --rate HZ            scan rate (default 10)\n"
    "  --start-time S       stamp of the first scan (default 1000.0; must be > 0)\n"
    "  --laser-x M, --laser-y M, --laser-yaw RAD\n"
    "                       laser pose on base_link (default 0.1 0 0)\n"
    "  --dropout P          per-beam dropout probability -> NaN (default 0.01)\n"
    "  --outliers P         per-beam probability of a spurious short return (default 0)\n"
    "  --range-noise M      range noise floor: sigma = max(M, F * range) (default 0.01)\n"
    "  --range-noise-fraction F\n"
    "                       range noise per metre of range (default 0.01, the datasheet's 1 %)\n"
    "  --no-noise           exact ranges: no range noise, dropouts or outliers\n"
    "  --robot-radius M     refuse paths closer than M to a wall (default 0.17, the Create's radius; 0: off)\n"
    "  --wheel-odometry     also write Create-like wheel odometry: /wheel_odom nav_msgs/Odometry, frame 'odom'\n"
    "                       (the first true pose) -> 'base_link' (no TF: the laser odometry owns it), pose\n"
    "                       integrated from noisy left/right wheel travel (wheel base 0.258 m), twist in the\n"
    "                       robot frame. Each wheel's travel is scaled by 1 + e, e drawn once per run uniform\n"
    "                       in [-E, E] per wheel, plus slip noise S * sqrt(travel) * N(0,1) per step. Its own\n"
    "                       random stream: the scans are the same with and without it\n"
    "  --wheel-rate HZ      wheel odometry rate (default 20)\n"
    "  --wheel-scale-error E  per-wheel scale error bound (default 0.01: 1 %)\n"
    "  --wheel-slip S       slip noise in m per sqrt(m) of wheel travel (default 0.002)\n";

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

double parseDouble(const std::string& flag, const std::string& value) {
  char* end = nullptr;
  const double v = std::strtod(value.c_str(), &end);
  if (value.empty() || *end != '\0' || !std::isfinite(v)) throw UsageError(flag + ": '" + value + "' is not a number");
  return v;
}

long long parseInt(const std::string& flag, const std::string& value) {
  char* end = nullptr;
  const long long v = std::strtoll(value.c_str(), &end, 10);
  if (value.empty() || *end != '\0') throw UsageError(flag + ": '" + value + "' is not an integer");
  return v;
}

struct Options {
  std::string floorplan, path, out;
  std::uint64_t seed = 1;
  double duration = 0.0;  // 0: the whole path
  int laps = 1;
  double rate = 10.0;
  double start_time = 1000.0;
  Pose2D laser_mount{0.1, 0.0, 0.0};
  double dropout = 0.01;
  double outliers = 0.0;
  double range_noise = ScanSimulatorConfig().noise_min_stddev;  // the datasheet's, as the simulator's defaults
  double range_noise_fraction = ScanSimulatorConfig().noise_range_fraction;
  bool no_noise = false;
  double robot_radius = 0.17;
  bool wheel_odometry = false;
  double wheel_rate = 20.0;
  WheelOdometryConfig wheels;
};

/// The wheel odometry's options with a value; false when `flag` is not one of them.
bool parseWheelFlag(const std::string& flag, const std::string& value, Options* o) {
  if (flag == "--wheel-rate") {
    o->wheel_rate = parseDouble(flag, value);
    if (!(o->wheel_rate > 0.0 && o->wheel_rate <= 1000.0)) throw UsageError("--wheel-rate must be in (0, 1000] Hz");
  } else if (flag == "--wheel-scale-error") {
    o->wheels.scale_error = parseDouble(flag, value);
    if (!(o->wheels.scale_error >= 0.0 && o->wheels.scale_error < 0.5))
      throw UsageError("--wheel-scale-error must be in [0, 0.5)");
  } else if (flag == "--wheel-slip") {
    o->wheels.slip = parseDouble(flag, value);
    if (!(o->wheels.slip >= 0.0)) throw UsageError("--wheel-slip must be >= 0");
  } else {
    return false;
  }
  return true;
}

Options parseArgs(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "-h" || flag == "--help") {
      std::cout << kUsage;
      std::exit(0);
    }
    if (flag == "--no-noise") {
      o.no_noise = true;
      continue;
    }
    if (flag == "--wheel-odometry") {
      o.wheel_odometry = true;
      continue;
    }
    if (flag.rfind("--", 0) != 0) throw UsageError("unexpected argument '" + flag + "'");
    if (i + 1 >= argc) throw UsageError(flag + " needs a value");
    const std::string value = argv[++i];
    if (flag == "--floorplan") {
      o.floorplan = value;
    } else if (flag == "--path") {
      o.path = value;
    } else if (flag == "--out") {
      o.out = value;
    } else if (flag == "--seed") {
      const long long s = parseInt(flag, value);
      if (s < 0) throw UsageError("--seed must be >= 0");
      o.seed = static_cast<std::uint64_t>(s);
    } else if (flag == "--duration") {
      o.duration = parseDouble(flag, value);
      if (!(o.duration > 0.0)) throw UsageError("--duration must be positive");
    } else if (flag == "--laps") {
      const long long n = parseInt(flag, value);
      if (n < 1 || n > 10000) throw UsageError("--laps must be between 1 and 10000");
      o.laps = static_cast<int>(n);
    } else if (flag == "--rate") {
      o.rate = parseDouble(flag, value);
      if (!(o.rate > 0.0 && o.rate <= 1000.0)) throw UsageError("--rate must be in (0, 1000] Hz");
    } else if (flag == "--start-time") {
      o.start_time = parseDouble(flag, value);
      if (!(o.start_time > 0.0 && o.start_time < 4e9)) throw UsageError("--start-time must be in (0, 4e9) s");
    } else if (flag == "--laser-x") {
      o.laser_mount.x = parseDouble(flag, value);
    } else if (flag == "--laser-y") {
      o.laser_mount.y = parseDouble(flag, value);
    } else if (flag == "--laser-yaw") {
      o.laser_mount.theta = normalizeAngle(parseDouble(flag, value));
    } else if (flag == "--dropout") {
      o.dropout = parseDouble(flag, value);
      if (!(o.dropout >= 0.0 && o.dropout <= 1.0)) throw UsageError("--dropout must be in [0, 1]");
    } else if (flag == "--range-noise") {
      o.range_noise = parseDouble(flag, value);
      if (!(o.range_noise >= 0.0)) throw UsageError("--range-noise must be >= 0");
    } else if (flag == "--range-noise-fraction") {
      o.range_noise_fraction = parseDouble(flag, value);
      if (!(o.range_noise_fraction >= 0.0)) throw UsageError("--range-noise-fraction must be >= 0");
    } else if (flag == "--outliers") {
      o.outliers = parseDouble(flag, value);
      if (!(o.outliers >= 0.0 && o.outliers <= 1.0)) throw UsageError("--outliers must be in [0, 1]");
    } else if (flag == "--robot-radius") {
      o.robot_radius = parseDouble(flag, value);
      if (!(o.robot_radius >= 0.0)) throw UsageError("--robot-radius must be >= 0");
    } else if (!parseWheelFlag(flag, value, &o)) {
      throw UsageError("unknown option '" + flag + "'");
    }
  }
  if (o.floorplan.empty()) throw UsageError("--floorplan is required");
  if (o.path.empty()) throw UsageError("--path is required");
  if (o.out.empty()) throw UsageError("--out is required");
  return o;
}

std::vector<Waypoint> resolveWaypoints(const Options& o) {
  if (o.path == "loop" || o.path == "explore") {
    const std::string file = builtinPathFile(o.floorplan, o.path);
    if (!fs::exists(file)) {
      throw std::runtime_error("floor plan " + o.floorplan + " has no built-in '" + o.path + "' path (expected " +
                               file + "); pass a waypoint file with --path FILE");
    }
    return loadTimedWaypoints(file);
  }
  return loadTimedWaypoints(o.path);
}

boost::shared_ptr<ros::M_string> latchedHeader(const tf2_msgs::TFMessage& msg) {
  auto h = boost::make_shared<ros::M_string>();
  (*h)["type"] = ros::message_traits::datatype(msg);
  (*h)["md5sum"] = ros::message_traits::md5sum(msg);
  (*h)["message_definition"] = ros::message_traits::definition(msg);
  (*h)["callerid"] = "/simulate_scans";
  (*h)["latching"] = "1";
  return h;
}

/// The plan: a map_server raster (.yaml/.yml) or a geometry plan (any other file).
struct Plan {
  std::optional<FloorPlan> grid;
  std::optional<VectorPlan> geometry;

  explicit Plan(const std::string& file) {
    const std::string ext = fs::path(file).extension().string();
    if (ext == ".yaml" || ext == ".yml") {
      grid = FloorPlan::load(file);
    } else {
      geometry = VectorPlan::load(file);
    }
  }
  std::string checkClearance(const std::vector<Eigen::Vector2d>& waypoints, double radius) const {
    if (grid) return checkPathClearance(*grid, waypoints, radius);
    const VectorPlan& g = *geometry;
    return checkPathClearance([&g](const Eigen::Vector2d& p, double r) { return g.clearance(p, r); }, 0.01, waypoints,
                              radius);
  }
};

/// The waypoints as driven (laps, repeats for --duration), checked against the plan.
std::vector<Waypoint> planWaypoints(const Options& o, const Plan& plan, const PathConfig& path_config) {
  std::vector<Waypoint> waypoints = resolveWaypoints(o);
  const bool closed = isClosedLoop(positionsOf(waypoints));
  if (o.laps > 1) {
    if (!closed) std::cerr << "simulate_scans: warning: the path is not a closed loop; --laps closes it\n";
    waypoints = repeatLoop(waypoints, o.laps);
  }
  if (o.robot_radius > 0.0) {
    const std::string problem = plan.checkClearance(positionsOf(waypoints), o.robot_radius);
    if (!problem.empty()) throw std::runtime_error(o.path + ": " + problem);
  }
  if (o.duration > 0.0 && closed) {
    // Repeat the loop until it lasts at least --duration.
    const std::vector<Waypoint> one = waypoints;
    int laps = 1;
    while (pathDuration(waypoints, path_config) < o.duration && laps < 10000) waypoints = repeatLoop(one, ++laps);
  }
  return waypoints;
}

/// The path sampled at `rate`, cut at --duration.
std::vector<TimedPose> sampleCut(const std::vector<Waypoint>& waypoints, double rate, const Options& o,
                                 const PathConfig& path_config, bool warn) {
  std::vector<TimedPose> path = samplePath(waypoints, rate, path_config);
  if (o.duration > 0.0) {
    const double last = path.back().stamp;
    if (warn && last < o.duration) {
      std::cerr << "simulate_scans: warning: the path ends after " << last << " s, before --duration " << o.duration
                << " s (it is not a closed loop, so it is not repeated)\n";
    }
    while (!path.empty() && path.back().stamp > o.duration + 1e-9) path.pop_back();
  }
  return path;
}

ScanSimulatorConfig sensorConfig(const Options& o) {
  ScanSimulatorConfig sensor;
  sensor.scan_rate = o.rate;
  sensor.dropout_probability = o.dropout;
  sensor.outlier_probability = o.outliers;
  sensor.noise_min_stddev = o.range_noise;
  sensor.noise_range_fraction = o.range_noise_fraction;
  if (o.no_noise) {
    sensor.noise_min_stddev = 0.0;
    sensor.noise_range_fraction = 0.0;
    sensor.dropout_probability = 0.0;
    sensor.grazing_dropout_probability = 0.0;
    sensor.outlier_probability = 0.0;
  }
  return sensor;
}

/// /wheel_odom at --wheel-rate along the same path, stamped on the scans' clock, up to the last scan.
void writeWheelOdometry(rosbag::Bag& bag, const Options& o, const std::vector<Waypoint>& waypoints,
                        const PathConfig& path_config, double last_scan) {
  const std::vector<TimedPose> path = sampleCut(waypoints, o.wheel_rate, o, path_config, false);
  // A stream of its own, derived from the seed, so that the scans do not change with the option.
  WheelOdometrySimulator wheels(o.wheels, o.seed * 0x9E3779B97F4A7C15ULL + 0x5EED);
  std::printf("simulate_scans: wheel odometry scale errors: left %+.3f %%, right %+.3f %%\n",
              100.0 * (wheels.leftScale() - 1.0), 100.0 * (wheels.rightScale() - 1.0));
  std::uint32_t seq = 0;
  for (const TimedPose& tp : path) {
    if (tp.stamp > last_scan + 1e-9) break;
    const WheelOdometryReading r = wheels.step(tp);
    ros::Time t;
    t.fromSec(o.start_time + tp.stamp);
    nav_msgs::Odometry msg;
    msg.header.stamp = t;
    msg.header.seq = seq++;
    msg.header.frame_id = "odom";
    msg.child_frame_id = "base_link";
    msg.pose.pose = toPoseMsg(r.pose);
    msg.twist.twist.linear.x = r.v;
    msg.twist.twist.angular.z = r.w;
    // Variances: x, y and yaw grow with the distance driven (scale error and slip); z, roll and pitch
    // are not measured (large, as drivers of planar robots publish them).
    const double e = o.wheels.scale_error, slip2 = o.wheels.slip * o.wheels.slip, b = o.wheels.wheel_base;
    const double var_xy = std::pow(e * r.distance, 2) + slip2 * r.distance + 1e-6;
    const double var_yaw = 2.0 * (std::pow(e * r.distance, 2) + slip2 * r.distance) / (b * b) + 1e-6;
    for (int i : {14, 21, 28}) msg.pose.covariance[i] = msg.twist.covariance[i] = 1e6;
    msg.pose.covariance[0] = msg.pose.covariance[7] = var_xy;
    msg.pose.covariance[35] = var_yaw;
    const double dt = 1.0 / o.wheel_rate;
    msg.twist.covariance[0] = msg.twist.covariance[7] = slip2 * 0.5 / dt + std::pow(e * r.v, 2) + 1e-6;
    msg.twist.covariance[35] = 2.0 * (slip2 * 0.5 / dt + std::pow(e * r.v, 2)) / (b * b) + 1e-6;
    bag.write("/wheel_odom", t, msg);
  }
}

int run(const Options& o) {
  const Plan plan(o.floorplan);
  const PathConfig path_config;
  const std::vector<Waypoint> waypoints = planWaypoints(o, plan, path_config);
  const std::vector<TimedPose> path = sampleCut(waypoints, o.rate, o, path_config, true);

  const ScanSimulatorConfig sensor = sensorConfig(o);
  ScanSimulator simulator = plan.grid ? ScanSimulator(*plan.grid, sensor, o.seed)
                                      : ScanSimulator(*plan.geometry, sensor, o.seed);

  fs::create_directories(o.out);
  const std::string bag_path = (fs::path(o.out) / "sim.bag").string();
  const std::string tum_path = (fs::path(o.out) / "ground_truth.tum").string();
  FILE* tum = std::fopen(tum_path.c_str(), "w");
  if (!tum) throw std::runtime_error(tum_path + ": cannot write");

  rosbag::Bag bag;
  bag.open(bag_path, rosbag::bagmode::Write);

  double length = 0.0;
  for (std::size_t k = 0; k < path.size(); ++k) {
    const TimedPose& tp = path[k];
    const double stamp = o.start_time + tp.stamp;
    ros::Time t;
    t.fromSec(stamp);

    if (k == 0) {
      tf2_msgs::TFMessage tf;
      geometry_msgs::TransformStamped mount;
      mount.header.stamp = t;
      mount.header.frame_id = "base_link";
      mount.child_frame_id = sensor.frame_id;
      mount.transform = toTransformMsg(o.laser_mount);
      tf.transforms.push_back(mount);
      bag.write("/tf_static", t, tf, latchedHeader(tf));
    } else {
      length += (tp.pose.translation() - path[k - 1].pose.translation()).norm();
    }

    const Pose2D laser_pose = tp.pose * o.laser_mount;
    sensor_msgs::LaserScan scan = toMsg(simulator.simulate(laser_pose, stamp));
    scan.header.stamp = t;
    scan.header.seq = static_cast<std::uint32_t>(k);
    bag.write("/scan", t, scan);

    nav_msgs::Odometry gt;
    gt.header.stamp = t;
    gt.header.seq = static_cast<std::uint32_t>(k);
    gt.header.frame_id = "map";
    gt.child_frame_id = "base_link";
    gt.pose.pose = toPoseMsg(tp.pose);
    gt.twist.twist.linear.x = tp.v;
    gt.twist.twist.angular.z = tp.w;
    bag.write("/ground_truth", t, gt);

    const auto& q = gt.pose.pose.orientation;
    std::fprintf(tum, "%.6f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", t.toSec(), tp.pose.x, tp.pose.y, 0.0, q.x, q.y,
                 q.z, q.w);
  }
  if (o.wheel_odometry && !path.empty()) writeWheelOdometry(bag, o, waypoints, path_config, path.back().stamp);
  bag.close();
  if (std::fclose(tum) != 0) throw std::runtime_error(tum_path + ": write error");

  const double span = path.empty() ? 0.0 : path.back().stamp;
  std::printf("simulate_scans: %zu scans over %.1f s (%.1f m driven) on %s, seed %llu\n", path.size(), span, length,
              o.floorplan.c_str(), static_cast<unsigned long long>(o.seed));
  std::printf("  %s\n  %s\n", bag_path.c_str(), tum_path.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  try {
    options = parseArgs(argc, argv);
  } catch (const UsageError& e) {
    std::cerr << "simulate_scans: " << e.what() << "\n\n" << kUsage;
    return 2;
  }
  try {
    return run(options);
  } catch (const std::exception& e) {
    std::cerr << "simulate_scans: error: " << e.what() << "\n";
    return 1;
  }
}
