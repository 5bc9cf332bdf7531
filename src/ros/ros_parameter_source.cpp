#include "laser_dpslam/ros/ros_parameter_source.h"

#include <stdexcept>

namespace laser_dpslam {

template <class T>
bool RosParameterSource::getTyped(const std::string& key, T& value, const char* type) const {
  if (!nh_.hasParam(key)) return false;
  if (!nh_.getParam(key, value)) {
    throw std::invalid_argument("parameter '" + nh_.resolveName(key) + "' must be " + type);
  }
  return true;
}

bool RosParameterSource::get(const std::string& key, double& value) const { return getTyped(key, value, "a number"); }
bool RosParameterSource::get(const std::string& key, int& value) const { return getTyped(key, value, "an integer"); }
bool RosParameterSource::get(const std::string& key, bool& value) const { return getTyped(key, value, "true or false"); }
bool RosParameterSource::get(const std::string& key, std::string& value) const { return getTyped(key, value, "a string"); }
bool RosParameterSource::get(const std::string& key, std::vector<double>& value) const {
  return getTyped(key, value, "a list of numbers");
}

}  // namespace laser_dpslam
