// dpslam_node: scans + odometry (TF odom→base_link) in, map / pose / map→odom out. Thin glue around
// laser_dpslam::DpSlam; parameters are read once in readParameters().
//
// Odometry source: the TF odom→base_link at the scan's stamp (it works with laser_odometry_node, wheel
// odometry or any other source, and laser_odometry_node stamps it with the very scan time). When the
// `odom` topic carries a covariance for that stamp (laser_odometry_node does), it is used as the motion
// noise; otherwise the motion model's parametric noise applies.
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

#include <deque>
#include <memory>
#include <mutex>

#include "laser_dpslam/SaveMap.h"
#include "laser_dpslam/slam/dpslam.h"
#include "laser_dpslam/slam/dpslam_parameters.h"
#include "laser_dpslam/export/occupancy_export.h"
#include "laser_dpslam/ros/msg_conversion.h"
#include "laser_dpslam/ros/names.h"
#include "laser_dpslam/ros/ros_parameter_source.h"
#include "laser_dpslam/ros/tf_wait.h"
#include "laser_dpslam/scan/scan_preprocessor.h"
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
    map_srv_ = nh.advertiseService(names::kDynamicMapService, &DpSlamNode::onGetMap, this);
    save_srv_ = nh.advertiseService(names::kSaveMapService, &DpSlamNode::onSaveMap, this);
    ROS_INFO("dpslam_node: %s -> %s from TF %s -> %s, %d particles", map_frame_.c_str(), odom_frame_.c_str(),
             odom_frame_.c_str(), base_frame_.c_str(), slam_config_.particles);
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
    pre_config_ = settings.preprocessing;
    slam_config_ = settings.slam;
  }

  void onOdom(const nav_msgs::Odometry::ConstPtr& msg) {
    // Keep the recent twist covariances by stamp: the motion noise of the scan with the same stamp.
    odom_cov_.push_back(msg);
    while (odom_cov_.size() > 50) odom_cov_.pop_front();
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

  void onScan(const sensor_msgs::LaserScan::ConstPtr& msg) {
    const std::string laser_frame = cleanFrameId(msg->header.frame_id);
    const ros::Time stamp = msg->header.stamp;
    if (!last_stamp_.isZero() && stamp < last_stamp_) {
      ROS_WARN("dpslam_node: scan time went backwards (bag looped?): SLAM reset, the map starts over");
      slam_->reset();
      has_last_odom_ = false;
      tf_buffer_.clear();
    }
    last_stamp_ = stamp;
    geometry_msgs::TransformStamped mount_tf, odom_tf;
    if (!lookup(base_frame_, laser_frame, ros::Time(0), &mount_tf, "the static laser mount")) return;
    if (!lookup(odom_frame_, base_frame_, stamp, &odom_tf, "the odometry; is laser_odometry_node running?")) return;
    const LaserMount mount = mountFromTransform(mount_tf.transform);
    const Pose2D odom = poseFromMsg(odom_tf.transform);
    const Pose2D delta = has_last_odom_ ? between(last_odom_, odom) : Pose2D();
    Eigen::Matrix3d delta_cov = Eigen::Matrix3d::Zero();
    const double dt = has_last_odom_ ? (stamp - last_odom_stamp_).toSec() : 0.0;
    for (const auto& o : odom_cov_) {
      if (o->header.stamp == stamp && dt > 0) {
        const int idx[3] = {0, 1, 5};
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) delta_cov(r, c) = o->twist.covariance[idx[r] * 6 + idx[c]] * dt * dt;
      }
    }
    last_odom_ = odom;
    last_odom_stamp_ = stamp;
    has_last_odom_ = true;

    const PreprocessedScan pre = preprocessScan(fromMsg(*msg), pre_config_);
    if (!pre.ok()) ROS_WARN_THROTTLE(5.0, "dpslam_node: malformed scan: %s", pre.error.c_str());
    DpSlamUpdate u;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      u = slam_->process(stamp.toSec(), pre, mount, delta, delta_cov);
    }
    if (!u.ok) {
      ROS_WARN_THROTTLE(5.0, "dpslam_node: scan skipped (%s)", u.skip_reason.c_str());
    }
    publishPose(stamp, u, odom);
    if (last_map_stamp_.isZero() || (stamp - last_map_stamp_).toSec() >= map_update_interval_) {
      publishMap(stamp);
      last_map_stamp_ = stamp;
    }
  }

  void publishPose(const ros::Time& stamp, const DpSlamUpdate& u, const Pose2D& odom) {
    geometry_msgs::PoseWithCovarianceStamped p;
    p.header.stamp = stamp;  // the scan's time, never now()
    p.header.frame_id = map_frame_;
    p.pose.pose = toPoseMsg(u.pose);
    const int idx[3] = {0, 1, 5};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) p.pose.covariance[idx[r] * 6 + idx[c]] = u.covariance(r, c);
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
    res.map = gridMsg(last_stamp_);
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
  double map_update_interval_ = 2.0, transform_timeout_ = 0.2;
  bool publish_particles_ = true;
  DpSlamConfig slam_config_;
  ScanPreprocessorConfig pre_config_;

  std::unique_ptr<DpSlam> slam_;
  std::mutex mutex_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  ros::Publisher map_pub_, metadata_pub_, pose_pub_, path_pub_, particles_pub_;
  ros::Subscriber scan_sub_, odom_sub_;
  ros::ServiceServer map_srv_, save_srv_;
  std::deque<nav_msgs::Odometry::ConstPtr> odom_cov_;
  Pose2D last_odom_;
  ros::Time last_odom_stamp_, last_stamp_, last_map_stamp_;
  bool has_last_odom_ = false;
  nav_msgs::OccupancyGrid last_map_;
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
