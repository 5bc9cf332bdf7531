// Where parameters come from: a YAML file (offline tools) or the ROS parameter server (nodes). The
// core reads every parameter through this interface, so each parameter is named in one place only.
#pragma once

#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace laser_dpslam {

class ParameterSource {
 public:
  virtual ~ParameterSource() = default;
  // Each returns false when the key is absent (the default stays); throws std::invalid_argument with the
  // key's name when it is present with the wrong type. Every key asked for counts as known (unknownKeys).
  template <class T>
  bool get(const std::string& key, T& value) const {
    known_.insert(key);
    return lookup(key, value);
  }

  /// Keys the caller reads by other means (a node's own settings), so that they count as known.
  void markKnown(const std::vector<std::string>& keys) const { known_.insert(keys.begin(), keys.end()); }
  /// The keys the source holds (top level).
  virtual std::vector<std::string> keys() const = 0;
  /// The keys asked for or marked so far.
  const std::set<std::string>& knownKeys() const { return known_; }
  /// One message per key the source holds that nobody asked for (a misspelt or retired parameter would
  /// otherwise be silently ignored), naming the closest known key when one is close.
  std::vector<std::string> unknownKeys() const;

 protected:
  virtual bool lookup(const std::string& key, double& value) const = 0;
  virtual bool lookup(const std::string& key, int& value) const = 0;
  virtual bool lookup(const std::string& key, bool& value) const = 0;
  virtual bool lookup(const std::string& key, std::string& value) const = 0;
  virtual bool lookup(const std::string& key, std::vector<double>& value) const = 0;

 private:
  mutable std::set<std::string> known_;
};

/// Edit distance (insertions, deletions, substitutions) between two strings.
int editDistance(const std::string& a, const std::string& b);

/// Parameters from a YAML mapping (the same files as config/*.yaml).
class YamlParameterSource : public ParameterSource {
 public:
  YamlParameterSource() = default;
  explicit YamlParameterSource(const YAML::Node& root) : root_(root) {}
  /// Loads a file; throws std::runtime_error naming the file (and line) when it is missing or malformed.
  static YamlParameterSource load(const std::string& path);

  std::vector<std::string> keys() const override;

 protected:
  bool lookup(const std::string& key, double& value) const override;
  bool lookup(const std::string& key, int& value) const override;
  bool lookup(const std::string& key, bool& value) const override;
  bool lookup(const std::string& key, std::string& value) const override;
  bool lookup(const std::string& key, std::vector<double>& value) const override;

 private:
  template <class T>
  bool getScalar(const std::string& key, T& value, const char* type) const;
  YAML::Node root_;
};

}  // namespace laser_dpslam
