// simulate_scans: a Hokuyo URG-04LX on an iRobot Create driving through a floor plan, written to a bag.
//
//   simulate_scans --floorplan PLAN.yaml --path {loop,explore,WAYPOINTS.txt} --out DIR [--seed N] [--duration S]
//                  [--rate HZ] [--laps N] [--start-time S] [--laser-x M] [--laser-y M] [--laser-yaw RAD]
//                  [--dropout P] [--outliers P] [--range-noise M]
//                  [--range-noise-fraction F] [--no-noise] [--robot-radius M]
//
// Writes DIR/sim.bag (/scan, /tf_static, /ground_truth) and DIR/ground_truth.tum. `--path loop` and
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
#include <stdexcept>
#include <string>
#include <vector>

#include "laser_dpslam/floor_plan.h"
#include "laser_dpslam/ros/msg_conversion.h"
#include "laser_dpslam/scan_simulator.h"
#include "laser_dpslam/sim_path.h"

namespace fs = std::filesystem;
using namespace laser_dpslam;

namespace {

const char* kUsage =
    "usage: simulate_scans --floorplan PLAN.yaml --path {loop,explore,WAYPOINTS.txt} --out DIR\n"
    "                      [--seed N] [--duration S] [options]\n"
    "\n"
    "Simulates a Hokuyo URG-04LX (683 beams, 240 deg, 0.02-5.6 m, 10 Hz, datasheet noise, dropouts as NaN,\n"
    "no return as +inf) on an iRobot Create driving the waypoints through the floor plan (map_server YAML).\n"
    "Writes DIR/sim.bag (/scan sensor_msgs/LaserScan frame 'laser'; /tf_static base_link->laser;\n"
    "/ground_truth nav_msgs/Odometry map->base_link) and DIR/ground_truth.tum (true base_link pose at every\n"
    "scan stamp: 'stamp x y z qx qy qz qw').\n"
    "\n"
    "  --path loop|explore  the built-in paths of the plan: <plan dir>/<plan stem>_loop.txt / _explore.txt\n"
    "  --path FILE          waypoints, one 'x y' per line (metres, map frame), '#' comments; the robot starts\n"
    "                       at the first facing the second and turns in place at each\n"
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
    "  --robot-radius M     refuse paths closer than M to a wall (default 0.17, the Create's radius; 0: off)\n";

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
};

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
    } else {
      throw UsageError("unknown option '" + flag + "'");
    }
  }
  if (o.floorplan.empty()) throw UsageError("--floorplan is required");
  if (o.path.empty()) throw UsageError("--path is required");
  if (o.out.empty()) throw UsageError("--out is required");
  return o;
}

std::vector<Eigen::Vector2d> resolveWaypoints(const Options& o) {
  if (o.path == "loop" || o.path == "explore") {
    const std::string file = builtinPathFile(o.floorplan, o.path);
    if (!fs::exists(file)) {
      throw std::runtime_error("floor plan " + o.floorplan + " has no built-in '" + o.path + "' path (expected " +
                               file + "); pass a waypoint file with --path FILE");
    }
    return loadWaypoints(file);
  }
  return loadWaypoints(o.path);
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

int run(const Options& o) {
  const FloorPlan plan = FloorPlan::load(o.floorplan);
  std::vector<Eigen::Vector2d> waypoints = resolveWaypoints(o);
  const bool closed = isClosedLoop(waypoints);
  if (o.laps > 1) {
    if (!closed) std::cerr << "simulate_scans: warning: the path is not a closed loop; --laps closes it\n";
    waypoints = repeatLoop(waypoints, o.laps);
  }

  if (o.robot_radius > 0.0) {
    const std::string problem = checkPathClearance(plan, waypoints, o.robot_radius);
    if (!problem.empty()) throw std::runtime_error(o.path + ": " + problem);
  }

  PathConfig path_config;
  if (o.duration > 0.0 && closed) {
    // Repeat the loop until it lasts at least --duration.
    const std::vector<Eigen::Vector2d> one = waypoints;
    int laps = 1;
    while (pathDuration(waypoints, path_config) < o.duration && laps < 10000) waypoints = repeatLoop(one, ++laps);
  }
  std::vector<TimedPose> path = samplePath(waypoints, o.rate, path_config);
  if (o.duration > 0.0) {
    const double last = path.back().stamp;
    if (last < o.duration) {
      std::cerr << "simulate_scans: warning: the path ends after " << last << " s, before --duration " << o.duration
                << " s (it is not a closed loop, so it is not repeated)\n";
    }
    while (!path.empty() && path.back().stamp > o.duration + 1e-9) path.pop_back();
  }

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
  ScanSimulator simulator(plan, sensor, o.seed);

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
