// DP-SLAM on top of the laser odometry (the thesis's "scan-matching motion model"): particles move by
// the scan-match delta plus noise drawn from its covariance, are weighted by the laser-penetration model
// against their own maps (one shared DpSlamMap with an ancestry tree), and are resampled when the
// effective sample size drops. The facade the offline tool and the node call. No ROS.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "laser_dpslam/common/laser_mount.h"
#include "laser_dpslam/common/pose2d.h"
#include "laser_dpslam/common/trajectory_io.h"
#include "laser_dpslam/export/occupancy_export.h"
#include "laser_dpslam/scan/scan_preprocessor.h"
#include "laser_dpslam/scan/surface_incidence.h"
#include "laser_dpslam/slam/ancestry_tree.h"
#include "laser_dpslam/slam/dpslam_map.h"
#include "laser_dpslam/slam/particle_filter.h"
#include "laser_dpslam/slam/revisit_detector.h"

namespace laser_dpslam {

class WorkerPool;

/// Every SLAM parameter; their keys, units and ranges are in the registry of dpslam_parameters.cpp.
struct DpSlamConfig {
  // --- Particle filter ---
  int particles = 30;               ///< P
  int oversampling = 4;             ///< candidate poses drawn per particle; the best by the cheap score is kept (1 = off; doc/benchmarks.md: 4 closes every loop-building seed)
  double cull_window = 0.25;        ///< m, half-width around each measured range traced by the cheap score
  double resample_threshold = 0.5;  ///< resample when Neff < this × P (1 = every update)
  ProposalNoise proposal;           ///< noise added to the scan-match delta (see ProposalNoise)
  /// Multiplies the proposal noise while the robot explores (no path of the best particle from at least
  /// revisit_min_travel ago within revisit_radius): there the particles' own maps cannot tell their spread
  /// apart, and noise only random-walks the filter away from its odometry; on revisits the full noise lets
  /// it find the older map's alignment. 1 = off.
  double explore_noise_scale = 0.25;
  double revisit_radius = 2.0;       ///< m, see explore_noise_scale
  /// On old ground (see explore_noise_scale) the map keeps what it has: scans write only cells the particle
  /// has no entry for (new space). Updated, a particle arriving 0.1-0.3 m off the old map writes its offset
  /// view over it (5.6 m ahead of itself), those fresh walls outweigh the old ones, and the filter turns
  /// along the ridge between them instead of stepping across (doc/experiments.md, 2026-12-02).
  bool revisit_freeze_map = true;
  double revisit_min_travel = 10.0;  ///< m of travel after which a stretch of path counts as old (revisitable)
  double min_travel_distance = 0.0;  ///< m; the filter updates once the robot moved this far ... (0 = off)
  double min_travel_angle = 0.0;     ///< rad; ... or turned this much since its last update (0 = off; both off = every scan)
  // --- Map ---
  double map_resolution = 0.05;    ///< m per cell
  /// The map frame's axes run along the first scan's dominant wall direction (wall_direction.h, modulo 90°)
  /// instead of the first pose's heading: the grid's rows then lie along the walls, as they would on a plan,
  /// and the first pose is (0, 0, −that angle). Only when the chords agree at least map_wall_min_strength.
  bool map_align_to_walls = true;
  double map_wall_min_strength = 0.3;  ///< [0, 1]
  double trace_max_range = 20.0;   ///< m; beams are traced this far at most, longer returns count as free space
  double no_return_range = 6.0;    ///< m; a no-return beam is free space up to min(this, the scan's range_max)
  double entry_prior_cells = 4.0;  ///< cells of distance a new cell entry starts with (DP-SLAM's prior)
  int update_beam_step = 1;        ///< every k-th beam is written into the map
  /// a power of two k: every k-th beam writes its whole path; the others write only where the beams of the
  /// coarser levels (every 2nd, 4th, ... beam) lie more than a cell apart, and near their return (1 = off).
  /// 8: a fifth less CPU on the URG-04LX, same maps; accuracy in doc/benchmarks.md ("Thinned free space")
  int free_space_beam_step = 8;
  double free_saturation_distance = 1.0;  ///< m; free cells seen without a hit over this distance are not rewritten (0 = off)
  double map_update_distance = 0.0;  ///< m travelled since the last map update before the next ... (0 = off)
  double map_update_angle = 0.0;     ///< rad turned since the last map update (0 = off; both off = every filter update)
  /// m; within this distance of a return (along its beam) distance through a cell is measured along the
  /// normal of the surface hit, in writes and scores alike (DpSlamMap::setSurfaceDepth; 0 = off)
  double surface_depth = 0.5;
  double surface_min_cos = SurfaceIncidenceConfig().min_cos;  ///< lower bound of that projection (|cos| of the incidence; grazing fits are unreliable)
  /// [0, 1]: a cell a beam stopped in keeps that surface's normal (per lineage), and distance through it counts along that
  /// normal for every beam crossing it, |cos| bounded below by this (DpSlamMap::setCellNormals; 0 = off)
  double cell_normal_min_cos = 0.2;
  /// with cell normals: a cell also keeps where along its normal the surface lies (mean of its stops), and a
  /// stop there is scored at the beam's crossing of that line, not the middle of the cell (DpSlamMap::setSurfaceOffsets)
  bool cell_surface_offsets = true;
  // --- Observation model ---
  BeamModelConfig beam;         ///< sigma, window, log floor, unknown mean free path
  int score_beam_step = 4;      ///< every k-th beam is scored (tempering and speed)
  /// every k-th beam enters the cheap score that picks among the over-sampled candidates (8: half the scored
  /// beams are enough to rank a particle's candidates; doc/benchmarks.md, "Thinned free space")
  int cull_beam_step = 8;
  double likelihood_weight = 0.5;  ///< exponent of a scan's likelihood in the weights (tempering, 0–1]
  bool score_no_return = true;  ///< no-return beams are scored too (free space up to the range)
  int min_points = 20;          ///< fewer valid returns: the scan is not used (particles still move)
  // --- Output ---
  double occupancy_stop_length = 0.1;  ///< m; occupancy = 1 − exp(−density · this)
  /// s; σ of the Gaussian window over which the output path (bestTrajectory) takes its pose from the SLAM
  /// and its short-term motion from the odometry (trajectory_smoother.h; 0 = the best particle's raw path)
  double trajectory_smoothing = 1.0;
  /// dpslam_offline: trajectory.tum is the output path refined by a pose graph of keyframe matches
  /// (trajectory_refiner.h) and trajectory_filter.tum the path as the filter left it; false = no refinement.
  /// The SLAM itself (its map, its live pose) does not use it.
  bool refine_trajectory = true;
  std::uint64_t seed = 1;              ///< random seed (same seed and input → same output)
  int threads = 2;                     ///< worker threads for scoring (results do not depend on it)

  /// Throws std::invalid_argument naming the first impossible value.
  void validate() const;
};

struct DpSlamUpdate {
  bool ok = false;               ///< false: the scan was not used (skip_reason); particles still moved
  std::string skip_reason;       ///< "malformed_scan", "too_few_points"
  double stamp = 0.0;
  Pose2D pose;                   ///< best particle, map → base_link
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  ///< weighted spread of the particles (x, y, θ)
  bool filter_updated = false;   ///< weights updated (false while below the minimum travel)
  bool map_updated = false;
  bool resampled = false;
  double neff = 0.0;             ///< effective sample size after the update
  double score_spread = 0.0;     ///< best − worst log-likelihood of this scan over the particles (weight peakiness)
  bool revisit = false;          ///< the filter update saw the robot on old ground (full proposal noise)
  std::size_t tree_nodes = 0;
  std::size_t map_entries = 0;
  std::size_t map_writes = 0;    ///< cell writes this update planned (0 when the map was not updated)
  std::size_t memory_bytes = 0;  ///< map + caches
};

/// Whether `motion` (since the last update) reaches a travel threshold: `distance` metres or `angle` radians,
/// each ignored when 0 (either alone works); with both 0, always.
bool travelThresholdReached(const Pose2D& motion, double distance, double angle);

/// Where beam `beam` of a scan (angle_min + beam·increment) starts writing free space, for
/// DpSlamConfig::free_space_beam_step = step: 0 for every step-th beam; otherwise from where the beams of
/// the coarser levels lie more than a cell apart. Every cell is then crossed by some beam, as with all beams.
double freeSpaceWriteFrom(long beam, int step, double increment, double resolution);

/// The part of a scan's motion that the odometry held rather than measured: along `direction` (unit, in the
/// previous base frame, as the delta) nothing in the scan faces the motion (a blank stretch of corridor), and
/// the motion is a held speed times dt. Its error is that speed's error, the same at every scan of the hold
/// (a bias, not noise): each particle draws one speed error when a hold starts and keeps it to the hold's
/// end, so that its path runs straight along the corridor at its own speed instead of random-walking scan by
/// scan where no scan can tell the steps apart (the particle-filter form of a constant velocity error).
struct HeldMotion {
  Eigen::Vector2d direction = Eigen::Vector2d::Zero();
  double speed_sigma = 0.0;  ///< m/s, σ of the held speed
  double dt = 0.0;           ///< s, the time the delta spans
  bool active() const { return speed_sigma > 0.0 && dt > 0.0 && direction.squaredNorm() > 0.25; }
};

class DpSlam {
 public:
  explicit DpSlam(const DpSlamConfig& config = DpSlamConfig());
  ~DpSlam();
  DpSlam(const DpSlam&) = delete;
  DpSlam& operator=(const DpSlam&) = delete;

  /// One scan. `delta`/`delta_cov`: the laser odometry's motion since the previous call (in the previous
  /// base frame) and its covariance; ignored on the first scan, which defines the map frame (= the base
  /// frame at that scan, turned to its walls with map_align_to_walls). Skipped scans still move the particles by `delta`.
  /// `held`: the delta's held component, if any (see HeldMotion).
  DpSlamUpdate process(double stamp, const PreprocessedScan& scan, const LaserMount& mount, const Pose2D& delta,
                       const Eigen::Matrix3d& delta_cov, const HeldMotion& held = HeldMotion());
  void reset();

  bool initialized() const { return initialized_; }
  Pose2D bestPose() const;
  /// The best particle's whole path: one pose per process() call since the first used scan, smoothed
  /// against the motion given to process() over `trajectory_smoothing` seconds.
  std::vector<StampedPose> bestTrajectory() const;
  /// The same path as the particle's lineage holds it (no smoothing).
  std::vector<StampedPose> bestLineagePath() const;
  /// The motion given to process(), composed, at every pose of the paths: with bestLineagePath() the input
  /// of smoothTrajectory(), so a caller holding a lock can copy both and smooth outside it.
  const std::vector<StampedPose>& motionPath() const { return motion_path_; }
  OccupancyGridData bestMap() const;
  std::vector<Pose2D> particlePoses() const;
  std::vector<double> logWeights() const { return logw_; }
  /// Each particle's held speed error, m/s along the hold's direction (HeldMotion; all 0 outside a hold).
  const std::vector<double>& heldSpeedErrors() const { return held_speed_error_; }

  const DpSlamConfig& config() const { return config_; }
  const DpSlamMap& map() const { return map_; }
  const AncestryTree& tree() const { return tree_; }
  std::size_t memoryBytes() const;

 private:
  struct BaseBeam {
    double dx, dy;  ///< unit direction in the base frame
    double range;   ///< m
    bool no_return;
    double incidence;  ///< |cos| to the surface normal at the return (1: no return / no fit)
    /// rad, that normal's direction in the base frame (NaN: no return / no fit); an angle, so that a pose
    /// only adds its heading (an atan2 per beam and particle cost 3 % of the CPU)
    double normal_angle = std::numeric_limits<double>::quiet_NaN();
    double write_from = 0.0;    ///< m; the map write starts here (free_space_beam_step)
  };
  /// A pose with its rotation, so that the cosine and sine are computed once per pose, not once per beam.
  struct PoseFrame {
    explicit PoseFrame(const Pose2D& p) : pose(p), c(std::cos(p.theta)), s(std::sin(p.theta)) {}
    Pose2D pose;
    double c, s;
  };
  void makeBeams(const PreprocessedScan& scan, const LaserMount& mount);
  MapBeam toMap(const PoseFrame& f, const BaseBeam& b) const;
  double score(const Pose2D& pose, int slot, LookupCache& cache) const;
  /// Calls f(i, beam, cache) for every item i < n and every beam of `beams`, beam by beam over a block of
  /// items (all of them on one thread, else a few blocks per worker): particles close together trace
  /// nearly the same cells, so the map memory one beam touches stays in the CPU cache from one particle to
  /// the next. Per item, the beams come in order, so per-item sums are the same as item by item.
  template <class F>
  void forEachBeamByBlock(std::size_t n, const std::vector<BaseBeam>& beams, F&& f);
  /// Fills ll[i] with score(chosen[i], slot i) for every particle, beam-major.
  void scoreAll(const std::vector<Pose2D>& chosen, std::vector<double>& ll);
  /// Fills cheap[n] with cheapScore(candidates[n], slot n / per_slot), beam-major.
  void cheapScoreAll(const std::vector<Pose2D>& candidates, int per_slot, std::vector<double>& cheap);
  /// Plans the scan writes of `who` (old particles, at `at`, seen through the scoring caches) in parallel.
  void planWrites(const std::vector<int>& who, const std::vector<Pose2D>& at);
  /// Applies the planned writes of who[s] under nodes[s] (single-threaded, in order).
  void applyWrites(const std::vector<int>& who, const std::vector<int>& nodes);
  void filterStep(double stamp, const Pose2D& delta, const Eigen::Matrix3d& cov, DpSlamUpdate& u);
  /// Steps 1-3 of filterStep: every particle's new pose into chosen, its log-likelihood there into ll.
  void propose(const Pose2D& delta, const Eigen::Matrix3d& cov, std::vector<Pose2D>& chosen,
               std::vector<double>& ll);
  /// Starts, keeps or ends the particles' held speed errors for this update (HeldMotion); returns `cov`
  /// without its variance along the held direction while holding.
  Eigen::Matrix3d startHeldMotion(const Eigen::Matrix3d& cov);
  /// Sampled candidates, the best of `oversampling` per particle by the cheap score, then scored.
  void proposeSampled(const Pose2D& delta, const Eigen::Matrix3d& L, std::vector<Pose2D>& chosen,
                      std::vector<double>& ll);
  /// Steps 5-6: the surviving lineages' scan writes when due, the ancestry tree's new generation.
  void updateMapAndTree(const Pose2D& delta, const std::vector<int>& parents, const std::vector<Pose2D>& chosen,
                        DpSlamUpdate& u);
  /// Each particle j takes its parent's pose and weight; best_ follows the best parent.
  void adoptSurvivors(const std::vector<int>& parents, const std::vector<Pose2D>& chosen, int best_parent,
                      bool resampled);
  void record(double stamp);
  void fill(DpSlamUpdate& u) const;

  DpSlamConfig config_;
  std::unique_ptr<WorkerPool> pool_;
  std::vector<LookupCache> caches_;  ///< one per worker (scoring)
  LookupCache update_cache_;
  std::vector<std::vector<DpSlamMap::CellWrite>> writes_;  ///< per particle, reused up to kKeptWrites
  static constexpr std::size_t kKeptWrites = 8192;
  GaussianSampler rng_;
  AncestryTree tree_;
  DpSlamMap map_;

  bool initialized_ = false;
  int generation_ = 0;
  std::vector<Pose2D> poses_;   ///< particle poses at their last filter update
  std::vector<int> leaves_;     ///< ancestry node of each particle
  std::vector<double> logw_;
  int best_ = 0;
  double last_neff_ = 0.0;
  Pose2D pending_;              ///< odometry motion since the last filter update (base frame then)
  Pose2D motion_;               ///< all motion given to process() since the first used scan, composed
  std::vector<StampedPose> motion_path_;  ///< motion_ at every pose of the particles' paths
  Eigen::Matrix3d pending_cov_ = Eigen::Matrix3d::Zero();
  int pending_scans_ = 0;  ///< scans whose motion pending_ composes (the proposal's noise floor is per scan)
  HeldMotion pending_held_;     ///< the held part of pending_ (direction in pending_'s start frame, dt summed)
  bool holding_ = false;        ///< the last filter update was inside a hold
  double held_scale_ = 1.0;     ///< the proposal scale the speed errors were drawn at (explore_noise_scale or 1)
  std::vector<double> held_speed_error_;  ///< per particle, m/s along the hold's direction (0 outside holds)
  Pose2D since_map_update_;     ///< filter motion since the last map update
  bool force_map_update_ = false;

  Eigen::Vector2d beam_origin_ = Eigen::Vector2d::Zero();  ///< laser position in the base frame

  std::vector<BaseBeam> score_beams_, cull_beams_, update_beams_;
  RevisitDetector revisit_;      ///< on the best particle's path: exploring or revisiting
  bool last_revisit_ = false;
};

}  // namespace laser_dpslam
