// Conversions between ROS messages and the core's types: the only unit that knows both.
#pragma once

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Transform.h>
#include <sensor_msgs/LaserScan.h>

#include <Eigen/Core>
#include <boost/array.hpp>

#include "laser_dpslam/common/laser_mount.h"
#include "laser_dpslam/common/laser_scan.h"
#include "laser_dpslam/common/pose2d.h"

namespace laser_dpslam {

LaserScan fromMsg(const sensor_msgs::LaserScan& msg);
sensor_msgs::LaserScan toMsg(const LaserScan& scan);

/// Planar part of a 3D pose (yaw of the quaternion). `upside_down` is set when the z axis points down
/// (roll or pitch near pi): an upside-down laser has its beam angles mirrored.
Pose2D poseFromMsg(const geometry_msgs::Pose& msg, bool* upside_down = nullptr);
Pose2D poseFromMsg(const geometry_msgs::Transform& msg, bool* upside_down = nullptr);

/// The laser's mount from the 3D base→laser transform (handles upside-down lasers, see LaserMount).
LaserMount mountFromTransform(const geometry_msgs::Transform& msg);

geometry_msgs::Pose toPoseMsg(const Pose2D& pose);
geometry_msgs::Transform toTransformMsg(const Pose2D& pose);

/// The planar (x, y, yaw) block of a ROS 6×6 covariance (x, y, z, roll, pitch, yaw): rows and columns 0, 1, 5.
Eigen::Matrix3d planarCovarianceFromMsg(const boost::array<double, 36>& msg);
/// Writes `cov` into that block of `msg`, leaving its other entries as they are.
void setPlanarCovariance(const Eigen::Matrix3d& cov, boost::array<double, 36>* msg);

/// tf2 rejects frame ids with a leading slash (old bags: "/laser"); strip it.
std::string cleanFrameId(const std::string& frame_id);

}  // namespace laser_dpslam
