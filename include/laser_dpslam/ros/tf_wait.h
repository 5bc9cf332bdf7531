// Waiting for a transform with a wall-clock bound. tf2_ros::Buffer::lookupTransform(…, timeout) measures
// the timeout in ROS time: under use_sim_time, once the bag stops publishing /clock, ROS time stands still
// and such a wait never ends (the node then also stops answering its services). This one cannot hang.
#pragma once

#include <geometry_msgs/TransformStamped.h>
#include <ros/time.h>
#include <tf2_ros/buffer.h>

#include <string>

namespace laser_dpslam {

/// target←source at `stamp` (ros::Time(0): the latest). Polls the buffer until it can answer or
/// `wall_timeout` seconds of wall time have passed; then throws the tf2::TransformException of the last
/// attempt (which names the frames and the reason).
geometry_msgs::TransformStamped lookupTransformWall(const tf2_ros::Buffer& buffer, const std::string& target,
                                                    const std::string& source, const ros::Time& stamp,
                                                    double wall_timeout);

}  // namespace laser_dpslam
