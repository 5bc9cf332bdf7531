// A laser scan as the core sees it: sensor_msgs/LaserScan's fields without ROS.
#pragma once

#include <string>
#include <vector>

namespace laser_dpslam {

struct LaserScan {
  double stamp = 0.0;            ///< seconds (the header stamp of the message)
  std::string frame_id;          ///< as received; may have a leading slash in old bags
  double angle_min = 0.0;        ///< rad, angle of ranges[0]
  double angle_max = 0.0;        ///< rad, angle of the last beam
  double angle_increment = 0.0;  ///< rad between beams (positive: counter-clockwise)
  double time_increment = 0.0;   ///< s between beams
  double scan_time = 0.0;        ///< s between scans
  double range_min = 0.0;        ///< m
  double range_max = 0.0;        ///< m
  std::vector<float> ranges;     ///< m; REP-117: NaN = no measurement, +inf = no return, -inf = too close
  std::vector<float> intensities;
};

}  // namespace laser_dpslam
