// dpslam_node: scans + odometry (TF odom→base_link) in, map / pose / map→odom out. Thin glue around
// laser_dpslam::DpSlam; parameters are read once in readParameters().
//
// Odometry source: the TF odom→base_link at the scan's stamp (it works with laser_odometry_node, wheel
// odometry or any other source, and laser_odometry_node stamps it with the very scan time). When the
// `odom` topic carries a covariance for that stamp (laser_odometry_node does), the motion noise is the
// composition of the odometry messages' covariances since the previous scan used (motion_covariance.h);
// otherwise the motion model's parametric noise applies.
//
// CPU: a worker thread processes the scans; the scan callback only leaves the newest scan for it
// (newest_slot.h). While a step takes less than the scan period every scan is processed; when the CPU is
// short, a scan that a newer one overtakes before the worker is free is skipped (counted), the next one
// processed gets the odometry's whole motion since the last one, and map→odom lags the scan time by at most
// about one step plus one period instead of falling behind through a queue of stale scans. Processing time,
// that lag and the scans skipped go to /diagnostics (WARN while scans are skipped or the lag exceeds 1 s).
#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/GetMap.h>
#include <nav_msgs/MapMetaData.h>
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <diagnostic_updater/diagnostic_updater.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>

#include "laser_dpslam/OdometryHold.h"
#include "laser_dpslam/SaveMap.h"
#include "laser_dpslam/common/newest_slot.h"
#include "laser_dpslam/common/run_statistics.h"
#include "laser_dpslam/export/occupancy_export.h"
#include "laser_dpslam/ros/msg_conversion.h"
#include "laser_dpslam/ros/names.h"
#include "laser_dpslam/ros/ros_parameter_source.h"
#include "laser_dpslam/ros/tf_wait.h"
#include "laser_dpslam/scan/scan_preprocessor.h"
#include "laser_dpslam/slam/dpslam.h"
#include "laser_dpslam/slam/dpslam_parameters.h"
#include "laser_dpslam/slam/motion_covariance.h"
#include "laser_dpslam/slam/slam_load_monitor.h"
#include "laser_dpslam/slam/trajectory_smoother.h"

namespace laser_dpslam {

class DpSlamNode {
 public:
  DpSlamNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) : tf_listener_(tf_buffer_) {
    readParameters(pnh);
    slam_ = std::make_unique<DpSlam>(slam_config_);
    map_pub_ = nh.advertise<nav_msgs::OccupancyGrid>(names::kMapTopic, 1, true);
    metadata_pub_ = nh.advertise<nav_msgs::MapMetaData>(names::kMapMetadataTopic, 1, true);
    pose_pub_ = nh.advertise<geometry_msgs::PoseWithCovarianceStamped>(names::kPoseTopic, 10);
    path_pub_ = nh.advertise<nav_msgs::Path>(names::kTrajectoryTopic, 1, true);
    if (publish_particles_) particles_pub_ = nh.advertise<geometry_msgs::PoseArray>(names::kParticlesTopic, 1);
    scan_sub_ = nh.subscribe(names::kScanTopic, 20, &DpSlamNode::onScan, this);
    odom_sub_ = nh.subscribe(names::kOdomTopic, 50, &DpSlamNode::onOdom, this);
    held_sub_ = nh.subscribe(names::kOdometryHoldTopic, 50, &DpSlamNode::onOdometryHold, this);
    map_srv_ = nh.advertiseService(names::kDynamicMapService, &DpSlamNode::onGetMap, this);
    save_srv_ = nh.advertiseService(names::kSaveMapService, &DpSlamNode::onSaveMap, this);
    updater_.setHardwareID("none");
    updater_.add("scan processing", this, &DpSlamNode::diagnose);
    // Wall time: the status keeps coming while a bag is paused or over (ROS time then stands still).
    diagnostics_timer_ = nh.createWallTimer(ros::WallDuration(updater_.getPeriod()),
                                            [this](const ros::WallTimerEvent&) { updater_.force_update(); });
    ROS_INFO("dpslam_node: %s -> %s from TF %s -> %s, %d particles", map_frame_.c_str(), odom_frame_.c_str(),
             odom_frame_.c_str(), base_frame_.c_str(), slam_config_.particles);
    if (work_multiplier_ > 1.0) {
      ROS_WARN("dpslam_node: work_multiplier %.2f: each scan's processing is stretched as on a CPU that much slower "
               "(for benchmarks)", work_multiplier_);
    }
    worker_ = std::thread([this] { work(); });
  }

  ~DpSlamNode() {
    slot_.close();
    if (worker_.joinable()) worker_.join();
    const SlotCounts c = slot_.counts();
    if (c.skipped > 0) {
      ROS_INFO("dpslam_node: %zu of %zu scans skipped (CPU short: a newer scan arrived before they were processed)",
               c.skipped, c.offered);
    }
  }

 private:
  void readParameters(ros::NodeHandle& pnh) {
    const RosParameterSource source(pnh);
    DpSlamNodeSettings settings;
    readDpSlamNodeParameters(source, settings);
    for (const std::string& m : source.unknownKeys()) ROS_WARN("dpslam_node: %s", m.c_str());
    map_frame_ = settings.map_frame;
    odom_frame_ = settings.odom_frame;
    base_frame_ = settings.base_frame;
    map_update_interval_ = settings.map_update_interval;
    publish_particles_ = settings.publish_particles;
    transform_timeout_ = settings.transform_timeout;
    work_multiplier_ = settings.work_multiplier;
    pre_config_ = settings.preprocessing;
    slam_config_ = settings.slam;
  }

  void onOdom(const nav_msgs::Odometry::ConstPtr& msg) {
    // Keep the recent messages: their twist covariances make the motion noise up to the scan with the same stamp.
    const Eigen::Matrix3d cov = planarCovarianceFromMsg(msg->twist.covariance);
    const std::int64_t stamp = static_cast<std::int64_t>(msg->header.stamp.toNSec());
    {
      std::lock_guard<std::mutex> lock(odom_mutex_);
      if (stamp < odom_newest_ns_) odom_window_.clear();  // time went backwards: a new time line
      odom_window_.add(stamp, poseFromMsg(msg->pose.pose), cov);
      odom_newest_ns_ = stamp;
    }
    odom_arrived_.notify_all();
  }

  void onOdometryHold(const laser_dpslam::OdometryHold::ConstPtr& msg) {
    const std::int64_t stamp = static_cast<std::int64_t>(msg->header.stamp.toNSec());
    std::lock_guard<std::mutex> lock(odom_mutex_);
    if (!held_.empty() && stamp <= held_.back().first) held_.clear();  // time went backwards: a new time line
    HeldMotion h;
    h.direction = Eigen::Vector2d(msg->direction.x, msg->direction.y);
    h.speed_sigma = std::isfinite(msg->speed_sigma) ? msg->speed_sigma : 0.0;
    if (!h.direction.allFinite()) return;
    held_.emplace_back(stamp, h);
    while (held_.size() > kHeldKept) held_.pop_front();
  }

  /// The odometry's held motion at the scan `stamp` (laser_odometry_node sends it before that scan's odom
  /// message, which motionCovariance waited for), over the time since the last scan used; none when absent.
  HeldMotion heldMotion(const ros::Time& stamp) {
    const std::int64_t to = static_cast<std::int64_t>(stamp.toNSec());
    std::lock_guard<std::mutex> lock(odom_mutex_);
    HeldMotion out;
    while (!held_.empty() && held_.front().first < to) held_.pop_front();
    if (has_last_odom_ && !held_.empty() && held_.front().first == to) {
      out = held_.front().second;
      out.dt = (stamp - last_odom_stamp_).toSec();
    }
    return out;
  }

  /// Covariance of the odometry's motion from the last scan used to the one at `stamp` (zero without
  /// odometry messages carrying that stamp).
  Eigen::Matrix3d motionCovariance(const ros::Time& stamp) {
    const std::int64_t to = static_cast<std::int64_t>(stamp.toNSec());
    std::unique_lock<std::mutex> lock(odom_mutex_);
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    if (has_last_odom_) {
      const std::int64_t from = static_cast<std::int64_t>(last_odom_stamp_.toNSec());
      // laser_odometry_node sends a scan's odom message with its TF, which is here: when the messages kept
      // up until the previous scan, this one's is at most a moment behind.
      if (odom_newest_ns_ >= from && odom_newest_ns_ < to) {
        odom_arrived_.wait_for(lock, std::chrono::duration<double>(transform_timeout_),
                               [&] { return odom_newest_ns_ >= to || odom_newest_ns_ < from; });
      }
      cov = odom_window_.deltaCovariance(from, last_odom_, to);
    }
    odom_window_.dropUntil(to);
    return cov;
  }

  bool lookup(const std::string& target, const std::string& source, const ros::Time& stamp,
              geometry_msgs::TransformStamped* out, const char* what) {
    try {
      *out = lookupTransformWall(tf_buffer_, target, source, stamp, transform_timeout_);
      return true;
    } catch (const tf2::TransformException& e) {
      ROS_ERROR_THROTTLE(5.0, "dpslam_node: no transform %s -> %s at the scan's stamp (%s); scan dropped. tf2: %s",
                         target.c_str(), source.c_str(), what, e.what());
      return false;
    }
  }

  // Spinner thread: only hands the scan over; a scan still waiting for the worker is replaced (skipped).
  void onScan(const sensor_msgs::LaserScan::ConstPtr& msg) {
    {
      std::lock_guard<std::mutex> lock(load_mutex_);
      load_.received(msg->header.stamp.toSec());
    }
    slot_.put(msg);
  }

  void work() {
    sensor_msgs::LaserScan::ConstPtr msg;
    while (slot_.take(&msg)) {
      try {
        processScan(*msg);
      } catch (const std::exception& e) {
        ROS_ERROR_THROTTLE(5.0, "dpslam_node: scan at %.3f not processed: %s", msg->header.stamp.toSec(), e.what());
      }
      msg.reset();
    }
  }

  /// With work_multiplier > 1: burns (work_multiplier − 1) × the process CPU time used since cpu_start on
  /// this thread, as a CPU that many times slower would have taken (the scoring threads' time included).
  void stretch(double cpu_start) const {
    if (work_multiplier_ <= 1.0) return;
    const double extra = (work_multiplier_ - 1.0) * (processCpuSeconds() - cpu_start);
    const double t0 = threadCpuSeconds();
    while (threadCpuSeconds() - t0 < extra) {
    }
  }

  void processScan(const sensor_msgs::LaserScan& scan) {
    const ros::WallTime wall_start = ros::WallTime::now();
    const double cpu_start = processCpuSeconds();
    const std::string laser_frame = cleanFrameId(scan.header.frame_id);
    const ros::Time stamp = scan.header.stamp;
    if (!last_stamp_.isZero() && stamp < last_stamp_) {
      ROS_WARN("dpslam_node: scan time went backwards (bag looped?): SLAM reset, the map starts over");
      std::lock_guard<std::mutex> lock(mutex_);
      slam_->reset();
      has_last_odom_ = false;
      tf_buffer_.clear();
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      last_stamp_ = stamp;
    }
    geometry_msgs::TransformStamped mount_tf, odom_tf;
    if (!lookup(base_frame_, laser_frame, ros::Time(0), &mount_tf, "the static laser mount") ||
        !lookup(odom_frame_, base_frame_, stamp, &odom_tf, "the odometry; is laser_odometry_node running?")) {
      std::lock_guard<std::mutex> lock(load_mutex_);
      load_.dropped();
      return;
    }
    const LaserMount mount = mountFromTransform(mount_tf.transform);
    const Pose2D odom = poseFromMsg(odom_tf.transform);
    const Pose2D delta = has_last_odom_ ? between(last_odom_, odom) : Pose2D();
    const Eigen::Matrix3d delta_cov = motionCovariance(stamp);
    const HeldMotion held = heldMotion(stamp);
    if (held.active()) ROS_INFO_ONCE("dpslam_node: a blank stretch of corridor: the odometry's held speed (odom_held) reaches the filter");
    last_odom_ = odom;
    last_odom_stamp_ = stamp;
    has_last_odom_ = true;

    const PreprocessedScan pre = preprocessScan(fromMsg(scan), pre_config_);
    if (!pre.ok()) ROS_WARN_THROTTLE(5.0, "dpslam_node: malformed scan: %s", pre.error.c_str());
    DpSlamUpdate u;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      u = slam_->process(stamp.toSec(), pre, mount, delta, delta_cov, held);
    }
    if (!u.ok) {
      ROS_WARN_THROTTLE(5.0, "dpslam_node: scan skipped (%s)", u.skip_reason.c_str());
    }
    stretch(cpu_start);
    publishPose(stamp, u, odom);
    const double published_at = ros::Time::now().toSec();
    if (last_map_stamp_.isZero() || (stamp - last_map_stamp_).toSec() >= map_update_interval_) {
      const double cpu_map = processCpuSeconds();
      publishMap(stamp);
      stretch(cpu_map);
      last_map_stamp_ = stamp;
    }
    std::lock_guard<std::mutex> lock(load_mutex_);
    load_.processed(stamp.toSec(), (ros::WallTime::now() - wall_start).toSec(), published_at);
  }

  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
    SlamLoadReport r;
    {
      std::lock_guard<std::mutex> lock(load_mutex_);
      r = load_.report(slot_.counts().skipped);
    }
    stat.summary(r.warn ? diagnostic_msgs::DiagnosticStatus::WARN : diagnostic_msgs::DiagnosticStatus::OK, r.message);
    stat.add("scans received", r.received);
    stat.add("scans processed", r.processed);
    stat.add("scans skipped", r.skipped);
    stat.add("scans skipped since last report", r.skipped_recent);
    stat.add("scans dropped (no transform)", r.dropped);
    stat.addf("processing time last [s]", "%.4f", r.processing_s.last);
    stat.addf("processing time mean [s]", "%.4f", r.processing_s.mean);
    stat.addf("processing time max [s]", "%.4f", r.processing_s.max);
    stat.addf("map->odom lag last [s]", "%.4f", r.lag_s.last);
    stat.addf("map->odom lag mean [s]", "%.4f", r.lag_s.mean);
    stat.addf("map->odom lag max [s]", "%.4f", r.lag_s.max);
    stat.addf("map->odom lag max since last report [s]", "%.4f", r.lag_recent_max_s);
    stat.addf("newest scan ahead of map->odom [s]", "%.4f", r.backlog_s);
    if (work_multiplier_ > 1.0) stat.addf("work multiplier", "%.2f", work_multiplier_);
  }

  void publishPose(const ros::Time& stamp, const DpSlamUpdate& u, const Pose2D& odom) {
    geometry_msgs::PoseWithCovarianceStamped p;
    p.header.stamp = stamp;  // the scan's time, never now()
    p.header.frame_id = map_frame_;
    p.pose.pose = toPoseMsg(u.pose);
    setPlanarCovariance(u.covariance, &p.pose.covariance);
    pose_pub_.publish(p);

    // map→odom = map→base ⊕ (odom→base)⁻¹ (REP-105: the SLAM corrects the odometry's drift).
    geometry_msgs::TransformStamped t;
    t.header.stamp = stamp;
    t.header.frame_id = map_frame_;
    t.child_frame_id = odom_frame_;
    t.transform = toTransformMsg(u.pose * odom.inverse());
    tf_broadcaster_.sendTransform(t);

    if (publish_particles_) {
      geometry_msgs::PoseArray pa;
      pa.header = p.header;
      for (const Pose2D& q : slam_->particlePoses()) pa.poses.push_back(toPoseMsg(q));
      particles_pub_.publish(pa);
    }
  }

  nav_msgs::OccupancyGrid gridMsg(const ros::Time& stamp) {
    OccupancyGridData g;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      g = slam_->bestMap();
    }
    nav_msgs::OccupancyGrid m;
    m.header.stamp = stamp;
    m.header.frame_id = map_frame_;
    m.info.map_load_time = stamp;
    m.info.resolution = g.resolution;
    m.info.width = g.width;
    m.info.height = g.height;
    m.info.origin.position.x = g.origin_x;
    m.info.origin.position.y = g.origin_y;
    m.info.origin.orientation.w = 1.0;
    m.data = g.data;
    return m;
  }

  void publishMap(const ros::Time& stamp) {
    last_map_ = gridMsg(stamp);
    map_pub_.publish(last_map_);
    metadata_pub_.publish(last_map_.info);
    nav_msgs::Path path;
    path.header.stamp = stamp;
    path.header.frame_id = map_frame_;
    // Copy under the lock, smooth outside it: smoothing costs O(poses x window) and grows with the run,
    // and scans must not wait on it.
    std::vector<StampedPose> lineage, motion;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      lineage = slam_->bestLineagePath();
      motion = slam_->motionPath();
    }
    const std::vector<StampedPose> traj = smoothTrajectory(lineage, motion, slam_config_.trajectory_smoothing);
    for (const auto& sp : traj) {
      geometry_msgs::PoseStamped ps;
      ps.header.stamp.fromSec(sp.stamp);
      ps.header.frame_id = map_frame_;
      ps.pose = toPoseMsg(sp.pose);
      path.poses.push_back(ps);
    }
    path_pub_.publish(path);
  }

  bool onGetMap(nav_msgs::GetMap::Request&, nav_msgs::GetMap::Response& res) {
    ros::Time stamp;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stamp = last_stamp_;
    }
    res.map = gridMsg(stamp);
    return true;
  }

  bool onSaveMap(SaveMap::Request& req, SaveMap::Response& res) {
    if (req.path.empty()) {
      res.success = false;
      res.message = "empty path";
      return true;
    }
    try {
      OccupancyGridData g;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        g = slam_->bestMap();
      }
      writeMapServerFiles(g, req.path + ".yaml");
      res.success = true;
      res.message = req.path + ".yaml";
      ROS_INFO("dpslam_node: map saved to %s", res.message.c_str());
    } catch (const std::exception& e) {
      res.success = false;
      res.message = e.what();
      ROS_ERROR("dpslam_node: save_map failed: %s (any previous map file is untouched)", e.what());
    }
    return true;
  }

  std::string map_frame_, odom_frame_, base_frame_;
  double map_update_interval_ = 2.0, transform_timeout_ = 0.2, work_multiplier_ = 1.0;
  bool publish_particles_ = true;
  DpSlamConfig slam_config_;
  ScanPreprocessorConfig pre_config_;

  std::unique_ptr<DpSlam> slam_;
  std::mutex mutex_;  ///< slam_ and last_stamp_ (the worker writes them, services read them)
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  ros::Publisher map_pub_, metadata_pub_, pose_pub_, path_pub_, particles_pub_;
  ros::Subscriber scan_sub_, odom_sub_, held_sub_;
  ros::ServiceServer map_srv_, save_srv_;
  ros::WallTimer diagnostics_timer_;
  diagnostic_updater::Updater updater_;

  std::mutex odom_mutex_;  ///< odom_window_, odom_newest_ns_, held_ (the spinner writes them, the worker reads them)
  std::condition_variable odom_arrived_;
  MotionCovarianceWindow odom_window_;
  std::int64_t odom_newest_ns_ = 0;
  std::deque<std::pair<std::int64_t, HeldMotion>> held_;  ///< recent held motions by stamp (odom_mutex_)
  static constexpr std::size_t kHeldKept = 100;              ///< 10 s of scans at 10 Hz

  std::mutex load_mutex_;  ///< load_
  SlamLoadMonitor load_;
  NewestSlot<sensor_msgs::LaserScan::ConstPtr> slot_;

  // The worker's own.
  Pose2D last_odom_;
  ros::Time last_odom_stamp_, last_stamp_, last_map_stamp_;
  bool has_last_odom_ = false;
  nav_msgs::OccupancyGrid last_map_;
  std::thread worker_;  ///< last: started when everything else exists
};

}  // namespace laser_dpslam

int main(int argc, char** argv) {
  ros::init(argc, argv, "dpslam_node");
  ros::NodeHandle nh, pnh("~");
  try {
    laser_dpslam::DpSlamNode node(nh, pnh);
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("dpslam_node: %s", e.what());
    return 1;
  }
  return 0;
}
