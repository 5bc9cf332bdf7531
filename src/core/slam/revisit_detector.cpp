#include "laser_dpslam/slam/revisit_detector.h"

#include <cmath>
#include <stdexcept>

namespace laser_dpslam {

RevisitDetector::RevisitDetector(const RevisitDetectorConfig& config) : config_(config) {
  if (!(config_.radius > 0.0) || !(config_.min_travel >= 0.0) || !(config_.spacing > 0.0)) {
    throw std::invalid_argument("RevisitDetector: radius and spacing must be > 0, min_travel >= 0");
  }
}

void RevisitDetector::reset() {
  grid_.clear();
  travel_ = 0.0;
  last_sample_travel_ = 0.0;
  samples_ = 0;
}

std::int64_t RevisitDetector::cellIndex(double v) const {
  return static_cast<std::int64_t>(std::floor(v / config_.radius));
}

bool RevisitDetector::update(const Eigen::Vector2d& position, double travelled) {
  if (!position.allFinite() || !std::isfinite(travelled) || travelled < 0.0) return false;
  travel_ += travelled;
  // Cells have the side of the radius: every sample within it lies in the 3 × 3 block around the position.
  const std::int64_t cx = cellIndex(position.x()), cy = cellIndex(position.y());
  bool revisit = false;
  for (std::int64_t dx = -1; dx <= 1 && !revisit; ++dx) {
    for (std::int64_t dy = -1; dy <= 1 && !revisit; ++dy) {
      const auto it = grid_.find(key(cx + dx, cy + dy));
      if (it == grid_.end()) continue;
      for (const Sample& s : it->second) {
        if (s.travel <= travel_ - config_.min_travel && (s.position - position).norm() < config_.radius) {
          revisit = true;
          break;
        }
      }
    }
  }
  if (samples_ == 0 || travel_ - last_sample_travel_ >= config_.spacing) {
    grid_[key(cx, cy)].push_back({position, travel_});
    last_sample_travel_ = travel_;
    ++samples_;
  }
  return revisit;
}

}  // namespace laser_dpslam
