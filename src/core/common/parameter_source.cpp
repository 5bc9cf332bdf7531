#include "laser_dpslam/common/parameter_source.h"

#include <algorithm>
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

bool YamlParameterSource::lookup(const std::string& key, double& value) const { return getScalar(key, value, "a number"); }
bool YamlParameterSource::lookup(const std::string& key, int& value) const { return getScalar(key, value, "an integer"); }
bool YamlParameterSource::lookup(const std::string& key, bool& value) const { return getScalar(key, value, "true or false"); }
bool YamlParameterSource::lookup(const std::string& key, std::string& value) const { return getScalar(key, value, "a string"); }
bool YamlParameterSource::lookup(const std::string& key, std::vector<double>& value) const {
  return getScalar(key, value, "a list of numbers");
}

std::vector<std::string> YamlParameterSource::keys() const {
  std::vector<std::string> k;
  if (!root_ || !root_.IsMap()) return k;
  for (const auto& entry : root_) k.push_back(entry.first.as<std::string>());
  return k;
}

int editDistance(const std::string& a, const std::string& b) {
  std::vector<int> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = static_cast<int>(j);
  for (std::size_t i = 1; i <= a.size(); ++i) {
    int diagonal = row[0];
    row[0] = static_cast<int>(i);
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const int above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::vector<std::string> ParameterSource::unknownKeys() const {
  std::vector<std::string> messages;
  for (const std::string& key : keys()) {
    if (known_.count(key)) continue;
    std::string message = "unknown parameter '" + key + "' (ignored)";
    // A suggestion only when it is close: a third of the name's letters at most, and at least two.
    int best = std::max(2, static_cast<int>(key.size()) / 3) + 1;
    std::string closest;
    for (const std::string& k : known_) {
      const int d = editDistance(key, k);
      if (d < best) {
        best = d;
        closest = k;
      }
    }
    if (!closest.empty()) message = "unknown parameter '" + key + "' (ignored): did you mean '" + closest + "'?";
    messages.push_back(message);
  }
  return messages;
}

}  // namespace laser_dpslam
