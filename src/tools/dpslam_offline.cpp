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
#include <utility>
#include <sys/stat.h>
#include <vector>

#include "laser_dpslam/common/parameter_source.h"
#include "laser_dpslam/common/run_statistics.h"
#include "laser_dpslam/common/trajectory_io.h"
#include "laser_dpslam/export/occupancy_export.h"
#include "laser_dpslam/odometry/laser_odometry.h"
#include "laser_dpslam/odometry/odometry_parameters.h"
#include "laser_dpslam/offline/trajectory_refiner.h"
#include "laser_dpslam/ros/bag_scan_reader.h"
#include "laser_dpslam/ros/bag_tf.h"
#include "laser_dpslam/ros/msg_conversion.h"
#include "laser_dpslam/scan/scan_preprocessor.h"
#include "laser_dpslam/slam/dpslam.h"
#include "laser_dpslam/slam/dpslam_parameters.h"
#include "laser_dpslam/slam/motion_covariance.h"

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
    "                                               with use_wheel_odometry, and the SLAM's particles spread\n"
    "                                               no more than the wheels' error, as dpslam_node does)\n"
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

/// The odometry's, the preprocessor's and the SLAM's parameters.
struct Configs {
  LaserOdometryConfig odom;
  ScanPreprocessorConfig pre;
  DpSlamConfig slam;
};

/// Reads every --config file and applies --seed; false (the error printed) on a bad file or parameter.
bool readConfigs(const Args& args, Configs* c) {
  // One flat parameter namespace: a --config file may hold odometry and SLAM parameters alike
  // (config/laser_odometry.yaml, config/dpslam.yaml); later files override earlier ones.
  try {
    for (const auto& path : args.configs) {
      const YamlParameterSource source = YamlParameterSource::load(path);
      readOdometryParameters(source, c->odom, c->pre);
      // The nodes' own keys (frames, TF) are read too, so count as known, but unused here.
      readDpSlamParameters(source, c->slam);
      for (const std::string& m : source.unknownKeys()) std::cerr << "dpslam_offline: warning: " << path << ": " << m << "\n";
    }
    if (args.has_seed) {
      c->odom.seed = static_cast<std::uint64_t>(args.seed);
      c->slam.seed = static_cast<std::uint64_t>(args.seed);
    }
    if (!args.wheel_odom.empty()) c->slam.proposal.bounded_by_wheels = true;  // as use_wheel_odometry
    c->slam.validate();
  } catch (const std::exception& e) {
    std::cerr << "dpslam_offline: " << e.what() << "\n";
    return false;
  }
  return true;
}

/// --motion-tum's poses (none without it); false (the error printed) when unreadable, empty or not increasing.
bool readMotion(const Args& args, std::vector<StampedPose>* motion) {
  if (args.motion_tum.empty()) return true;
  try {
    *motion = readTum(args.motion_tum);
    for (std::size_t i = 1; i < motion->size(); ++i) {
      if (!((*motion)[i].stamp > (*motion)[i - 1].stamp)) {
        throw std::runtime_error("'" + args.motion_tum + "': stamps must increase (pose " + std::to_string(i + 1) + ")");
      }
    }
    if (motion->empty()) throw std::runtime_error("'" + args.motion_tum + "' holds no pose");
  } catch (const std::exception& e) {
    std::cerr << "dpslam_offline: --motion-tum: " << e.what() << "\n";
    return false;
  }
  return true;
}

/// Creates --out, opens the bag and --memory-log (with its header); false (the error printed) on failure.
bool openFiles(const Args& args, rosbag::Bag& bag, std::FILE** memory_log) {
  if (::mkdir(args.out.c_str(), 0755) != 0 && errno != EEXIST) {
    std::cerr << "dpslam_offline: cannot create output directory '" << args.out << "': " << std::strerror(errno) << "\n";
    return false;
  }
  try {
    bag.open(args.bag, rosbag::bagmode::Read);
  } catch (const std::exception& e) {
    // A bag cut short (copy interrupted, recorder killed) has lost its index at the end.
    std::cerr << "dpslam_offline: cannot read bag '" << args.bag << "': " << e.what()
              << " (truncated, or still being recorded? `rosbag reindex` recovers the complete part)\n";
    return false;
  }
  if (!args.memory_log.empty()) {
    // Streamed, not kept in memory: the log must not be the growth it measures.
    *memory_log = std::fopen(args.memory_log.c_str(), "w");
    if (!*memory_log) {
      std::cerr << "dpslam_offline: cannot write '" << args.memory_log << "': " << std::strerror(errno) << "\n";
      return false;
    }
    std::fprintf(*memory_log, "loop,scan,stamp,wall_s,rss_mb,tree_nodes,map_entries,slam_memory_mb\n");
  }
  return true;
}

/// One run over the bag: the odometry (and the SLAM) scan by scan, then the outputs.
class OfflineRun {
 public:
  OfflineRun(const Args& args, const Configs& configs, std::vector<StampedPose> motion, rosbag::Bag& bag,
             std::FILE* memory_log);
  /// Every loop over the bag; false (the error printed) when it holds no scans or is damaged.
  bool readBag();
  /// The outputs, stats.json last, and the summary line; false (the error printed) when one fails.
  bool writeOutputs();

 private:
  void startOver(double from, double to);
  bool countMessages(const std::vector<std::string>& scan_topics);
  bool isWheelMessage(const rosbag::MessageInstance& m) const;
  void addWheelMessage(const rosbag::MessageInstance& m);
  void processScan(const rosbag::MessageInstance& m, int loop);
  void findMount(const sensor_msgs::LaserScan& msg);
  void logMatch(const LaserScan& scan, const OdometryUpdate& u, double ms);
  bool recordOdometry(const LaserScan& scan, const PreprocessedScan& pre, const OdometryUpdate& u, double ms);
  void feedSlam(const LaserScan& scan, const PreprocessedScan& pre, const OdometryUpdate& u);
  void logSlam(double stamp);
  void logMemory(int loop, double stamp);
  void showProgress() const;
  void reportDamagedBag(const std::exception& e);
  void writeSlamOutputs();
  std::string statsJson(double duration, double wall, double cpu) const;

  const Args& args_;
  const Configs configs_;
  const std::vector<StampedPose> motion_;
  rosbag::Bag& bag_;
  std::FILE* memory_log_;
  const bool show_progress_;
  std::string slam_log_ = "stamp,ok,x,y,theta,sxx,syy,stt,neff,resampled,score_spread,revisit\n";
  std::string match_log_ = "stamp,ok,skip_reason,x,y,theta,dx,dy,dtheta,score,matched,degenerate,weak,de_gen,de_evals,newton,points,keyframe,ms,sxx,syy,stt,pxx,pyy,ptt,flow_beams,flow_speed,flow_applied,held,held_blank\n";
  LaserOdometry odometry_;
  // The offline refinement of the output path keeps a keyframe (its scan's points) every 0.2 m.
  const bool refine_;
  TrajectoryRefiner refiner_;
  std::unique_ptr<DpSlam> slam_;
  Pose2D slam_last_odom_;               // odometry pose of the last scan given to the SLAM
  Pose2D slam_pending_;                 // the odometry's own motion since then, composed
  Eigen::Matrix3d slam_delta_cov_ = Eigen::Matrix3d::Zero();  // its covariance, composed the same way
  Eigen::Matrix3d odom_last_covariance_ = Eigen::Matrix3d::Zero();  // the odometry's pose covariance at the last scan
  bool slam_has_last_ = false;
  double slam_last_stamp_ = 0.0;
  std::vector<double> slam_ms_;
  DpSlamUpdate last_slam_;
  std::size_t max_tree_nodes_ = 0;
  LaserMount mount_;
  bool mount_known_ = false;
  std::string laser_frame_;
  std::vector<StampedPose> odom_poses_;
  std::vector<double> odom_ms_;
  std::map<std::string, int> skipped_;
  int matched_ = 0, bad_ = 0, time_resets_ = 0;
  std::size_t wheel_messages_ = 0;
  bool have_stamp_ = false;
  double first_stamp_ = 0.0, last_stamp_ = 0.0, previous_stamp_ = 0.0;
  double earlier_segments_ = 0.0;  // s of data before the last time reset
  std::size_t per_loop_ = 0, total_ = 0, done_ = 0;
  std::vector<std::string> wheel_topics_;
  std::chrono::steady_clock::time_point wall0_;
  double cpu0_ = 0.0;
  RefinerStats refine_stats_;
  double refine_cpu_s_ = 0.0;
};

OfflineRun::OfflineRun(const Args& args, const Configs& configs, std::vector<StampedPose> motion, rosbag::Bag& bag,
                       std::FILE* memory_log)
    : args_(args),
      configs_(configs),
      motion_(std::move(motion)),
      bag_(bag),
      memory_log_(memory_log),
      show_progress_(!args.quiet && ::isatty(STDOUT_FILENO)),
      odometry_(configs.odom),
      refine_(!args.odometry_only && configs.slam.refine_trajectory) {
  if (!args.odometry_only) slam_ = std::make_unique<DpSlam>(configs.slam);
}

// A new time line (time went backwards): the outputs restart, so does the SLAM's map.
void OfflineRun::startOver(double from, double to) {
  if (!odom_poses_.empty()) earlier_segments_ += last_stamp_ - first_stamp_;
  if (!args_.quiet && time_resets_ == 0) {
    std::cerr << "dpslam_offline: warning: scan time went backwards (" << from << " -> " << to
              << " s): odometry and SLAM start over; the outputs describe the part after the last reset\n";
  }
  ++time_resets_;
  odom_poses_.clear();
  if (slam_) slam_->reset();
  refiner_.clear();
  slam_has_last_ = false;
  slam_pending_ = Pose2D();
  slam_delta_cov_.setZero();
}

/// Counts the scans per loop and in all; false (the error printed) when the bag has none, or no wheel odometry
/// on --wheel-odom.
bool OfflineRun::countMessages(const std::vector<std::string>& scan_topics) {
  // From time 0, not View's default TIME_MIN: logs without time (DP-SLAM) start at 0.
  per_loop_ = rosbag::View(bag_, rosbag::TopicQuery(scan_topics), ros::Time(0, 0), ros::TIME_MAX).size();
  total_ = per_loop_ * static_cast<std::size_t>(args_.loops);
  if (total_ == 0) {
    std::cerr << "dpslam_offline: no messages on " << args_.scan_topic << " in '" << args_.bag
              << "'; LaserScan topics in the bag:" << topicsOfType(bag_, "sensor_msgs/LaserScan") << " (use --scan-topic)\n";
    return false;
  }
  if (!wheel_topics_.empty() &&
      rosbag::View(bag_, rosbag::TopicQuery(wheel_topics_), ros::Time(0, 0), ros::TIME_MAX).size() == 0) {
    std::cerr << "dpslam_offline: --wheel-odom: no messages on " << args_.wheel_odom << " in '" << args_.bag
              << "'; Odometry topics in the bag:" << topicsOfType(bag_, "nav_msgs/Odometry") << "\n";
    return false;
  }
  return true;
}

bool OfflineRun::readBag() {
  wall0_ = std::chrono::steady_clock::now();
  cpu0_ = processCpuSeconds();
  try {
    const std::vector<std::string> scan_topics = withAndWithoutSlash(args_.scan_topic);
    if (!args_.wheel_odom.empty()) wheel_topics_ = withAndWithoutSlash(args_.wheel_odom);
    if (!countMessages(scan_topics)) return false;
    std::vector<std::string> topics = scan_topics;
    topics.insert(topics.end(), wheel_topics_.begin(), wheel_topics_.end());
    rosbag::View view(bag_, rosbag::TopicQuery(topics), ros::Time(0, 0), ros::TIME_MAX);
    for (int loop = 0; loop < args_.loops; ++loop) {
      for (const rosbag::MessageInstance& m : view) {
        if (isWheelMessage(m)) {
          addWheelMessage(m);
        } else {
          processScan(m, loop);
        }
      }
    }
  } catch (const std::exception& e) {
    reportDamagedBag(e);
    return false;
  }
  if (memory_log_ && std::fclose(memory_log_) != 0) {
    std::cerr << "dpslam_offline: cannot write '" << args_.memory_log << "': " << std::strerror(errno) << "\n";
    return false;
  }
  if (show_progress_) {
    progress(done_, total_);
    std::fprintf(stdout, "\n");
  }
  return true;
}

void OfflineRun::reportDamagedBag(const std::exception& e) {
  // rosbag's exceptions for damaged chunks, readLaserScan's for damaged records. Nothing is written:
  // outputs of part of a bag would look like the result of the whole.
  if (show_progress_) std::fprintf(stdout, "\n");
  std::cerr << "dpslam_offline: error reading bag '" << args_.bag << "'";
  if (per_loop_ > 0) std::cerr << " at scan message " << (done_ - 1) % per_loop_ + 1 << " of " << per_loop_;
  std::cerr << ": " << e.what()
            << "; the bag is damaged, no outputs written (`rosbag check` / `rosbag reindex` may help)\n";
  if (memory_log_) std::fclose(memory_log_);
}

bool OfflineRun::isWheelMessage(const rosbag::MessageInstance& m) const {
  return !wheel_topics_.empty() && (m.getTopic() == wheel_topics_[0] || m.getTopic() == wheel_topics_[1]);
}

void OfflineRun::addWheelMessage(const rosbag::MessageInstance& m) {
  // Wheel odometry in bag order, as the node receives it: a scan sees the samples before it.
  if (const nav_msgs::Odometry::ConstPtr w = readOdometry(m)) {
    odometry_.addWheelOdometry(w->header.stamp.toSec(), poseFromMsg(w->pose.pose));
    ++wheel_messages_;
  }
}

void OfflineRun::showProgress() const {
  if (show_progress_ && done_ % 20 == 0) progress(done_, total_);
}

void OfflineRun::processScan(const rosbag::MessageInstance& m, int loop) {
  ++done_;
  sensor_msgs::LaserScan::ConstPtr msg = readLaserScan(m);
  if (!msg) {
    ++skipped_["not_a_laser_scan"];
    return;
  }
  if (!mount_known_) findMount(*msg);
  const LaserScan scan = fromMsg(*msg);
  // Time went backwards (a looped bag): start over like dpslam_node, which resets the SLAM on any
  // earlier stamp; the odometry resets itself. The outputs keep one monotonic time line.
  if (have_stamp_ && scan.stamp < previous_stamp_) startOver(previous_stamp_, scan.stamp);
  have_stamp_ = true;
  previous_stamp_ = scan.stamp;
  const double t0 = threadCpuSeconds();
  const PreprocessedScan pre = preprocessScan(scan, configs_.pre);
  const OdometryUpdate u = odometry_.process(pre, mount_);
  const double ms = 1e3 * (threadCpuSeconds() - t0);
  if (!args_.match_log.empty()) logMatch(scan, u, ms);
  if (!recordOdometry(scan, pre, u, ms)) return;
  feedSlam(scan, pre, u);
  if (memory_log_) logMemory(loop, scan.stamp);
  showProgress();
}

/// The laser's pose on the robot, from the first scan: --laser-pose, else the bag's TF.
void OfflineRun::findMount(const sensor_msgs::LaserScan& msg) {
  laser_frame_ = cleanFrameId(msg.header.frame_id);
  if (args_.has_laser_pose) {
    mount_ = LaserMount::fromPose(Pose2D(args_.laser_pose[0], args_.laser_pose[1], args_.laser_pose[2]));
  } else {
    geometry_msgs::Transform t;
    std::string error;
    if (laser_frame_ == cleanFrameId(args_.base_frame)) {
      mount_ = LaserMount();
    } else if (findBagTransform(bag_, args_.base_frame, laser_frame_, &t, &error)) {
      mount_ = mountFromTransform(t);
    } else {
      std::cerr << "dpslam_offline: warning: " << error << "; taking the laser to be at " << args_.base_frame
                << " (use --laser-pose X Y YAW to override)\n";
    }
  }
  mount_known_ = true;
}

void OfflineRun::logMatch(const LaserScan& scan, const OdometryUpdate& u, double ms) {
  char line[512];
  std::snprintf(line, sizeof(line), "%.6f,%d,%s,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.4f,%.3f,%d,%d,%d,%d,%d,%d,%d,%.4f,%.3g,%.3g,%.3g,%.4g,%.4g,%.4g,%d,%.4f,%d,%d,%d\n",
                scan.stamp, u.ok, toString(u.skip_reason), u.pose.x, u.pose.y, u.pose.theta, u.delta.x, u.delta.y,
                u.delta.theta, u.match.score_per_point, u.match.matched_fraction, u.match.degenerate, u.match.weak,
                u.match.de_generations, u.match.de_evaluations, u.match.newton_iterations, u.points_used,
                u.new_keyframe, ms, u.delta_covariance(0, 0), u.delta_covariance(1, 1), u.delta_covariance(2, 2),
                u.pose_covariance(0, 0), u.pose_covariance(1, 1), u.pose_covariance(2, 2),
                u.range_flow.valid ? u.range_flow.beams : 0, u.range_flow.valid ? u.range_flow.speed : 0.0,
                u.range_flow_applied ? 1 : 0, u.velocity_held ? 1 : 0, u.velocity_held_blank ? 1 : 0);
  match_log_ += line;
}

/// Counts the odometry's result and keeps its pose; false when the scan goes no further (no pose on the
/// outputs' time line).
bool OfflineRun::recordOdometry(const LaserScan& scan, const PreprocessedScan& pre, const OdometryUpdate& u,
                                double ms) {
  // The odometry restarted by its own time check (compared with the last scan it used): same thing.
  if (u.reset && !odom_poses_.empty()) startOver(odom_poses_.back().stamp, scan.stamp);
  if (odom_poses_.empty()) first_stamp_ = scan.stamp;
  if (!u.ok) {
    ++skipped_[pre.ok() ? toString(u.skip_reason) : "malformed_scan"];
    if (u.skip_reason == OdometrySkipReason::kTimeBackwards ||
        u.skip_reason == OdometrySkipReason::kDuplicateStamp || !pre.ok()) {
      showProgress();
      return false;
    }
  } else {
    odom_ms_.push_back(ms);
    if (!u.reset) {
      ++matched_;
      if (u.match.weak || u.match.degenerate) ++bad_;
    }
  }
  if (!odom_poses_.empty() && scan.stamp <= odom_poses_.back().stamp) {
    // Not reached since the reset above (kept as a guard): the TUM files need a monotonic time line.
    ++skipped_["time_backwards"];
    return false;
  }
  odom_poses_.push_back({scan.stamp, u.pose});
  if (refine_) refiner_.addScan(scan.stamp, u.pose, mount_.apply(pre.points), u.reset);
  odom_last_covariance_ = u.pose_covariance;
  last_stamp_ = scan.stamp;
  return true;
}

void OfflineRun::feedSlam(const LaserScan& scan, const PreprocessedScan& pre, const OdometryUpdate& u) {
  // The motion given to the SLAM: the laser odometry's, or --motion-tum's at this stamp.
  Pose2D motion_pose = u.pose;
  const bool have_motion = motion_.empty() || interpolatePose(motion_, scan.stamp, &motion_pose);
  if (!have_motion) ++skipped_["slam_outside_motion_tum"];
  // A scan not given to the SLAM adds to the next delta's covariance, composed as the node composes it.
  if (slam_) composeMotion(slam_pending_, slam_delta_cov_, u.delta, u.delta_covariance);
  if (!slam_ || !have_motion) return;
  const Pose2D delta = slam_has_last_ && !u.reset ? between(slam_last_odom_, motion_pose) : Pose2D();
  const auto s0 = std::chrono::steady_clock::now();
  HeldMotion held;
  if (slam_has_last_ && !u.reset && motion_.empty()) {
    held.direction = u.held_direction;
    held.speed_sigma = u.held_speed_sigma;
    held.dt = scan.stamp - slam_last_stamp_;
  }
  last_slam_ = slam_->process(scan.stamp, pre, mount_, delta, slam_delta_cov_, held);
  slam_last_stamp_ = scan.stamp;
  // Wall time: the SLAM scores particles on several threads.
  slam_ms_.push_back(1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count());
  if (!last_slam_.ok) ++skipped_["slam_" + last_slam_.skip_reason];
  if (!args_.slam_log.empty()) logSlam(scan.stamp);
  max_tree_nodes_ = std::max(max_tree_nodes_, last_slam_.tree_nodes);
  slam_last_odom_ = motion_pose;
  slam_pending_ = Pose2D();
  slam_delta_cov_.setZero();
  slam_has_last_ = true;
}

void OfflineRun::logSlam(double stamp) {
  char line[256];
  std::snprintf(line, sizeof(line), "%.6f,%d,%.5f,%.5f,%.5f,%.3g,%.3g,%.3g,%.2f,%d,%.3f,%d\n", stamp, last_slam_.ok,
                last_slam_.pose.x, last_slam_.pose.y, last_slam_.pose.theta, last_slam_.covariance(0, 0),
                last_slam_.covariance(1, 1), last_slam_.covariance(2, 2), last_slam_.neff, last_slam_.resampled,
                last_slam_.score_spread, last_slam_.revisit);
  slam_log_ += line;
}

void OfflineRun::logMemory(int loop, double stamp) {
  std::fprintf(memory_log_, "%d,%zu,%.6f,%.3f,%.3f,%zu,%zu,%.3f\n", loop, done_, stamp,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0_).count(), currentRssMb(),
               slam_ ? last_slam_.tree_nodes : 0, slam_ ? last_slam_.map_entries : 0,
               slam_ ? last_slam_.memory_bytes / 1048576.0 : 0.0);
}

bool OfflineRun::writeOutputs() {
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0_).count();
  const double cpu = processCpuSeconds() - cpu0_;
  const double duration = earlier_segments_ + (odom_poses_.empty() ? 0.0 : last_stamp_ - first_stamp_);
  try {
    writeFileAtomically(args_.out + "/odometry.tum", formatTum(odom_poses_));
    if (slam_) writeSlamOutputs();
    if (!args_.match_log.empty()) writeFileAtomically(args_.match_log, match_log_);
    if (!args_.slam_log.empty()) writeFileAtomically(args_.slam_log, slam_log_);
    // Last: a stats.json means the run completed and every other output was written.
    writeFileAtomically(args_.out + "/stats.json", statsJson(duration, wall, cpu));
  } catch (const std::exception& e) {
    std::cerr << "dpslam_offline: " << e.what() << "\n";
    return false;
  }
  if (!args_.quiet) {
    std::printf("dpslam_offline: %zu scans, %.1f s of data in %.2f s (%.1fx real time), odometry median %.3f ms; wrote %s\n",
                total_, duration, wall, wall > 0 ? duration / wall : 0.0, summarize(odom_ms_).median, args_.out.c_str());
  }
  return true;
}

/// The SLAM's path (refined, with the filter's own beside it) and its map.
void OfflineRun::writeSlamOutputs() {
  std::vector<StampedPose> trajectory = slam_->bestTrajectory();
  const OccupancyGridData grid = slam_->bestMap();
  std::vector<StampedPose> trajectory_filter;
  if (refine_) {
    const double r0 = processCpuSeconds();
    trajectory_filter = trajectory;
    trajectory = refiner_.refine(trajectory, &refine_stats_);
    refine_cpu_s_ = processCpuSeconds() - r0;
  }
  writeFileAtomically(args_.out + "/trajectory.tum", formatTum(trajectory));
  if (refine_) writeFileAtomically(args_.out + "/trajectory_filter.tum", formatTum(trajectory_filter));
  writeMapServerFiles(grid, args_.out + "/map.yaml");
  writeMapPng(grid, trajectory, args_.out + "/map.png");
}

std::string OfflineRun::statsJson(double duration, double wall, double cpu) const {
  std::string json = "{\n";
  json += "  \"scans\": " + std::to_string(total_) + ",\n";
  json += "  \"data_duration_s\": " + jsonNumber(duration) + ",\n";
  json += "  \"wall_s\": " + jsonNumber(wall) + ",\n";
  json += "  \"cpu_s\": " + jsonNumber(cpu) + ",\n";
  json += "  \"realtime_factor\": " + jsonNumber(wall > 0 ? duration / wall : 0.0) + ",\n";
  json += "  \"odometry_ms\": " + jsonTiming(summarize(odom_ms_)) + ",\n";
  json += "  \"slam_ms\": " + (slam_ ? jsonTiming(summarize(slam_ms_)) : std::string("null")) + ",\n";
  json += "  \"peak_rss_mb\": " + jsonNumber(peakRssMb()) + ",\n";
  json += "  \"particles\": " + std::to_string(slam_ ? configs_.slam.particles : 0) + ",\n";
  if (slam_) {
    json += "  \"tree_nodes\": " + std::to_string(last_slam_.tree_nodes) + ",\n";
    json += "  \"tree_nodes_max\": " + std::to_string(max_tree_nodes_) + ",\n";
    json += "  \"map_entries\": " + std::to_string(last_slam_.map_entries) + ",\n";
    json += "  \"slam_memory_mb\": " + jsonNumber(last_slam_.memory_bytes / 1048576.0) + ",\n";
    // The output path's refinement (refine_trajectory; after the run, not in wall_s / cpu_s).
    json += refine_ ? "  \"refinement\": {\"keyframes\": " + std::to_string(refine_stats_.keyframes) +
                          ", \"matches\": " + std::to_string(refine_stats_.match_edges) +
                          ", \"rejected_matches\": " + std::to_string(refine_stats_.rejected_matches) +
                          ", \"iterations\": " + std::to_string(refine_stats_.graph.iterations) +
                          ", \"max_shift_m\": " + jsonNumber(refine_stats_.max_shift_m) +
                          ", \"cpu_s\": " + jsonNumber(refine_cpu_s_) + "},\n"
                    : std::string("  \"refinement\": null,\n");
  }
  json += "  \"seed\": " + std::to_string(configs_.odom.seed) + ",\n";
  // The odometry's own pose uncertainty at the end (what /odom's pose covariance says): σ x, y, θ.
  json += "  \"odometry_final_sigma\": {\"x_m\": " + jsonNumber(std::sqrt(odom_last_covariance_(0, 0))) +
          ", \"y_m\": " + jsonNumber(std::sqrt(odom_last_covariance_(1, 1))) +
          ", \"theta_rad\": " + jsonNumber(std::sqrt(odom_last_covariance_(2, 2))) + "},\n";
  json += "  \"bad_match_percent\": " + jsonNumber(matched_ ? 100.0 * bad_ / matched_ : 0.0) + ",\n";
  json += "  \"resampling\": " + jsonString(resamplingMethodName(configs_.odom.resampling)) + ",\n";
  json += std::string("  \"mode\": ") + (slam_ ? "\"slam\"" : "\"odometry-only\"") + ",\n";
  json += "  \"loops\": " + std::to_string(args_.loops) + ",\n";
  json += "  \"wheel_odometry_messages\": " + std::to_string(wheel_messages_) + ",\n";
  json += "  \"time_resets\": " + std::to_string(time_resets_) + ",\n";
  json += "  \"skipped\": " + jsonCounts(skipped_) + "\n}\n";
  return json;
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parseArgs(argc, argv);
  Configs configs;
  std::vector<StampedPose> motion;
  if (!readConfigs(args, &configs) || !readMotion(args, &motion)) return 2;
  rosbag::Bag bag;
  std::FILE* memory_log = nullptr;
  if (!openFiles(args, bag, &memory_log)) return 1;
  OfflineRun run(args, configs, std::move(motion), bag, memory_log);
  if (!run.readBag()) return 1;
  return run.writeOutputs() ? 0 : 1;
}
