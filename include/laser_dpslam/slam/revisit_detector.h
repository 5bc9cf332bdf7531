// Tells exploration from revisits along a path: a pose is a revisit when the path passed within `radius`
// of it at least `min_travel` metres of travel earlier (the robot came back to mapped ground, where a
// particle filter can correct its pose against an older part of its map). DP-SLAM uses it to scale the
// proposal noise: while exploring, the particles' spread cannot be told apart by their own fresh maps and
// only random-walks (doc/benchmarks.md). No ROS.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace laser_dpslam {

struct RevisitDetectorConfig {
  double radius = 2.0;       ///< m, a pose within this of an old path sample is a revisit
  double min_travel = 10.0;  ///< m of travel that makes a path sample "old"
  double spacing = 0.25;     ///< m of travel between stored path samples
};

class RevisitDetector {
 public:
  explicit RevisitDetector(const RevisitDetectorConfig& config = RevisitDetectorConfig());

  /// Advances the path by `travelled` metres to `position`; true when that position is a revisit (judged
  /// against the samples stored before it). Non-finite input is ignored (false).
  bool update(const Eigen::Vector2d& position, double travelled);
  void reset();

  double travel() const { return travel_; }
  std::size_t samples() const { return samples_; }

 private:
  struct Sample {
    Eigen::Vector2d position;
    double travel;
  };
  std::int64_t key(std::int64_t ix, std::int64_t iy) const { return ix * 73856093LL ^ iy * 19349663LL; }
  std::int64_t cellIndex(double v) const;

  RevisitDetectorConfig config_;
  std::unordered_map<std::int64_t, std::vector<Sample>> grid_;  ///< cells of side `radius`
  double travel_ = 0.0;
  double last_sample_travel_ = 0.0;
  std::size_t samples_ = 0;
};

}  // namespace laser_dpslam
