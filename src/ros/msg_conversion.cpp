#include "laser_dpslam/ros/msg_conversion.h"

#include <tf2/LinearMath/Matrix3x3.h>
#include <tf2/LinearMath/Quaternion.h>

#include <cmath>

namespace laser_dpslam {

LaserScan fromMsg(const sensor_msgs::LaserScan& msg) {
  LaserScan s;
  s.stamp = msg.header.stamp.toSec();
  s.frame_id = msg.header.frame_id;
  s.angle_min = msg.angle_min;
  s.angle_max = msg.angle_max;
  s.angle_increment = msg.angle_increment;
  s.time_increment = msg.time_increment;
  s.scan_time = msg.scan_time;
  s.range_min = msg.range_min;
  s.range_max = msg.range_max;
  s.ranges = msg.ranges;
  s.intensities = msg.intensities;
  return s;
}

sensor_msgs::LaserScan toMsg(const LaserScan& s) {
  sensor_msgs::LaserScan msg;
  msg.header.stamp.fromSec(s.stamp);
  msg.header.frame_id = s.frame_id;
  msg.angle_min = s.angle_min;
  msg.angle_max = s.angle_max;
  msg.angle_increment = s.angle_increment;
  msg.time_increment = s.time_increment;
  msg.scan_time = s.scan_time;
  msg.range_min = s.range_min;
  msg.range_max = s.range_max;
  msg.ranges = s.ranges;
  msg.intensities = s.intensities;
  return msg;
}

namespace {
Pose2D planar(double x, double y, const tf2::Quaternion& q, bool* upside_down) {
  // The laser's z axis in the parent frame: pointing down means the scan is mirrored.
  const tf2::Matrix3x3 m(q);
  const bool flipped = m[2][2] < 0.0;
  if (upside_down) *upside_down = flipped;
  // Heading of the laser's x axis projected on the plane.
  const double yaw = std::atan2(m[1][0], m[0][0]);
  return {x, y, yaw};
}
}  // namespace

Pose2D poseFromMsg(const geometry_msgs::Pose& msg, bool* upside_down) {
  tf2::Quaternion q(msg.orientation.x, msg.orientation.y, msg.orientation.z, msg.orientation.w);
  if (q.length2() < 1e-12) q = tf2::Quaternion(0, 0, 0, 1);
  q.normalize();
  return planar(msg.position.x, msg.position.y, q, upside_down);
}

Pose2D poseFromMsg(const geometry_msgs::Transform& msg, bool* upside_down) {
  tf2::Quaternion q(msg.rotation.x, msg.rotation.y, msg.rotation.z, msg.rotation.w);
  if (q.length2() < 1e-12) q = tf2::Quaternion(0, 0, 0, 1);
  q.normalize();
  return planar(msg.translation.x, msg.translation.y, q, upside_down);
}

LaserMount mountFromTransform(const geometry_msgs::Transform& msg) {
  tf2::Quaternion q(msg.rotation.x, msg.rotation.y, msg.rotation.z, msg.rotation.w);
  if (q.length2() < 1e-12) q = tf2::Quaternion(0, 0, 0, 1);
  q.normalize();
  const tf2::Matrix3x3 m(q);
  LaserMount mount;
  mount.A << m[0][0], m[0][1], m[1][0], m[1][1];
  mount.t = Eigen::Vector2d(msg.translation.x, msg.translation.y);
  return mount;
}

geometry_msgs::Pose toPoseMsg(const Pose2D& pose) {
  geometry_msgs::Pose p;
  p.position.x = pose.x;
  p.position.y = pose.y;
  p.position.z = 0.0;
  p.orientation.z = std::sin(0.5 * pose.theta);
  p.orientation.w = std::cos(0.5 * pose.theta);
  return p;
}

geometry_msgs::Transform toTransformMsg(const Pose2D& pose) {
  geometry_msgs::Transform t;
  t.translation.x = pose.x;
  t.translation.y = pose.y;
  t.translation.z = 0.0;
  t.rotation.z = std::sin(0.5 * pose.theta);
  t.rotation.w = std::cos(0.5 * pose.theta);
  return t;
}

namespace {
constexpr int kPlanarAxes[3] = {0, 1, 5};  // x, y, yaw among x, y, z, roll, pitch, yaw
}  // namespace

Eigen::Matrix3d planarCovarianceFromMsg(const boost::array<double, 36>& msg) {
  Eigen::Matrix3d cov;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) cov(r, c) = msg[kPlanarAxes[r] * 6 + kPlanarAxes[c]];
  return cov;
}

void setPlanarCovariance(const Eigen::Matrix3d& cov, boost::array<double, 36>* msg) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) (*msg)[kPlanarAxes[r] * 6 + kPlanarAxes[c]] = cov(r, c);
}

std::string cleanFrameId(const std::string& frame_id) {
  std::size_t i = 0;
  while (i < frame_id.size() && frame_id[i] == '/') ++i;
  return frame_id.substr(i);
}

}  // namespace laser_dpslam
