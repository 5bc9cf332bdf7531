// Laser odometry: every scan is matched (ScanMatcher) against a local map made of the last few
// keyframes, starting from a constant-velocity prior, so the drift grows per keyframe, not per scan.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <random>
#include <string>
#include <vector>

#include "laser_dpslam/common/laser_mount.h"
#include "laser_dpslam/common/pose2d.h"
#include "laser_dpslam/matching/scan_matcher.h"
#include "laser_dpslam/odometry/held_speed.h"
#include "laser_dpslam/odometry/range_flow.h"
#include "laser_dpslam/scan/saliency_resampler.h"
#include "laser_dpslam/scan/scan_preprocessor.h"
#include "laser_dpslam/scan/scan_resampler.h"

namespace laser_dpslam {

struct LaserOdometryConfig {
  ResamplingMethod resampling = ResamplingMethod::kSaliency;  ///< points used to match each scan
  int resampling_budget = 100;       ///< points kept for the DE search
  int polish_budget = 0;             ///< points (spatially uniform) for the Newton polish; 0 = all valid points
  SaliencyConfig saliency;
  ScanMatcherConfig matcher;
  double keyframe_distance = 0.25;   ///< m moved since the last keyframe before a new one is taken
  double keyframe_angle = 0.17;      ///< rad turned since the last keyframe before a new one is taken
  int local_map_keyframes = 10;      ///< keyframes in the local map (10 × 0.25 m: scripts/benchmark_loop.sh, CSAIL)
  /// m/s²; > 0: the constant-velocity prior enters the Newton polish as a Gaussian on the translation with
  /// σ = ½·a·dt² (the displacement an unmodelled acceleration a causes over the scan interval dt), see
  /// ScanMatcher::match. 0 = off.
  double prior_acceleration = 2.0;
  /// A new keyframe is also taken when the matched fraction fell this much below the first match after the
  /// last keyframe: new structure came into view that the local map lacks (0 = off). Without it a robot whose
  /// estimate stalls in a corridor never takes the keyframe that would show it the wall ahead.
  double keyframe_overlap_drop = 0.1;
  /// [0, 1]: kVelocityGain along the unconstrained direction of a degenerate match (corridor), where the
  /// match's motion is mostly the prior plus the score's ripple; < kVelocityGain averages that ripple
  /// over more scans. Negative = kVelocityGain. Applies only to short-range lasers (below).
  double degenerate_velocity_gain = 0.1;
  /// m; degenerate_velocity_gain applies when the scan's effective range_max is at most this (0 = always).
  /// A short-range laser sees little along a corridor and the ripple dominates (CSAIL cut to 5.6 m: SLAM
  /// error −39 %); a long-range one sees far structure and real speed changes (full-range CSAIL: worse).
  double degenerate_velocity_max_range = 10.0;
  /// [0, 1]; > 0: where a degenerate match (same range gate) has lines in view that face along its weak
  /// direction (a niche, a door frame, a pillar), the speed along that direction is also measured from how
  /// their ranges changed since the previous scan (measureRangeFlow). When two consecutive flows agree and
  /// their mean is more than 3σ + 0.02 m/s from the velocity, the velocity moves this fraction towards it,
  /// instead of degenerate_velocity_gain or the hold: the local-map match cannot tell a robot that stopped
  /// from one that drives on (with the hold the estimate drove on at the old speed), the previous scan can.
  /// 0 = off.
  double range_flow_gain = 0.3;
  RangeFlowConfig range_flow;
  /// m/s; > 0: while the estimated speed is below this, a degenerate (corridor) match may drop the motion
  /// prior when the scan fits clearly better without it (ScanMatcher::kPriorReleaseMargin). Starting
  /// from rest in a corridor, the prior says "at rest" and the smoothed velocity catches up slowly: the
  /// loop building's start lost 0.6–1.2 m in 5 s (0.04–0.12 m with it; scripts/benchmark_loop.sh). 0 = off.
  double prior_release_speed = 0.15;
  double map_voxel = 0.05;           ///< m, voxel size of the local map's points
  /// Match in a frame whose axes run along the first scan's walls (dominantWallDirection, modulo 90°), when
  /// that scan shows a clear direction (strength ≥ wall_alignment_min_strength); outputs stay in the odom
  /// frame (the first pose). NDT's cells are axis-aligned, and with walls oblique to them the match drifts
  /// more along corridors: on the loop building started a few degrees off the walls, odometry ATE mean
  /// 0.187 m over seeds 1–12, 0.092 m with this on (doc/experiments.md). With walls lying exactly on a 5 cm
  /// lattice (a simulated plan, a start on a pixel) the estimate's ~0.3° error made the 0.05 m DE raster drift:
  /// on by default together with the DE raster's 0.03 m spacing (ScanMatcher::kRasterResolution).
  bool align_to_walls = true;
  double wall_alignment_min_strength = 0.3;  ///< [0, 1]
  int min_points = 20;               ///< fewer valid points: the scan is skipped
  double max_prior_gap = 1.0;        ///< s; a longer gap between scans gives a zero-velocity prior
  std::uint64_t seed = 1;            ///< seed of the DE random generator
};

/// Why a scan was skipped, or why the odometry started over (kTimeBackwards: the scan is then used).
enum class OdometrySkipReason { kNone, kTooFewPoints, kMalformedScan, kTimeBackwards, kDuplicateStamp, kMatchFailed };

/// "" for kNone, else "too_few_points", "malformed_scan", "time_backwards", "duplicate_stamp", "match_failed":
/// the words the logs, the match log and stats.json use.
const char* toString(OdometrySkipReason reason);

/// What one scan produced.
struct OdometryUpdate {
  bool ok = false;                    ///< false: the scan was skipped (see skip_reason); pose propagated
  OdometrySkipReason skip_reason = OdometrySkipReason::kNone;
  bool reset = false;                 ///< the odometry was reset (first scan, or time went backwards)
  double stamp = 0.0;
  Pose2D pose;                        ///< odom → base_link
  Eigen::Matrix3d pose_covariance = Eigen::Matrix3d::Zero();
  Pose2D delta;                       ///< motion since the previous scan, in the previous base frame
  Eigen::Matrix3d delta_covariance = Eigen::Matrix3d::Identity();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  ///< (vx, vy, ω) in the base frame
  MatchResult match;                  ///< its pose and weak_direction are in the matching frame (frameAngle())
  RangeFlow range_flow;               ///< the speed along match.weak_direction from the range flow (range_flow_gain)
  bool range_flow_applied = false;    ///< it (with the previous scan's) refuted the velocity and moved it
  /// The velocity along match.weak_direction was held (velocityAlongCorridor): the pose's variance along it
  /// grows with the time held.
  bool velocity_held = false;
  bool velocity_held_blank = false;  ///< no surface in the scan faces along the corridor: the match kept the prior along it
  /// A held velocity in a blank stretch (velocity_held and velocity_held_blank, laser only): the held
  /// direction (unit, previous base frame, as delta) and the held speed's σ (m/s). The delta's error along it
  /// is that speed's error times dt, the same at every scan of the stretch: a bias, not noise (DpSlam's
  /// HeldMotion). Zero otherwise.
  Eigen::Vector2d held_direction = Eigen::Vector2d::Zero();
  double held_speed_sigma = 0.0;
  bool wheel_prior = false;           ///< the motion prior was the wheel odometry's (addWheelOdometry)
  bool new_keyframe = false;
  int points_used = 0;
};

class LaserOdometry {
 public:
  /// Weight of the newest scan-to-scan translation velocity in the constant-velocity prior (exponential
  /// smoothing per scan). The last motion alone (1) feeds each match's small bias along a corridor straight
  /// back into the next prior: on the generated buildings the odometry's drift median went 0.33 / 0.34 % →
  /// 0.54 / 0.65 % (search seeds 1 / 2, doc/experiments.md "Which corridor rules earn their place").
  static constexpr double kVelocityGain = 0.3;

  explicit LaserOdometry(const LaserOdometryConfig& config = LaserOdometryConfig());

  /// Processes one preprocessed scan (laser frame) with the laser's mount on the robot.
  OdometryUpdate process(const PreprocessedScan& scan, const LaserMount& mount);

  /// Forgets everything (next scan starts at the identity). Wheel odometry samples are kept: they are a time
  /// line of their own (addWheelOdometry).
  void reset();

  /// A wheel odometry pose (in the wheels' own fixed frame) at `stamp`. From then on the wheels' motion
  /// between two scan stamps replaces the constant-velocity prediction, and along a direction the scan does
  /// not constrain (a corridor) the match keeps it: the laser decides wherever it sees structure, the wheels
  /// carry the robot where it does not. A stamp not after the last sample's starts a new time line.
  /// False (the sample ignored) when the stamp or the pose is not finite.
  bool addWheelOdometry(double stamp, const Pose2D& pose);

  /// odom → base_link (the odom frame is the first pose).
  Pose2D pose() const { return toOdom(pose_); }
  /// rad: the matching frame is the odom frame turned by this (align_to_walls; 0 otherwise).
  double frameAngle() const { return frame_angle_; }
  const LaserOdometryConfig& config() const { return config_; }
  std::size_t keyframes() const { return keyframes_.size(); }

 private:
  struct Keyframe {
    Pose2D pose;
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  ///< of `pose`, odom frame
    std::vector<Eigen::Vector2d> points;  ///< in the matching frame (the odom frame unless align_to_walls)
    NdtView view;                         ///< where the laser saw them from, matching frame
  };
  struct WheelSample {
    double stamp;
    Pose2D pose;
  };
  void addKeyframe(const std::vector<Eigen::Vector2d>& base_points, const PreprocessedScan& scan,
                   const LaserMount& mount);
  /// The wheels' motion from stamp `from` to `to` (in the robot's frame at `from`), interpolated between
  /// samples; false when the samples do not cover that interval.
  bool wheelMotion(double from, double to, Pose2D* motion) const;
  /// The wheel pose at `t` (interpolated, or extrapolated a little past the last sample); false outside.
  bool wheelPoseAt(double t, Pose2D* pose) const;
  /// The motion prior from the last scan to `stamp`: the wheels' when they cover it, else constant velocity.
  Pose2D priorDelta(double stamp, bool* from_wheels) const;
  /// process() in the matching frame: u.pose, u.pose_covariance and pose_ are in it.
  OdometryUpdate processInFrame(const PreprocessedScan& scan, const LaserMount& mount);
  /// A scan with nothing to match: the pose moves by the motion prior, u says why.
  void propagateUnmatched(const PreprocessedScan& scan, OdometryUpdate& u);
  /// The first usable scan: the matching frame, the first keyframe.
  void start(const PreprocessedScan& scan, const LaserMount& mount, const std::vector<Eigen::Vector2d>& base_points,
             OdometryUpdate& u);
  /// The corridor handling (hold, degenerate gain, blank stretches) is for lasers up to
  /// degenerate_velocity_max_range.
  bool shortRange(const PreprocessedScan& scan) const;
  /// Whether the scan, at the prior's heading, shows no surface facing along the last match's weak direction
  /// (a blank stretch of corridor): then the match keeps the prior along it.
  bool blankAlongCorridor(const std::vector<Eigen::Vector2d>& base_points, const Pose2D& prior) const;
  /// Cuts a degenerate match's step along its weak direction to kDegenerateStepSigmas · prior_sigma from the prior.
  static void limitDegenerateStep(const Pose2D& prior, double prior_sigma, MatchResult& m);
  /// Keeps the poses of constrained matches on the straight run; at a blank stretch's first scan, the held speed.
  void seeAlongCorridor(double stamp, double dt, const OdometryUpdate& u);
  void holdSpeedFromSeenMatches(double stamp, const Eigen::Vector2d& weak);
  /// The scan's match against the local map from `prior`, into u.match (and u.points_used).
  void matchToLocalMap(const PreprocessedScan& scan, const LaserMount& mount,
                       const std::vector<Eigen::Vector2d>& base_points, const Pose2D& prior, double dt,
                       OdometryUpdate& u);
  /// u.delta_covariance and pose_covariance_ from the match, `previous` the pose before it.
  void matchCovariances(const Pose2D& previous, OdometryUpdate& u);
  /// velocity_ (and the range flow) after a match `dt` after the last one.
  void updateVelocity(const PreprocessedScan& scan, const LaserMount& mount, const Pose2D& previous, double dt,
                      OdometryUpdate& u);
  /// Where the velocity was held: the pose's variance along the weak direction grows with the time held,
  /// as that velocity's error does.
  void heldCovariance(const Pose2D& previous, double stamp, double dt, OdometryUpdate& u);
  /// velocity_ along a degenerate match's weak direction. Once a match has fixed every direction, a degenerate
  /// match leaves the velocity along its weak direction as it was, with no time limit, as a constant-velocity
  /// model keeps a velocity nothing observes: where nothing along a corridor is in range each match pulls a
  /// little back towards the local map, and taken into the velocity that slows the estimate scan after scan
  /// (the loop building's west corridor lost 0.10-0.36 m; a 10 s limit stalled the estimate in the generated
  /// buildings' longer corridors, doc/experiments.md). Only the range flow moves it (a stop or a start seen
  /// against the previous scan), and a released prior ends the hold (the scan refuted that velocity). Before
  /// any constrained match, or after a release, degenerate_velocity_gain smooths it instead.
  void velocityAlongCorridor(const PreprocessedScan& scan, const LaserMount& mount, const Pose2D& previous,
                             double dt, const Eigen::Vector2d& before, const Eigen::Vector3d& measured,
                             OdometryUpdate& u);
  /// The pose has moved or turned far enough from the newest keyframe, or the overlap with it dropped.
  bool keyframeDue(const MatchResult& match);
  /// A pose of the matching frame in the odom frame.
  Pose2D toOdom(const Pose2D& p) const { return Pose2D(0.0, 0.0, -frame_angle_) * p; }

  LaserOdometryConfig config_;
  ScanMatcher matcher_;
  std::mt19937_64 rng_;
  bool initialized_ = false;
  double last_stamp_ = 0.0;
  Pose2D pose_;  ///< in the matching frame (the odom frame turned by frame_angle_)
  double frame_angle_ = 0.0;  ///< rad, see frameAngle()
  Eigen::Matrix3d pose_covariance_ = Eigen::Matrix3d::Zero();
  Eigen::Vector3d velocity_ = Eigen::Vector3d::Zero();  ///< base frame, per second
  std::deque<Keyframe> keyframes_;
  // Blank stretches of corridor (doc/algorithms.md §6, doc/experiments.md "Blank stretches told by the
  // surfaces facing along them"). Less than this much surface facing along the corridor (m) is a blank
  // stretch: about one door jamb's face; on the generated buildings' blank corridors the scans show none.
  static constexpr double kMinFacingLength = 0.1;
  // A degenerate match moves the pose along its weak direction by at most this many prior σ from the prior.
  static constexpr double kDegenerateStepSigmas = 3.0;
  // s of constrained matches the held speed is fitted to, and the shortest window tried. Their positions
  // jitter by 1-2 cm, so a 3 s fit was several per cent off; over 12 s a 40 m blank corridor ends within
  // 0.5 % (doc/experiments.md, "The held speed fitted to the matches that measured it").
  static constexpr double kHoldSpeedWindow = 12.0;
  static constexpr double kMinHoldSpeedWindow = 0.5;
  // The window's two halves agree within this fraction of the speed plus kHoldSpeedAgreementMin (m/s).
  static constexpr double kHoldSpeedAgreement = 0.03;
  static constexpr double kHoldSpeedAgreementMin = 0.005;
  static constexpr double kNoStamp = -1e300;  ///< held_since_ / fitted_through_: none
  /// A match neither degenerate nor weak has measured the velocity since the start, a gap or a released
  /// prior: degenerate matches hold it along their weak direction (velocityAlongCorridor).
  bool velocity_measured_ = false;
  double held_since_ = kNoStamp;  ///< stamp of the first scan of the current hold (none: not holding)
  double held_start_variance_ = 0.0;  ///< m², the pose's variance along the held direction then
  PreprocessedScan previous_scan_;  ///< the last scan matched (range_flow_gain)
  RangeFlow last_flow_;              ///< the range flow measured with the last scan (invalid: none)
  Eigen::Vector2d last_flow_direction_ = Eigen::Vector2d::Zero();  ///< its direction (the match's weak direction, matching frame)
  Eigen::Vector2d last_weak_ = Eigen::Vector2d::Zero();  ///< the last match's weak direction if it was degenerate (matching frame), else 0
  std::deque<std::pair<double, Pose2D>> seen_along_;  ///< stamped poses of constrained matches on the current straight run
  double fitted_through_ = kNoStamp;  ///< stamp of the newest pose the last held speed was fitted to
  HeldSpeed held_speed_;  ///< the held speed of the current straight run, fit by fit
  bool was_blank_ = false;  ///< the last scan was in a blank stretch (velocity_held_blank)
  double keyframe_matched_ = -1.0;  ///< matched fraction of the first match after the last keyframe (-1: none yet)
  std::uint64_t scan_count_ = 0;
  std::deque<WheelSample> wheels_;  ///< wheel odometry since shortly before the last scan (addWheelOdometry)
};

}  // namespace laser_dpslam
