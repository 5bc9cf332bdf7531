#include "laser_dpslam/offline/trajectory_refiner.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <random>
#include <utility>

namespace laser_dpslam {

namespace {

// Information of a covariance; false when it is not symmetric positive definite.
bool informationOf(const Eigen::Matrix3d& cov, Eigen::Matrix3d* info) {
  if (!cov.allFinite()) return false;
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(0.5 * (cov + cov.transpose()));
  if (ldlt.info() != Eigen::Success || (ldlt.vectorD().array() <= 0.0).any()) return false;
  *info = ldlt.solve(Eigen::Matrix3d::Identity());
  return info->allFinite();
}

// `info` without what it says along the unit direction `d` of the translation error.
Eigen::Matrix3d withoutDirection(const Eigen::Matrix3d& info, const Eigen::Vector2d& d) {
  Eigen::Matrix3d keep = Eigen::Matrix3d::Identity();
  keep.topLeftCorner<2, 2>() -= d * d.transpose();
  return keep.transpose() * info * keep;
}

// The SLAM path's edges: consecutive keyframes (loose across the motion, where the matches are precise), and
// baselines of 2, 4, … keyframes that hold its shape at every scale. Returns the path length up to each node.
std::vector<double> addPathEdges(const std::vector<Pose2D>& slam, const TrajectoryRefinerConfig& config,
                                 std::vector<PoseGraphEdge>& edges) {
  const int n = static_cast<int>(slam.size());
  const double sa2 = config.slam_sigma_along * config.slam_sigma_along;
  const double sc2 = config.slam_sigma_across * config.slam_sigma_across;
  const double st2 = config.slam_sigma_theta * config.slam_sigma_theta;
  std::vector<double> travel(n, 0.0);  // SLAM path length up to each node
  for (int m = 1; m < n; ++m) {
    const Pose2D z = between(slam[m - 1], slam[m]);
    const double len = std::hypot(z.x, z.y);
    travel[m] = travel[m - 1] + len;
    const Eigen::Vector2d u = len > 1e-9 ? Eigen::Vector2d(z.x / len, z.y / len) : Eigen::Vector2d(1.0, 0.0);
    const Eigen::Vector2d v(-u.y(), u.x());
    // The error lives in the measurement's frame, turned by z.theta from the first keyframe's.
    const Eigen::Matrix2d r = Pose2D(0.0, 0.0, z.theta).rotation().transpose();
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    cov.topLeftCorner<2, 2>() = r * (sa2 * u * u.transpose() + sc2 * v * v.transpose()) * r.transpose();
    cov(2, 2) = st2;
    edges.push_back({m - 1, m, z, cov.inverse(), false});
    for (int k = 2; k <= config.max_baseline && m - k >= 0; k *= 2) {
      if (m % k != 0) continue;
      const Eigen::Vector3d info(1.0 / sa2, 1.0 / sa2, 1.0 / st2);
      edges.push_back({m - k, m, between(slam[m - k], slam[m]), Eigen::Matrix3d(info.asDiagonal()), false});
    }
  }
  return travel;
}

// Which keyframe pairs to match, grouped by the reference (older) keyframe: its NDT is built once.
std::vector<std::vector<int>> matchPairs(const std::vector<Pose2D>& slam, const std::vector<double>& travel,
                                         const TrajectoryRefinerConfig& config) {
  const int n = static_cast<int>(slam.size());
  std::vector<std::vector<int>> matches(n);
  for (int j = 0; j < n; ++j) {
    for (int s = 1; s <= config.sequential_matches && j - s >= 0; ++s) matches[j - s].push_back(j);
    std::vector<std::pair<double, int>> near;
    for (int i = 0; i < j - config.sequential_matches; ++i) {
      if (travel[j] - travel[i] < 2.0 * config.overlap_radius) continue;  // the same pass
      const double dist = std::hypot(slam[j].x - slam[i].x, slam[j].y - slam[i].y);
      if (dist > config.overlap_radius) continue;
      if (std::abs(normalizeAngle(slam[j].theta - slam[i].theta)) > config.overlap_max_angle) continue;
      near.emplace_back(dist, i);
    }
    std::sort(near.begin(), near.end());
    const int take = std::min<int>(config.overlap_matches, static_cast<int>(near.size()));
    for (int c = 0; c < take; ++c) matches[near[c].second].push_back(j);
  }
  return matches;
}

// The accepted matches of `matches` as edges, used across the heading and in rotation only.
void addMatchEdges(const std::vector<const RefinerKeyframe*>& kf, const std::vector<Pose2D>& slam,
                   const std::vector<std::vector<int>>& matches, const TrajectoryRefinerConfig& config,
                   std::vector<PoseGraphEdge>& edges, RefinerStats& st) {
  ScanMatcher matcher(config.matcher);
  std::mt19937_64 rng(1);  // the matcher's DE when configured; Newton alone draws nothing
  for (int i = 0; i < static_cast<int>(kf.size()); ++i) {
    if (matches[i].empty()) continue;
    matcher.setReference(kf[i]->points);
    for (const int j : matches[i]) {
      const Pose2D prior = between(slam[i], slam[j]);
      const MatchResult r = matcher.hasReference() ? matcher.match(kf[j]->points, prior, rng) : MatchResult();
      const Pose2D off = between(prior, r.pose);
      Eigen::Matrix3d info;
      if (!r.valid || r.weak || r.score_per_point < config.min_score ||
          std::hypot(off.x, off.y) > config.max_correction_xy || std::abs(off.theta) > config.max_correction_theta ||
          !informationOf(r.bounded_covariance, &info)) {
        ++st.rejected_matches;
        continue;
      }
      // Across the heading and in rotation only (see the header); along a corridor (degenerate) not across
      // the corridor's weak direction either. The error's frame is the measured pose's.
      if (r.degenerate && r.weak_direction.norm() > 0.0) {
        const Eigen::Matrix2d back = Pose2D(0.0, 0.0, r.pose.theta).rotation().transpose();
        info = withoutDirection(info, (back * r.weak_direction).normalized());
      }
      info = withoutDirection(info, Eigen::Vector2d(1.0, 0.0));
      edges.push_back({i, j, r.pose, info});
      ++st.match_edges;
    }
  }
}

// `path` with every pose moved by the correction of the keyframes around it (refined = correction ⊕ slam).
std::vector<StampedPose> applyCorrection(const std::vector<StampedPose>& path,
                                         const std::vector<const RefinerKeyframe*>& kf,
                                         const std::vector<Pose2D>& slam, const std::vector<Pose2D>& refined,
                                         RefinerStats& st) {
  const int n = static_cast<int>(kf.size());
  std::vector<StampedPose> correction(n);  // refined = correction ⊕ slam, in the map frame
  for (int m = 0; m < n; ++m) {
    correction[m] = {kf[m]->stamp, refined[m] * slam[m].inverse()};
    st.max_shift_m = std::max(st.max_shift_m, std::hypot(refined[m].x - slam[m].x, refined[m].y - slam[m].y));
  }
  std::vector<StampedPose> out = path;
  for (auto& p : out) {
    Pose2D c;  // before the first keyframe and after the last: the nearest one's
    if (!interpolatePose(correction, p.stamp, &c)) {
      c = p.stamp < correction.front().stamp ? correction.front().pose : correction.back().pose;
    }
    p.pose = c * p.pose;
  }
  return out;
}

}  // namespace

TrajectoryRefiner::TrajectoryRefiner(const TrajectoryRefinerConfig& config) : config_(config) {}

void TrajectoryRefiner::clear() {
  keyframes_.clear();
  after_reset_ = true;
}

void TrajectoryRefiner::addScan(double stamp, const Pose2D& odometry, const std::vector<Eigen::Vector2d>& points,
                                bool reset) {
  if (reset) after_reset_ = true;
  if (!after_reset_ && !keyframes_.empty()) {
    const Pose2D d = between(keyframes_.back().odometry, odometry);
    if (std::hypot(d.x, d.y) < config_.keyframe_distance && std::abs(d.theta) < config_.keyframe_angle) return;
  }
  if (points.empty()) return;  // nothing to match: the next scan with points is the keyframe
  keyframes_.push_back({stamp, odometry, points});
  after_reset_ = false;
}

std::vector<StampedPose> TrajectoryRefiner::refine(const std::vector<StampedPose>& path, RefinerStats* stats) const {
  RefinerStats st;
  std::vector<const RefinerKeyframe*> kf;  // the graph's nodes
  std::vector<Pose2D> slam;                // the SLAM's pose at each
  for (const auto& k : keyframes_) {
    Pose2D p;
    if (interpolatePose(path, k.stamp, &p)) {
      kf.push_back(&k);
      slam.push_back(p);
    }
  }
  const int n = static_cast<int>(kf.size());
  st.keyframes = n;
  if (n < 2) {
    if (stats) *stats = st;
    return path;
  }

  std::vector<PoseGraphEdge> edges;
  const std::vector<double> travel = addPathEdges(slam, config_, edges);
  st.path_edges = static_cast<int>(edges.size());
  addMatchEdges(kf, slam, matchPairs(slam, travel, config_), config_, edges, st);

  std::vector<Pose2D> refined = slam;
  st.graph = optimizePoseGraph(refined, edges, config_.graph, 0);
  std::vector<StampedPose> out = applyCorrection(path, kf, slam, refined, st);
  if (stats) *stats = st;
  return out;
}

}  // namespace laser_dpslam
