#include "laser_dpslam/slam/trajectory_smoother.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace laser_dpslam {

std::vector<StampedPose> smoothTrajectory(const std::vector<StampedPose>& path, const std::vector<StampedPose>& motion,
                                          double sigma_s) {
  if (path.size() != motion.size()) {
    throw std::invalid_argument("smoothTrajectory: path has " + std::to_string(path.size()) + " poses, motion " +
                                std::to_string(motion.size()));
  }
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (path[i].stamp != motion[i].stamp) {
      throw std::invalid_argument("smoothTrajectory: stamps differ at pose " + std::to_string(i));
    }
  }
  if (!(sigma_s > 0.0) || !std::isfinite(sigma_s) || path.size() < 2) return path;

  const double reach = 4.0 * sigma_s;
  std::vector<StampedPose> out(path.size());
  std::size_t lo = 0, hi = 0;  // the window [lo, hi) around i
  for (std::size_t i = 0; i < path.size(); ++i) {
    const double t = path[i].stamp;
    while (lo < i && path[lo].stamp < t - reach) ++lo;
    if (hi < i + 1) hi = i + 1;
    while (hi < path.size() && path[hi].stamp <= t + reach) ++hi;
    // Angles are averaged as offsets from pose i's own (no wrap-around inside a window).
    double sw = 0.0, sx = 0.0, sy = 0.0, st = 0.0;
    for (std::size_t j = lo; j < hi; ++j) {
      const double d = (path[j].stamp - t) / sigma_s;
      const double w = std::exp(-0.5 * d * d);
      // Neighbour j's SLAM pose carried to time i by the motion from j to i.
      const Pose2D p = path[j].pose * between(motion[j].pose, motion[i].pose);
      sw += w;
      sx += w * p.x;
      sy += w * p.y;
      st += w * normalizeAngle(p.theta - path[i].pose.theta);
    }
    out[i].stamp = t;
    out[i].pose = Pose2D{sx / sw, sy / sw, normalizeAngle(path[i].pose.theta + st / sw)};
  }
  return out;
}

}  // namespace laser_dpslam
