// Static transforms stored in a bag (/tf_static, and /tf for old bags): what the offline tools use
// instead of a TF listener.
#pragma once

#include <geometry_msgs/Transform.h>
#include <rosbag/bag.h>

#include <string>

namespace laser_dpslam {

/// Finds parent→child in the bag's /tf_static and /tf messages (first occurrence of each edge), walking
/// a chain of edges if needed. Frame ids are compared without leading slashes. Returns false (and says
/// which frames it saw, and any damaged TF records it skipped, in `error`) when there is no path.
bool findBagTransform(rosbag::Bag& bag, const std::string& parent, const std::string& child,
                      geometry_msgs::Transform* out, std::string* error);

}  // namespace laser_dpslam
