// dpslam_offline: runs the laser odometry (and, without --odometry-only, the SLAM) on a bag as fast as
// the CPU allows, without a ROS master. Usage: dpslam_offline --help.
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <sys/stat.h>
#include <vector>

#include "laser_dpslam/slam/dpslam.h"
#include "laser_dpslam/slam/dpslam_parameters.h"
#include "laser_dpslam/odometry/laser_odometry.h"
#include "laser_dpslam/export/occupancy_export.h"
#include "laser_dpslam/odometry/odometry_parameters.h"
#include "laser_dpslam/common/parameter_source.h"
#include "laser_dpslam/ros/bag_scan_reader.h"
#include "laser_dpslam/ros/bag_tf.h"
#include "laser_dpslam/ros/msg_conversion.h"
#include "laser_dpslam/common/run_statistics.h"
#include "laser_dpslam/scan/scan_preprocessor.h"
#include "laser_dpslam/common/trajectory_io.h"
#include "laser_dpslam/offline/trajectory_refiner.h"

using namespace laser_dpslam;

namespace {

const char* kUsage =
    "usage: dpslam_offline --bag IN.bag --out DIR [--scan-topic /scan] [--config FILE.yaml]... [--seed N]\n"
    "                      [--odometry-only] [--base-frame base_link] [--laser-pose X Y YAW] [--quiet]\n"
    "                      [--match-log FILE.csv]   (one line per scan: the match's quality figures)\n"
    "                      [--memory-log FILE.csv]  (one line per scan: RSS, ancestry tree and map size)\n"
    "                      [--slam-log FILE.csv]    (one line per scan: the filter's best pose, spread, Neff;\n"
    "                                               not with --odometry-only)\n"
    "                      [--motion-tum FILE.tum]  (the SLAM moves its particles by this trajectory's motion\n"
    "                                               between scans, interpolated at their stamps, instead of\n"
    "                                               the laser odometry's, with the odometry's covariance: wheel\n"
    "                                               odometry, or a simulator's ground truth to measure the\n"
    "                                               SLAM alone; scans outside its time span are not given to\n"
    "                                               the SLAM)\n"
    "                      [--loops N]              (replay the bag N times, as rosbag play -l would: time\n"
    "                                               goes back at each loop and everything starts over)\n"
    "                      [--wheel-odom TOPIC]     (the wheels' nav_msgs/Odometry in the bag, e.g. /wheel_odom:\n"
    "                                               their motion between two scans replaces the odometry's\n"
    "                                               constant-velocity prediction, as laser_odometry_node does\n"
    "                                               with use_wheel_odometry)\n"
    "Outputs are written at the end, stats.json last; a failed run (e.g. a corrupted bag) writes none.\n"
    "When scan time goes backwards (a looped bag) the odometry and the SLAM start over, as the nodes\n"
    "do, and the outputs describe the part after the last such reset.\n";

struct Args {
  std::string bag, out, scan_topic = "/scan", base_frame = "base_link";
  std::vector<std::string> configs;
  bool has_seed = false;
  long long seed = 0;
  bool odometry_only = false;
  bool has_laser_pose = false;
  double laser_pose[3] = {0, 0, 0};
  bool quiet = false;
  std::string match_log;
  std::string memory_log;
  std::string slam_log;
  std::string motion_tum;
  std::string wheel_odom;
  int loops = 1;
};

[[noreturn]] void usageError(const std::string& what) {
  std::cerr << "dpslam_offline: " << what << "\n" << kUsage;
  std::exit(2);
}

double parseNumber(const std::string& flag, const char* s) {
  char* end = nullptr;
  const double v = std::strtod(s, &end);
  if (end == s || *end != '\0' || !std::isfinite(v)) usageError(flag + " expects a number, got '" + s + "'");
  return v;
}

Args parseArgs(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string f = argv[i];
    auto next = [&](int k = 1) {
      if (i + k >= argc) usageError(f + " needs " + std::to_string(k) + " value(s)");
      return argv[++i];
    };
    if (f == "--bag") a.bag = next();
    else if (f == "--out") a.out = next();
    else if (f == "--scan-topic") a.scan_topic = next();
    else if (f == "--config") a.configs.push_back(next());
    else if (f == "--base-frame") a.base_frame = next();
    else if (f == "--seed") {
      const double v = parseNumber(f, next());
      if (v < 0 || v != std::floor(v)) usageError("--seed expects a non-negative integer");
      a.has_seed = true;
      a.seed = static_cast<long long>(v);
    } else if (f == "--odometry-only") a.odometry_only = true;
    else if (f == "--quiet") a.quiet = true;
    else if (f == "--match-log") a.match_log = next();
    else if (f == "--memory-log") a.memory_log = next();
    else if (f == "--slam-log") a.slam_log = next();
    else if (f == "--motion-tum") a.motion_tum = next();
    else if (f == "--wheel-odom") a.wheel_odom = next();
    else if (f == "--loops") {
      const double v = parseNumber(f, next());
      if (v < 1 || v > 1e6 || v != std::floor(v)) usageError("--loops expects a positive integer");
      a.loops = static_cast<int>(v);
    }
    else if (f == "--laser-pose") {
      if (i + 3 >= argc) usageError("--laser-pose needs X Y YAW");
      for (double& v : a.laser_pose) v = parseNumber(f, argv[++i]);
      a.has_laser_pose = true;
    } else if (f == "-h" || f == "--help") {
      std::cout << kUsage;
      std::exit(0);
    } else usageError("unknown argument '" + f + "'");
  }
  if (a.bag.empty()) usageError("--bag is required");
  if (a.out.empty()) usageError("--out is required");
  if (a.odometry_only && !a.slam_log.empty()) usageError("--slam-log needs the SLAM: drop --odometry-only");
  if (a.odometry_only && !a.motion_tum.empty()) usageError("--motion-tum moves the SLAM: drop --odometry-only");
  return a;
}

void progress(std::size_t done, std::size_t total) {
  const int width = 40;
  const int filled = total ? static_cast<int>(width * done / total) : width;
  std::fprintf(stdout, "\r[%s%s] %zu/%zu scans", std::string(filled, '#').c_str(),
               std::string(width - filled, ' ').c_str(), done, total);
  std::fflush(stdout);
}

/// The topic with and without its leading slash (a bag may hold either).
std::vector<std::string> withAndWithoutSlash(const std::string& topic) {
  if (!topic.empty() && topic[0] == '/') return {topic, topic.substr(1)};
  return {topic, "/" + topic};
}

/// " /a /b" for the bag's topics of `type`, or " none".
std::string topicsOfType(const rosbag::Bag& bag, const std::string& type) {
  std::set<std::string> found;
  rosbag::View all(bag);
  for (const auto* c : all.getConnections()) {
    if (c->datatype == type) found.insert(c->topic);
  }
  std::string list;
  for (const auto& t : found) list += " " + t;
  return list.empty() ? " none" : list;
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parseArgs(argc, argv);

  // One flat parameter namespace: a --config file may hold odometry and SLAM parameters alike
  // (config/laser_odometry.yaml, config/dpslam.yaml); later files override earlier ones.
  LaserOdometryConfig odom_config;
  ScanPreprocessorConfig pre_config;
  DpSlamConfig slam_config;
  try {
    for (const auto& path : args.configs) {
      const YamlParameterSource source = YamlParameterSource::load(path);
      readOdometryParameters(source, odom_config, pre_config);
      // The nodes' own keys (frames, TF) are read too, so count as known, but unused here.
      readDpSlamParameters(source, slam_config);
      for (const std::string& m : source.unknownKeys()) std::cerr << "dpslam_offline: warning: " << path << ": " << m << "\n";
    }
    if (args.has_seed) {
      odom_config.seed = static_cast<std::uint64_t>(args.seed);
      slam_config.seed = static_cast<std::uint64_t>(args.seed);
    }
    slam_config.validate();
  } catch (const std::exception& e) {
    std::cerr << "dpslam_offline: " << e.what() << "\n";
    return 2;
  }
  std::vector<StampedPose> motion;
  if (!args.motion_tum.empty()) {
    try {
      motion = readTum(args.motion_tum);
      for (std::size_t i = 1; i < motion.size(); ++i) {
        if (!(motion[i].stamp > motion[i - 1].stamp)) {
          throw std::runtime_error("'" + args.motion_tum + "': stamps must increase (pose " + std::to_string(i + 1) + ")");
        }
      }
      if (motion.empty()) throw std::runtime_error("'" + args.motion_tum + "' holds no pose");
    } catch (const std::exception& e) {
      std::cerr << "dpslam_offline: --motion-tum: " << e.what() << "\n";
      return 2;
    }
  }

  if (::mkdir(args.out.c_str(), 0755) != 0 && errno != EEXIST) {
    std::cerr << "dpslam_offline: cannot create output directory '" << args.out << "': " << std::strerror(errno) << "\n";
    return 1;
  }

  rosbag::Bag bag;
  try {
    bag.open(args.bag, rosbag::bagmode::Read);
  } catch (const std::exception& e) {
    // A bag cut short (copy interrupted, recorder killed) has lost its index at the end.
    std::cerr << "dpslam_offline: cannot read bag '" << args.bag << "': " << e.what()
              << " (truncated, or still being recorded? `rosbag reindex` recovers the complete part)\n";
    return 1;
  }

  std::FILE* memory_log = nullptr;
  if (!args.memory_log.empty()) {
    // Streamed, not kept in memory: the log must not be the growth it measures.
    memory_log = std::fopen(args.memory_log.c_str(), "w");
    if (!memory_log) {
      std::cerr << "dpslam_offline: cannot write '" << args.memory_log << "': " << std::strerror(errno) << "\n";
      return 1;
    }
    std::fprintf(memory_log, "loop,scan,stamp,wall_s,rss_mb,tree_nodes,map_entries,slam_memory_mb\n");
  }

  const bool show_progress = !args.quiet && ::isatty(STDOUT_FILENO);
  std::string slam_log = "stamp,ok,x,y,theta,sxx,syy,stt,neff,resampled,score_spread,revisit\n";
  std::string match_log = "stamp,ok,skip_reason,x,y,theta,dx,dy,dtheta,score,matched,degenerate,weak,de_gen,de_evals,newton,points,keyframe,ms,sxx,syy,stt,pxx,pyy,ptt,flow_beams,flow_speed,flow_applied\n";
  LaserOdometry odometry(odom_config);
  // The offline refinement of the output path keeps a keyframe (its scan's points) every 0.2 m.
  const bool refine = !args.odometry_only && slam_config.refine_trajectory;
  TrajectoryRefiner refiner;
  std::unique_ptr<DpSlam> slam;
  if (!args.odometry_only) slam = std::make_unique<DpSlam>(slam_config);
  Pose2D slam_last_odom;               // odometry pose of the last scan given to the SLAM
  Eigen::Matrix3d slam_delta_cov = Eigen::Matrix3d::Zero();  // accumulated since then
  Eigen::Matrix3d odom_last_covariance = Eigen::Matrix3d::Zero();  // the odometry's pose covariance at the last scan
  bool slam_has_last = false;
  std::vector<double> slam_ms;
  DpSlamUpdate last_slam;
  std::size_t max_tree_nodes = 0;
  LaserMount mount;
  bool mount_known = false;
  std::string laser_frame;
  std::vector<StampedPose> odom_poses;
  std::vector<double> odom_ms;
  std::map<std::string, int> skipped;
  int matched = 0, bad = 0, time_resets = 0;
  std::size_t wheel_messages = 0;
  bool have_stamp = false;
  double first_stamp = 0.0, last_stamp = 0.0, previous_stamp = 0.0;
  double earlier_segments = 0.0;  // s of data before the last time reset
  std::size_t per_loop = 0, total = 0, done = 0;
  // A new time line (time went backwards): the outputs restart, so does the SLAM's map.
  auto start_over = [&](double from, double to) {
    if (!odom_poses.empty()) earlier_segments += last_stamp - first_stamp;
    if (!args.quiet && time_resets == 0) {
      std::cerr << "dpslam_offline: warning: scan time went backwards (" << from << " -> " << to
                << " s): odometry and SLAM start over; the outputs describe the part after the last reset\n";
    }
    ++time_resets;
    odom_poses.clear();
    if (slam) slam->reset();
    refiner.clear();
    slam_has_last = false;
    slam_delta_cov.setZero();
  };
  const auto wall0 = std::chrono::steady_clock::now();
  const double cpu0 = processCpuSeconds();

  try {
    const std::vector<std::string> scan_topics = withAndWithoutSlash(args.scan_topic);
    const std::vector<std::string> wheel_topics =
        args.wheel_odom.empty() ? std::vector<std::string>() : withAndWithoutSlash(args.wheel_odom);
    // From time 0, not View's default TIME_MIN: logs without time (DP-SLAM) start at 0.
    per_loop = rosbag::View(bag, rosbag::TopicQuery(scan_topics), ros::Time(0, 0), ros::TIME_MAX).size();
    total = per_loop * static_cast<std::size_t>(args.loops);
    if (total == 0) {
      std::cerr << "dpslam_offline: no messages on " << args.scan_topic << " in '" << args.bag
                << "'; LaserScan topics in the bag:" << topicsOfType(bag, "sensor_msgs/LaserScan") << " (use --scan-topic)\n";
      return 1;
    }
    if (!wheel_topics.empty() &&
        rosbag::View(bag, rosbag::TopicQuery(wheel_topics), ros::Time(0, 0), ros::TIME_MAX).size() == 0) {
      std::cerr << "dpslam_offline: --wheel-odom: no messages on " << args.wheel_odom << " in '" << args.bag
                << "'; Odometry topics in the bag:" << topicsOfType(bag, "nav_msgs/Odometry") << "\n";
      return 1;
    }
    std::vector<std::string> topics = scan_topics;
    topics.insert(topics.end(), wheel_topics.begin(), wheel_topics.end());
    rosbag::View view(bag, rosbag::TopicQuery(topics), ros::Time(0, 0), ros::TIME_MAX);

    for (int loop = 0; loop < args.loops; ++loop) {
      for (const rosbag::MessageInstance& m : view) {
        if (!wheel_topics.empty() && (m.getTopic() == wheel_topics[0] || m.getTopic() == wheel_topics[1])) {
          // Wheel odometry in bag order, as the node receives it: a scan sees the samples before it.
          if (const nav_msgs::Odometry::ConstPtr w = readOdometry(m)) {
            odometry.addWheelOdometry(w->header.stamp.toSec(), poseFromMsg(w->pose.pose));
            ++wheel_messages;
          }
          continue;
        }
        ++done;
        sensor_msgs::LaserScan::ConstPtr msg = readLaserScan(m);
        if (!msg) {
          ++skipped["not_a_laser_scan"];
          continue;
        }
        if (!mount_known) {
          laser_frame = cleanFrameId(msg->header.frame_id);
          if (args.has_laser_pose) {
            mount = LaserMount::fromPose(Pose2D(args.laser_pose[0], args.laser_pose[1], args.laser_pose[2]));
          } else {
            geometry_msgs::Transform t;
            std::string error;
            if (laser_frame == cleanFrameId(args.base_frame)) {
              mount = LaserMount();
            } else if (findBagTransform(bag, args.base_frame, laser_frame, &t, &error)) {
              mount = mountFromTransform(t);
            } else {
              std::cerr << "dpslam_offline: warning: " << error << "; taking the laser to be at " << args.base_frame
                        << " (use --laser-pose X Y YAW to override)\n";
            }
          }
          mount_known = true;
        }
        const LaserScan scan = fromMsg(*msg);
        // Time went backwards (a looped bag): start over like dpslam_node, which resets the SLAM on any
        // earlier stamp; the odometry resets itself. The outputs keep one monotonic time line.
        if (have_stamp && scan.stamp < previous_stamp) start_over(previous_stamp, scan.stamp);
        have_stamp = true;
        previous_stamp = scan.stamp;
        const double t0 = threadCpuSeconds();
        const PreprocessedScan pre = preprocessScan(scan, pre_config);
        const OdometryUpdate u = odometry.process(pre, mount);
        const double ms = 1e3 * (threadCpuSeconds() - t0);

        if (!args.match_log.empty()) {
          char line[512];
          std::snprintf(line, sizeof(line), "%.6f,%d,%s,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.4f,%.3f,%d,%d,%d,%d,%d,%d,%d,%.4f,%.3g,%.3g,%.3g,%.4g,%.4g,%.4g,%d,%.4f,%d\n",
                        scan.stamp, u.ok, toString(u.skip_reason), u.pose.x, u.pose.y, u.pose.theta, u.delta.x, u.delta.y,
                        u.delta.theta, u.match.score_per_point, u.match.matched_fraction, u.match.degenerate, u.match.weak,
                        u.match.de_generations, u.match.de_evaluations, u.match.newton_iterations, u.points_used,
                        u.new_keyframe, ms, u.delta_covariance(0, 0), u.delta_covariance(1, 1), u.delta_covariance(2, 2),
                        u.pose_covariance(0, 0), u.pose_covariance(1, 1), u.pose_covariance(2, 2),
                        u.range_flow.valid ? u.range_flow.beams : 0, u.range_flow.valid ? u.range_flow.speed : 0.0,
                        u.range_flow_applied ? 1 : 0);
          match_log += line;
        }
        // The odometry restarted by its own time check (compared with the last scan it used): same thing.
        if (u.reset && !odom_poses.empty()) start_over(odom_poses.back().stamp, scan.stamp);
        if (odom_poses.empty()) first_stamp = scan.stamp;
        if (!u.ok) {
          ++skipped[pre.ok() ? toString(u.skip_reason) : "malformed_scan"];
          if (u.skip_reason == OdometrySkipReason::kTimeBackwards ||
              u.skip_reason == OdometrySkipReason::kDuplicateStamp || !pre.ok()) {
            if (show_progress && done % 20 == 0) progress(done, total);
            continue;
          }
        } else {
          odom_ms.push_back(ms);
          if (!u.reset) {
            ++matched;
            if (u.match.weak || u.match.degenerate) ++bad;
          }
        }
        if (!odom_poses.empty() && scan.stamp <= odom_poses.back().stamp) {
          // Not reached since the reset above (kept as a guard): the TUM files need a monotonic time line.
          ++skipped["time_backwards"];
          continue;
        }
        odom_poses.push_back({scan.stamp, u.pose});
        if (refine) refiner.addScan(scan.stamp, u.pose, mount.apply(pre.points), u.reset);
        odom_last_covariance = u.pose_covariance;
        last_stamp = scan.stamp;
        // The motion given to the SLAM: the laser odometry's, or --motion-tum's at this stamp.
        Pose2D motion_pose = u.pose;
        const bool have_motion = motion.empty() || interpolatePose(motion, scan.stamp, &motion_pose);
        if (!have_motion) ++skipped["slam_outside_motion_tum"];
        if (slam) slam_delta_cov += u.delta_covariance;  // a scan not given to the SLAM adds to the next delta's
        if (slam && have_motion) {
          const Pose2D delta = slam_has_last && !u.reset ? between(slam_last_odom, motion_pose) : Pose2D();
          const auto s0 = std::chrono::steady_clock::now();
          last_slam = slam->process(scan.stamp, pre, mount, delta, slam_delta_cov);
          // Wall time: the SLAM scores particles on several threads.
          slam_ms.push_back(1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count());
          if (!last_slam.ok) ++skipped["slam_" + last_slam.skip_reason];
          if (!args.slam_log.empty()) {
            char line[256];
            std::snprintf(line, sizeof(line), "%.6f,%d,%.5f,%.5f,%.5f,%.3g,%.3g,%.3g,%.2f,%d,%.3f,%d\n", scan.stamp, last_slam.ok,
                          last_slam.pose.x, last_slam.pose.y, last_slam.pose.theta, last_slam.covariance(0, 0),
                          last_slam.covariance(1, 1), last_slam.covariance(2, 2), last_slam.neff, last_slam.resampled,
                          last_slam.score_spread, last_slam.revisit);
            slam_log += line;
          }
          max_tree_nodes = std::max(max_tree_nodes, last_slam.tree_nodes);
          slam_last_odom = motion_pose;
          slam_delta_cov.setZero();
          slam_has_last = true;
        }
        if (memory_log) {
          std::fprintf(memory_log, "%d,%zu,%.6f,%.3f,%.3f,%zu,%zu,%.3f\n", loop, done, scan.stamp,
                       std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count(), currentRssMb(),
                       slam ? last_slam.tree_nodes : 0, slam ? last_slam.map_entries : 0,
                       slam ? last_slam.memory_bytes / 1048576.0 : 0.0);
        }
        if (show_progress && done % 20 == 0) progress(done, total);
      }
    }
  } catch (const std::exception& e) {
    // rosbag's exceptions for damaged chunks, readLaserScan's for damaged records. Nothing is written:
    // outputs of part of a bag would look like the result of the whole.
    if (show_progress) std::fprintf(stdout, "\n");
    std::cerr << "dpslam_offline: error reading bag '" << args.bag << "'";
    if (per_loop > 0) std::cerr << " at scan message " << (done - 1) % per_loop + 1 << " of " << per_loop;
    std::cerr << ": " << e.what()
              << "; the bag is damaged, no outputs written (`rosbag check` / `rosbag reindex` may help)\n";
    if (memory_log) std::fclose(memory_log);
    return 1;
  }
  if (memory_log && std::fclose(memory_log) != 0) {
    std::cerr << "dpslam_offline: cannot write '" << args.memory_log << "': " << std::strerror(errno) << "\n";
    return 1;
  }
  if (show_progress) {
    progress(done, total);
    std::fprintf(stdout, "\n");
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const double cpu = processCpuSeconds() - cpu0;
  RefinerStats refine_stats;
  double refine_cpu_s = 0.0;
  const double duration = earlier_segments + (odom_poses.empty() ? 0.0 : last_stamp - first_stamp);

  try {
    writeFileAtomically(args.out + "/odometry.tum", formatTum(odom_poses));
    if (slam) {
      std::vector<StampedPose> trajectory = slam->bestTrajectory();
      const OccupancyGridData grid = slam->bestMap();
      std::vector<StampedPose> trajectory_filter;
      if (refine) {
        const double r0 = processCpuSeconds();
        trajectory_filter = trajectory;
        trajectory = refiner.refine(trajectory, &refine_stats);
        refine_cpu_s = processCpuSeconds() - r0;
      }
      writeFileAtomically(args.out + "/trajectory.tum", formatTum(trajectory));
      if (refine) writeFileAtomically(args.out + "/trajectory_filter.tum", formatTum(trajectory_filter));
      writeMapServerFiles(grid, args.out + "/map.yaml");
      writeMapPng(grid, trajectory, args.out + "/map.png");
    }
    if (!args.match_log.empty()) writeFileAtomically(args.match_log, match_log);
    if (!args.slam_log.empty()) writeFileAtomically(args.slam_log, slam_log);
    std::string json = "{\n";
    json += "  \"scans\": " + std::to_string(total) + ",\n";
    json += "  \"data_duration_s\": " + jsonNumber(duration) + ",\n";
    json += "  \"wall_s\": " + jsonNumber(wall) + ",\n";
    json += "  \"cpu_s\": " + jsonNumber(cpu) + ",\n";
    json += "  \"realtime_factor\": " + jsonNumber(wall > 0 ? duration / wall : 0.0) + ",\n";
    json += "  \"odometry_ms\": " + jsonTiming(summarize(odom_ms)) + ",\n";
    json += "  \"slam_ms\": " + (slam ? jsonTiming(summarize(slam_ms)) : std::string("null")) + ",\n";
    json += "  \"peak_rss_mb\": " + jsonNumber(peakRssMb()) + ",\n";
    json += "  \"particles\": " + std::to_string(slam ? slam_config.particles : 0) + ",\n";
    if (slam) {
      json += "  \"tree_nodes\": " + std::to_string(last_slam.tree_nodes) + ",\n";
      json += "  \"tree_nodes_max\": " + std::to_string(max_tree_nodes) + ",\n";
      json += "  \"map_entries\": " + std::to_string(last_slam.map_entries) + ",\n";
      json += "  \"slam_memory_mb\": " + jsonNumber(last_slam.memory_bytes / 1048576.0) + ",\n";
      // The output path's refinement (refine_trajectory; after the run, not in wall_s / cpu_s).
      json += refine ? "  \"refinement\": {\"keyframes\": " + std::to_string(refine_stats.keyframes) +
                           ", \"matches\": " + std::to_string(refine_stats.match_edges) +
                           ", \"rejected_matches\": " + std::to_string(refine_stats.rejected_matches) +
                           ", \"iterations\": " + std::to_string(refine_stats.graph.iterations) +
                           ", \"max_shift_m\": " + jsonNumber(refine_stats.max_shift_m) +
                           ", \"cpu_s\": " + jsonNumber(refine_cpu_s) + "},\n"
                     : std::string("  \"refinement\": null,\n");
    }
    json += "  \"seed\": " + std::to_string(odom_config.seed) + ",\n";
    // The odometry's own pose uncertainty at the end (what /odom's pose covariance says): σ x, y, θ.
    json += "  \"odometry_final_sigma\": {\"x_m\": " + jsonNumber(std::sqrt(odom_last_covariance(0, 0))) +
            ", \"y_m\": " + jsonNumber(std::sqrt(odom_last_covariance(1, 1))) +
            ", \"theta_rad\": " + jsonNumber(std::sqrt(odom_last_covariance(2, 2))) + "},\n";
    json += "  \"bad_match_percent\": " + jsonNumber(matched ? 100.0 * bad / matched : 0.0) + ",\n";
    json += "  \"resampling\": " + jsonString(resamplingMethodName(odom_config.resampling)) + ",\n";
    json += std::string("  \"mode\": ") + (slam ? "\"slam\"" : "\"odometry-only\"") + ",\n";
    json += "  \"loops\": " + std::to_string(args.loops) + ",\n";
    json += "  \"wheel_odometry_messages\": " + std::to_string(wheel_messages) + ",\n";
    json += "  \"time_resets\": " + std::to_string(time_resets) + ",\n";
    json += "  \"skipped\": " + jsonCounts(skipped) + "\n}\n";
    // Last: a stats.json means the run completed and every other output was written.
    writeFileAtomically(args.out + "/stats.json", json);
  } catch (const std::exception& e) {
    std::cerr << "dpslam_offline: " << e.what() << "\n";
    return 1;
  }
  if (!args.quiet) {
    std::printf("dpslam_offline: %zu scans, %.1f s of data in %.2f s (%.1fx real time), odometry median %.3f ms; wrote %s\n",
                total, duration, wall, wall > 0 ? duration / wall : 0.0, summarize(odom_ms).median, args.out.c_str());
  }
  return 0;
}
