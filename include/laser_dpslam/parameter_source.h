// Where parameters come from: a YAML file (offline tools) or the ROS parameter server (nodes). The
// core reads every parameter through this interface, so each parameter is named in one place only.
#pragma once

#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace laser_dpslam {

class ParameterSource {
 public:
  virtual ~ParameterSource() = default;
  // Each returns false when the key is absent (the default stays); throws std::invalid_argument with the
  // key's name when it is present with the wrong type.
  virtual bool get(const std::string& key, double& value) const = 0;
  virtual bool get(const std::string& key, int& value) const = 0;
  virtual bool get(const std::string& key, bool& value) const = 0;
  virtual bool get(const std::string& key, std::string& value) const = 0;
  virtual bool get(const std::string& key, std::vector<double>& value) const = 0;
};

/// Parameters from a YAML mapping (the same files as config/*.yaml).
class YamlParameterSource : public ParameterSource {
 public:
  YamlParameterSource() = default;
  explicit YamlParameterSource(const YAML::Node& root) : root_(root) {}
  /// Loads a file; throws std::runtime_error naming the file (and line) when it is missing or malformed.
  static YamlParameterSource load(const std::string& path);

  bool get(const std::string& key, double& value) const override;
  bool get(const std::string& key, int& value) const override;
  bool get(const std::string& key, bool& value) const override;
  bool get(const std::string& key, std::string& value) const override;
  bool get(const std::string& key, std::vector<double>& value) const override;

 private:
  template <class T>
  bool getScalar(const std::string& key, T& value, const char* type) const;
  YAML::Node root_;
};

}  // namespace laser_dpslam
