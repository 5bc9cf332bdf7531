// Global refinement of a finished SLAM path (offline): a pose graph over keyframes (Lu & Milios 1997,
// "Globally consistent range scan alignment") whose edges are
//  - the SLAM path's own relative poses, between consecutive keyframes and at baselines 2, 4, … 1024
//    keyframes: the filter's map keeps its path globally consistent and right in scale, so its shape is
//    held at every scale, not only link by link;
//  - NDT matches (Newton from the SLAM's relative pose) of each keyframe with its predecessors and with the
//    older keyframes it overlaps, used across the robot's heading and in rotation only: along the heading a
//    scan-to-scan match is pulled toward no motion (measured on the loop building: 1-5 cm per match along
//    corridors, 0.2 % elsewhere), where the SLAM path is not.
// A particle filter corrects a drift only where it notices it (at a loop's closure) and the map it wrote
// before stays bent; the graph spreads the correction by each measurement's weight. Every pose of the path
// then moves with the correction of the keyframes around it. No ROS.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "laser_dpslam/common/pose2d.h"
#include "laser_dpslam/common/trajectory_io.h"
#include "laser_dpslam/matching/scan_matcher.h"
#include "laser_dpslam/offline/pose_graph.h"

namespace laser_dpslam {

struct TrajectoryRefinerConfig {
  double keyframe_distance = 0.2;   ///< m, odometry travel between keyframes ...
  double keyframe_angle = 0.1;      ///< rad, ... or rotation
  int sequential_matches = 3;       ///< each keyframe is matched to this many predecessors ...
  int overlap_matches = 4;          ///< ... and to at most this many older keyframes of another pass (nearest first)
  double overlap_radius = 1.5;      ///< m, within this distance (SLAM poses), another pass = ≥ 2× this of travel ago
  double overlap_max_angle = 0.8;   ///< rad, and this heading difference
  double min_score = 0.25;          ///< [0, 1] a match scoring less per point is not used (real scans: 0.2-0.3)
  double max_correction_xy = 0.3;   ///< m, a match further than this from the SLAM's relative pose is not used
  double max_correction_theta = 0.1;  ///< rad, the same for the heading
  double slam_sigma_along = 0.01;   ///< m, σ of the SLAM path's relative pose along its motion (every baseline: x and y)
  double slam_sigma_across = 0.05;  ///< m, σ across the motion, consecutive keyframes (the matches fix it)
  double slam_sigma_theta = 0.02;   ///< rad, σ of the SLAM path's relative heading (every baseline)
  int max_baseline = 1024;          ///< keyframes, longest baseline of the SLAM path's edges (powers of 2)
  ScanMatcherConfig matcher;        ///< the keyframe matcher (no DE: the SLAM's relative pose is the start)
  PoseGraphOptions graph;
  TrajectoryRefinerConfig() { matcher.use_de = false; }
};

struct RefinerKeyframe {
  double stamp = 0.0;
  Pose2D odometry;                      ///< odometry pose (keyframe spacing only)
  std::vector<Eigen::Vector2d> points;  ///< the scan's returns in the robot (base) frame
};

struct RefinerStats {
  int keyframes = 0;              ///< keyframes in the graph (within the path's time span)
  int path_edges = 0;             ///< edges from the SLAM path
  int match_edges = 0;            ///< accepted matches
  int rejected_matches = 0;       ///< weak, low score or too far from the SLAM's relative pose
  PoseGraphResult graph;
  double max_shift_m = 0.0;       ///< largest translation of a keyframe by the refinement
};

class TrajectoryRefiner {
 public:
  explicit TrajectoryRefiner(const TrajectoryRefinerConfig& config = TrajectoryRefinerConfig());

  /// One scan: `odometry` its odometry pose, `points` its returns in the base frame, `reset` the odometry
  /// started over (its frame jumped). Keeps a keyframe when the odometry moved keyframe_distance or turned
  /// keyframe_angle since the last one (always after a reset); a scan without points is never one.
  void addScan(double stamp, const Pose2D& odometry, const std::vector<Eigen::Vector2d>& points, bool reset);

  /// `path` (sorted by stamp) with every pose moved by the correction that the graph found for the
  /// keyframes around it (interpolated in time; the nearest keyframe's before the first and after the last).
  /// Fewer than two keyframes within `path`'s span: `path` unchanged. Deterministic.
  std::vector<StampedPose> refine(const std::vector<StampedPose>& path, RefinerStats* stats = nullptr) const;

  void clear();
  const std::vector<RefinerKeyframe>& keyframes() const { return keyframes_; }
  const TrajectoryRefinerConfig& config() const { return config_; }

 private:
  TrajectoryRefinerConfig config_;
  std::vector<RefinerKeyframe> keyframes_;
  bool after_reset_ = true;
};

}  // namespace laser_dpslam
