#include "laser_dpslam/ros/tf_wait.h"

#include <ros/duration.h>
#include <ros/time.h>
#include <tf2/exceptions.h>

#include <algorithm>

namespace laser_dpslam {

geometry_msgs::TransformStamped lookupTransformWall(const tf2_ros::Buffer& buffer, const std::string& target,
                                                    const std::string& source, const ros::Time& stamp,
                                                    double wall_timeout) {
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(std::max(0.0, wall_timeout));
  for (;;) {
    // canTransform without a timeout never blocks; lookupTransform then gives the exception text.
    if (buffer.canTransform(target, source, stamp) || ros::WallTime::now() >= deadline) {
      return buffer.lookupTransform(target, source, stamp);
    }
    ros::WallDuration(0.002).sleep();
  }
}

}  // namespace laser_dpslam
