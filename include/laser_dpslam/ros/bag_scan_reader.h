// LaserScans and TF messages read from a bag with their size checked before ROS deserializes them: a
// corrupted array length in a bag record makes the generated deserializer resize a vector to billions of
// elements (it checks the buffer only afterwards), which on a small robot computer means swapping or the
// OOM killer instead of an error message.
#pragma once

#include <nav_msgs/Odometry.h>
#include <rosbag/message_instance.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace laser_dpslam {

/// True when `size` bytes hold exactly one serialized sensor_msgs/LaserScan: every string and array
/// length fits in what is left and nothing is left over. Otherwise false, with what is wrong in *why.
bool serializedLaserScanFits(const std::uint8_t* data, std::size_t size, std::string* why);

/// The same for one serialized tf2_msgs/TFMessage (the bag's /tf_static and /tf records).
bool serializedTfMessageFits(const std::uint8_t* data, std::size_t size, std::string* why);

/// The same for one serialized nav_msgs/Odometry (wheel odometry).
bool serializedOdometryFits(const std::uint8_t* data, std::size_t size, std::string* why);

/// The bag message as a LaserScan; nullptr when it is of another type. Throws std::runtime_error saying
/// what is corrupted when the record does not hold a well-formed LaserScan (rosbag's own exceptions,
/// e.g. for a damaged chunk, pass through).
sensor_msgs::LaserScan::Ptr readLaserScan(const rosbag::MessageInstance& m);

/// The same for a tf2_msgs/TFMessage record.
tf2_msgs::TFMessage::Ptr readTfMessage(const rosbag::MessageInstance& m);

/// The same for a nav_msgs/Odometry record.
nav_msgs::Odometry::Ptr readOdometry(const rosbag::MessageInstance& m);

}  // namespace laser_dpslam
