#include "laser_dpslam/ros/ros_parameter_source.h"

#include <set>
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

bool RosParameterSource::lookup(const std::string& key, double& value) const { return getTyped(key, value, "a number"); }
bool RosParameterSource::lookup(const std::string& key, int& value) const { return getTyped(key, value, "an integer"); }
bool RosParameterSource::lookup(const std::string& key, bool& value) const { return getTyped(key, value, "true or false"); }
bool RosParameterSource::lookup(const std::string& key, std::string& value) const { return getTyped(key, value, "a string"); }
bool RosParameterSource::lookup(const std::string& key, std::vector<double>& value) const {
  return getTyped(key, value, "a list of numbers");
}

std::vector<std::string> RosParameterSource::keys() const {
  std::vector<std::string> names;
  nh_.getParamNames(names);
  const std::string prefix = nh_.getNamespace() + "/";
  std::set<std::string> keys;
  for (const std::string& n : names) {
    if (n.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string rest = n.substr(prefix.size());
    keys.insert(rest.substr(0, rest.find('/')));
  }
  return std::vector<std::string>(keys.begin(), keys.end());
}

}  // namespace laser_dpslam
