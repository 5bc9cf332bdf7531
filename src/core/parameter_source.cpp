#include "laser_dpslam/parameter_source.h"

#include <fstream>
#include <stdexcept>

namespace laser_dpslam {

YamlParameterSource YamlParameterSource::load(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open parameter file '" + path + "'");
  try {
    YAML::Node root = YAML::Load(in);
    if (!root.IsNull() && !root.IsMap()) {
      throw std::runtime_error("parameter file '" + path + "' is not a YAML mapping of name: value");
    }
    return YamlParameterSource(root);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error("parameter file '" + path + "' line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
}

template <class T>
bool YamlParameterSource::getScalar(const std::string& key, T& value, const char* type) const {
  if (!root_ || !root_.IsMap()) return false;
  const YAML::Node n = root_[key];
  if (!n) return false;
  try {
    value = n.as<T>();
  } catch (const YAML::Exception&) {
    throw std::invalid_argument("parameter '" + key + "' must be " + type);
  }
  return true;
}

bool YamlParameterSource::get(const std::string& key, double& value) const { return getScalar(key, value, "a number"); }
bool YamlParameterSource::get(const std::string& key, int& value) const { return getScalar(key, value, "an integer"); }
bool YamlParameterSource::get(const std::string& key, bool& value) const { return getScalar(key, value, "true or false"); }
bool YamlParameterSource::get(const std::string& key, std::string& value) const { return getScalar(key, value, "a string"); }
bool YamlParameterSource::get(const std::string& key, std::vector<double>& value) const {
  return getScalar(key, value, "a list of numbers");
}

}  // namespace laser_dpslam
