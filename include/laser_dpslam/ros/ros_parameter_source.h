// The ROS parameter server as a ParameterSource (private namespace of a node).
#pragma once

#include <ros/node_handle.h>

#include "laser_dpslam/common/parameter_source.h"

namespace laser_dpslam {

class RosParameterSource : public ParameterSource {
 public:
  explicit RosParameterSource(const ros::NodeHandle& nh) : nh_(nh) {}
  /// The parameters directly in the node handle's namespace.
  std::vector<std::string> keys() const override;

 protected:
  bool lookup(const std::string& key, double& value) const override;
  bool lookup(const std::string& key, int& value) const override;
  bool lookup(const std::string& key, bool& value) const override;
  bool lookup(const std::string& key, std::string& value) const override;
  bool lookup(const std::string& key, std::vector<double>& value) const override;

 private:
  template <class T>
  bool getTyped(const std::string& key, T& value, const char* type) const;
  ros::NodeHandle nh_;
};

}  // namespace laser_dpslam
