// laser_odometry_node: scans in, odom→base_link (TF) and nav_msgs/Odometry out. Thin glue around
// laser_dpslam::LaserOdometry; parameters are read once in readParameters().
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <memory>

#include "laser_dpslam/OdometryHold.h"
#include "laser_dpslam/common/run_statistics.h"
#include "laser_dpslam/odometry/laser_odometry.h"
#include "laser_dpslam/odometry/odometry_parameters.h"
#include "laser_dpslam/ros/msg_conversion.h"
#include "laser_dpslam/ros/names.h"
#include "laser_dpslam/ros/ros_parameter_source.h"
#include "laser_dpslam/ros/tf_wait.h"
#include "laser_dpslam/scan/scan_preprocessor.h"

namespace laser_dpslam {

class LaserOdometryNode {
 public:
  LaserOdometryNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) : tf_listener_(tf_buffer_) {
    readParameters(pnh);
    odometry_ = std::make_unique<LaserOdometry>(odom_config_);
    odom_pub_ = nh.advertise<nav_msgs::Odometry>(names::kOdomTopic, 20);
    held_pub_ = nh.advertise<laser_dpslam::OdometryHold>(names::kOdometryHoldTopic, 20);
    scan_sub_ = nh.subscribe(names::kScanTopic, 20, &LaserOdometryNode::onScan, this);
    if (use_wheel_odometry_) {
      wheel_sub_ = nh.subscribe(names::kWheelOdomTopic, 100, &LaserOdometryNode::onWheelOdometry, this);
      ROS_INFO("laser_odometry_node: wheel odometry from '%s'", wheel_sub_.getTopic().c_str());
    }
    ROS_INFO("laser_odometry_node: publishing %s -> %s from '%s' (resampling %s, %d points)", odom_frame_.c_str(),
             base_frame_.c_str(), scan_sub_.getTopic().c_str(), resamplingMethodName(odom_config_.resampling),
             odom_config_.resampling_budget);
  }

 private:
  void readParameters(ros::NodeHandle& pnh) {
    try {
      const RosParameterSource source(pnh);
      OdometryNodeSettings settings;
      readOdometryNodeParameters(source, settings);
      for (const std::string& m : source.unknownKeys()) ROS_WARN("laser_odometry_node: %s", m.c_str());
      base_frame_ = settings.base_frame;
      odom_frame_ = settings.odom_frame;
      publish_tf_ = settings.publish_tf;
      transform_timeout_ = settings.transform_timeout;
      use_wheel_odometry_ = settings.use_wheel_odometry;
      odom_config_ = settings.odometry;
      pre_config_ = settings.preprocessing;
    } catch (const std::exception& e) {
      ROS_FATAL("laser_odometry_node: %s", e.what());
      throw;
    }
  }

  /// The static base→laser mount; false (with a throttled error naming the frames) until TF has it.
  bool lookupMount(const std::string& laser_frame, const ros::Time& stamp) {
    if (mount_known_ && laser_frame == mount_frame_) return true;
    if (laser_frame == base_frame_) {
      mount_ = LaserMount();
    } else {
      try {
        const auto t = lookupTransformWall(tf_buffer_, base_frame_, laser_frame, stamp, transform_timeout_);
        mount_ = mountFromTransform(t.transform);
      } catch (const tf2::TransformException& e) {
        // Static transforms are valid at any time: try the latest one before giving up.
        try {
          const auto t = tf_buffer_.lookupTransform(base_frame_, laser_frame, ros::Time(0));
          mount_ = mountFromTransform(t.transform);
        } catch (const tf2::TransformException&) {
          ROS_ERROR_THROTTLE(5.0,
                             "laser_odometry_node: no transform %s -> %s yet (the static TF of the laser mount: "
                             "is a static_transform_publisher running?); dropping scans until it appears. tf2: %s",
                             base_frame_.c_str(), laser_frame.c_str(), e.what());
          ++dropped_without_tf_;
          return false;
        }
      }
    }
    if (dropped_without_tf_ > 0) {
      ROS_INFO("laser_odometry_node: transform %s -> %s found after dropping %d scans", base_frame_.c_str(),
               laser_frame.c_str(), dropped_without_tf_);
      dropped_without_tf_ = 0;
    }
    mount_known_ = true;
    mount_frame_ = laser_frame;
    return true;
  }

  void onWheelOdometry(const nav_msgs::Odometry::ConstPtr& msg) {
    if (!odometry_->addWheelOdometry(msg->header.stamp.toSec(), poseFromMsg(msg->pose.pose))) {
      ROS_WARN_THROTTLE(5.0, "laser_odometry_node: wheel odometry with a non-finite pose or stamp ignored");
      return;
    }
    if (++wheel_messages_ == 1) ROS_INFO("laser_odometry_node: first wheel odometry message received");
  }

  void onScan(const sensor_msgs::LaserScan::ConstPtr& msg) {
    const std::string laser_frame = cleanFrameId(msg->header.frame_id);
    if (laser_frame.empty()) {
      ROS_ERROR_THROTTLE(5.0, "laser_odometry_node: scan without frame_id; dropped");
      return;
    }
    if (!lookupMount(laser_frame, msg->header.stamp)) return;

    const double t0 = threadCpuSeconds();
    const PreprocessedScan pre = preprocessScan(fromMsg(*msg), pre_config_);
    if (!pre.ok()) {
      ROS_WARN_THROTTLE(5.0, "laser_odometry_node: malformed scan skipped: %s", pre.error.c_str());
    }
    const OdometryUpdate u = odometry_->process(pre, mount_);
    const double ms = 1e3 * (threadCpuSeconds() - t0);

    if (u.skip_reason == OdometrySkipReason::kTimeBackwards) {
      ROS_WARN("laser_odometry_node: scan time went backwards (bag looped?): odometry reset to the identity");
    } else if (!u.ok) {
      ROS_WARN_THROTTLE(5.0, "laser_odometry_node: scan skipped (%s, %zu valid beams); pose propagated",
                        toString(u.skip_reason), pre.counts.valid);
      if (u.skip_reason == OdometrySkipReason::kDuplicateStamp) return;  // nothing new to publish for this time
    }
    ROS_DEBUG("laser_odometry_node: score %.3f matched %.2f%s%s DE %d evals, %.3f ms", u.match.score_per_point,
              u.match.matched_fraction, u.match.degenerate ? " degenerate" : "", u.match.weak ? " weak" : "",
              u.match.de_evaluations, ms);
    publish(*msg, u);
  }

  void publish(const sensor_msgs::LaserScan& scan, const OdometryUpdate& u) {
    // Outputs carry the scan's stamp (never now()): correct under bag replay and sim time.
    nav_msgs::Odometry odom;
    odom.header.stamp = scan.header.stamp;
    odom.header.frame_id = odom_frame_;
    odom.child_frame_id = base_frame_;
    odom.pose.pose = toPoseMsg(u.pose);
    odom.twist.twist.linear.x = u.velocity.x();
    odom.twist.twist.linear.y = u.velocity.y();
    odom.twist.twist.angular.z = u.velocity.z();
    // 6×6 (x, y, z, roll, pitch, yaw) with the planar 3×3 in it. Unused axes get a large variance so that
    // consumers (robot_localization) ignore them.
    const double dt = scan.scan_time > 0 ? scan.scan_time : 0.1;
    for (int i = 0; i < 6; ++i) {
      odom.pose.covariance[i * 6 + i] = 1e6;
      odom.twist.covariance[i * 6 + i] = 1e6;
    }
    setPlanarCovariance(u.pose_covariance, &odom.pose.covariance);
    setPlanarCovariance(u.delta_covariance / (dt * dt), &odom.twist.covariance);
    if (u.held_speed_sigma > 0.0) {
      // Before the odom message: dpslam_node reads it once that message (and the TF) is in.
      laser_dpslam::OdometryHold held;
      held.header.stamp = scan.header.stamp;
      held.header.frame_id = base_frame_;
      held.direction.x = u.held_direction.x();
      held.direction.y = u.held_direction.y();
      held.speed_sigma = u.held_speed_sigma;
      held_pub_.publish(held);
    }
    odom_pub_.publish(odom);

    if (publish_tf_) {
      geometry_msgs::TransformStamped t;
      t.header = odom.header;
      t.child_frame_id = base_frame_;
      t.transform = toTransformMsg(u.pose);
      tf_broadcaster_.sendTransform(t);
    }
  }

  // Parameters.
  std::string base_frame_, odom_frame_;
  bool publish_tf_ = true;
  double transform_timeout_ = 0.2;
  bool use_wheel_odometry_ = false;
  LaserOdometryConfig odom_config_;
  ScanPreprocessorConfig pre_config_;

  // State.
  std::unique_ptr<LaserOdometry> odometry_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  ros::Publisher odom_pub_;
  ros::Publisher held_pub_;
  ros::Subscriber scan_sub_;
  ros::Subscriber wheel_sub_;
  std::size_t wheel_messages_ = 0;
  LaserMount mount_;
  bool mount_known_ = false;
  std::string mount_frame_;
  int dropped_without_tf_ = 0;
};

}  // namespace laser_dpslam

int main(int argc, char** argv) {
  ros::init(argc, argv, "laser_odometry_node");
  ros::NodeHandle nh, pnh("~");
  try {
    laser_dpslam::LaserOdometryNode node(nh, pnh);
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("laser_odometry_node: %s", e.what());
    return 1;
  }
  return 0;
}
