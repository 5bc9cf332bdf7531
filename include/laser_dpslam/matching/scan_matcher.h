// Scan matching of a scan against a reference point set (a keyframe or a local map): NDT score
// (Biber & Straßer) searched by Differential Evolution in a window around a motion prior, then polished
// by Newton steps on the exact score, coarse to fine. Returns the pose, an honest covariance and the
// thesis's quality figures.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <random>
#include <vector>

#include "laser_dpslam/common/pose2d.h"
#include "laser_dpslam/matching/differential_evolution.h"
#include "laser_dpslam/matching/ndt_grid.h"
#include "laser_dpslam/matching/ndt_score_raster.h"

namespace laser_dpslam {

struct ScanMatcherConfig {
  std::vector<double> cell_sizes{1.0, 0.5};  ///< m, NDT resolutions, coarse to fine; DE runs on the first
  NdtGridConfig ndt;                         ///< cell_size is overwritten by each of cell_sizes

  // Differential Evolution (doc/algorithms.md §3).
  bool use_de = true;                 ///< false: Newton from the prior only (for comparison)
  int de_population = 20;             ///< NP
  int de_generations = 30;            ///< G, upper bound
  double de_CR = 0.9;                 ///< crossover rate
  double window_xy = 0.3;             ///< m, half-width of the search window around the prior
  double window_theta = 0.26;         ///< rad, half-width of the search window (≈ 15°)
  double de_spread_xy = 0.01;         ///< m, stop when the population spread is below this …
  double de_spread_theta = 0.005;     ///< rad, … and this
  int de_stall_generations = 8;       ///< stop after this many generations without improvement

  // Newton polish on h (doc/algorithms.md §2).
  int newton_iterations = 10;         ///< per resolution
  /// m / rad, step size at which Newton stops: 0.1 mm is a fiftieth of the 5 mm σ floor, and 1e-5 took 15 %
  /// more instructions for no gain on the generated buildings (doc/experiments.md).
  double newton_tolerance = 1e-4;

  // Covariance and quality.
  double covariance_scale = 4.0;        ///< α in Σ = α·H⁻¹ + Σ_min (h is not a normalised likelihood)
  double min_sigma_xy = 0.005;          ///< m, standard deviation floor
  double min_sigma_theta = 0.002;       ///< rad, standard deviation floor
  double degeneracy_ratio = 0.02;       ///< eigenvalue of H's translation block below this × its largest: degenerate
  double degenerate_sigma = 0.3;        ///< m, σ added along a degenerate translation direction
  /// m, the same when the soft motion prior took part in the match (match()'s prior_sigma_xy > 0): the prior then
  /// holds that direction to about its own σ per scan, and a σ of 0.3 m per scan let the DP-SLAM's
  /// particles random-walk along corridors (doc/benchmarks.md).
  double degenerate_sigma_with_prior = 0.02;
  double weak_score = 0.25;             ///< score per point (0…1) below which the match is weak
  double weak_matched_fraction = 0.5;   ///< matched fraction below which the match is weak
  double weak_inflation = 10.0;         ///< covariance multiplier for a weak match
  /// > 0: a weak match is retried from the prior itself and by DE over ±rescue_window_theta; a retry
  /// replaces it only when its score per point is higher by more than this. 0 = no retry. It removes the
  /// odometry's turn failures (MIT CSAIL at 4.7 Hz, an in-place turn of the loop building); see doc/benchmarks.md.
  double rescue_margin = 0.05;
  double rescue_window_theta = 0.79;    ///< rad, θ half-width of the retry's DE window (≈ 45°)
};

struct MatchResult {
  bool valid = false;                         ///< false: nothing to match against or no points
  Pose2D pose;                                ///< pose of the scan's frame in the reference frame
  /// α·H⁻¹ + Σ_min (inflated when weak or degenerate). Where H is singular or indefinite it is huge along
  /// that direction ("unknown"): the SLAM's proposal uses it so (it caps the σ itself).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  /// The same with |H|'s eigenvalues and within the search window (boundedByWindow): what the odometry's
  /// pose covariance is built from (the newest keyframe's covariance plus this).
  Eigen::Matrix3d bounded_covariance = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d hessian = Eigen::Matrix3d::Zero();  ///< of h at the optimum (finest resolution)
  double score_per_point = 0.0;   ///< −h / (4·points) in [0, 1]: 1 = every point on a cell mean
  double matched_fraction = 0.0;  ///< points within 3σ of a cell
  bool degenerate = false;        ///< a direction is unconstrained (corridor, single wall)
  Eigen::Vector2d weak_direction = Eigen::Vector2d::Zero();  ///< unit, reference frame: that direction (when degenerate)
  bool weak = false;              ///< low score or low overlap
  bool prior_released = false;    ///< the motion prior was dropped (kPriorReleaseMargin)
  int de_generations = 0;
  int de_evaluations = 0;
  int newton_iterations = 0;
};

class ScanMatcher {
 public:
  explicit ScanMatcher(const ScanMatcherConfig& config = ScanMatcherConfig());

  /// Builds the NDT grids and the DE raster of the reference (points in the reference frame; `views`:
  /// where they were seen from, NdtGrid::build).
  void setReference(const std::vector<Eigen::Vector2d>& points, const std::vector<NdtView>& views = {});
  bool hasReference() const;

  /// Matches `points` (in the scan's own frame) starting from `prior`.
  MatchResult match(const std::vector<Eigen::Vector2d>& points, const Pose2D& prior, std::mt19937_64& rng) const {
    return match(points, points, prior, rng);
  }

  /// DE searches with `search_points` (a resampled subset: the cost is evaluated hundreds of times);
  /// the Newton polish, the covariance and the quality use `polish_points` (more points: the precision
  /// of the estimate grows with them, and Newton needs only a few evaluations).
  /// `prior_sigma_xy` > 0: the Newton polish minimises h + α/2·|t − t_prior|²/σ² (a Gaussian motion prior of
  /// this σ on the translation, in h's units through Σ = α·H⁻¹): where the scan constrains the pose the data
  /// wins, along a corridor the prior does, with no hard degeneracy threshold. ≤ 0: no prior.
  /// `allow_prior_release`: a degenerate match may drop that prior (kPriorReleaseMargin).
  /// `hold_prior_when_degenerate`: along a degenerate direction keep the prior exactly (the prior is a
  /// measurement there: wheel odometry, or a blank stretch of corridor).
  /// `unconstrained` (non-zero, with the hold): a translation direction the caller knows the scan does not
  /// measure (a blank stretch: nothing along it in view). The prior is kept along it and the match is
  /// reported degenerate along it even where the Hessian's ratio test passes: a few far returns at grazing
  /// incidence give the score a curvature there that is noise, not a measurement.
  MatchResult match(const std::vector<Eigen::Vector2d>& search_points, const std::vector<Eigen::Vector2d>& polish_points,
                    const Pose2D& prior, std::mt19937_64& rng, double prior_sigma_xy = 0.0,
                    bool allow_prior_release = false, bool hold_prior_when_degenerate = false,
                    const Eigen::Vector2d& unconstrained = Eigen::Vector2d::Zero()) const;

  /// Newton polish only, from `start`, on resolution level `level` (exposed for tests). With `basis`
  /// (3×k, orthonormal columns) the steps stay in the subspace it spans. `final_score`: the level's NDT
  /// score (without the prior's term) at the returned pose, with derivatives.
  Pose2D polish(const std::vector<Eigen::Vector2d>& points, const Pose2D& start, std::size_t level,
                int* iterations = nullptr, const Eigen::Matrix<double, 3, Eigen::Dynamic>* basis = nullptr,
                const Pose2D* prior = nullptr, double prior_sigma_xy = 0.0, NdtScore* final_score = nullptr) const;

  const ScanMatcherConfig& config() const { return config_; }
  const NdtGrid& grid(std::size_t level) const { return grids_.at(level); }

  /// `cov` (a match's, or the same rotated into another frame) scaled down to what the search window
  /// alone says: σ ≤ w/√3. Where the Hessian is singular or indefinite (a polish stopped on a ridge of h,
  /// a scene that does not fix the heading) MatchResult::covariance has σ of metres to tens of radians
  /// along that direction; the SLAM's proposal uses that direction as it is (it caps the σ itself), a pose
  /// covariance accumulated over a run should not carry it (LaserOdometry).
  Eigen::Matrix3d boundedByWindow(const Eigen::Matrix3d& cov) const;

 private:
  // m, sample spacing of the score raster DE evaluates (NdtScoreRaster): finer than the 5 cm lattice that
  // floor plans' walls often lie on. At 0.05 m a matching frame a few tenths of a degree off such walls made
  // the search drift along corridors; 0.03 m costs about a third more odometry CPU (doc/benchmarks.md).
  static constexpr double kRasterResolution = 0.03;
  // Prior release (where the caller allows it, LaserOdometryConfig::prior_release_speed): a degenerate match
  // held by the soft motion prior is polished again without it, and that pose replaces it when its score per
  // point is higher by more than kPriorReleaseMargin and it lies more than kPriorReleaseSigmas prior σ away
  // along the weak direction: the prior, not the scan, was wrong (a robot starting to move). 0.004 also fired
  // on scan noise while standing still, 0.005 did not in 42 standing tests of 30 s
  // (LaserOdometry.PriorReleaseDoesNotFireWhileStandingStill).
  static constexpr double kPriorReleaseMargin = 0.005;
  static constexpr double kPriorReleaseSigmas = 3.0;
  /// The Newton step at s (the Hessian made positive definite), within `basis`'s span when given.
  static Eigen::Vector3d newtonStep(const NdtScore& s, const Eigen::Matrix<double, 3, Eigen::Dynamic>* basis);
  /// What the steps of one match() share.
  struct MatchInput {
    const std::vector<Eigen::Vector2d>& search_points;
    const std::vector<Eigen::Vector2d>& polish_points;
    const Pose2D& prior;
    double prior_sigma_xy;
    double n;  ///< polish_points.size()
    Eigen::Vector2d unconstrained;  ///< unit direction the scan is known not to measure, or zero
  };
  /// DE over ±w around the prior on the raster, the prior seeded into the population; counts into r.
  Pose2D deSearch(const MatchInput& in, const Eigen::Vector3d& w, std::mt19937_64& rng, MatchResult& r) const;
  /// Newton polish coarse to fine from `pose`, its exact score at the finest level into *s.
  Pose2D polishAll(const MatchInput& in, Pose2D pose, NdtScore* s, MatchResult& r, bool with_prior = true) const;
  static double scorePerPoint(const MatchInput& in, const NdtScore& s);
  bool isWeak(const MatchInput& in, const NdtScore& s) const;
  /// The polish from the prior replaces *pose when it is lower in h plus the prior's term.
  void polishFromPrior(const MatchInput& in, Pose2D* pose, NdtScore* s, MatchResult& r) const;
  /// The prior and a wider DE search, polished; one replaces *pose when it scores clearly better.
  void rescueWeak(const MatchInput& in, const std::mt19937_64& rng, Pose2D* pose, NdtScore* s, MatchResult& r) const;
  /// Where *s is degenerate: *pose moved back to the prior along the weak direction, re-polished across it.
  void keepPriorAlongWeak(const MatchInput& in, Pose2D* pose, NdtScore* s, MatchResult& r) const;
  /// The polish without the prior replaces *pose when it scores clearly better far enough along `weak`.
  void releasePrior(const MatchInput& in, const Eigen::Vector2d& weak, double prior_sigma, Pose2D* pose, NdtScore* s,
                    MatchResult& r) const;
  Eigen::Matrix3d covarianceFrom(const Eigen::Matrix3d& hessian, bool with_prior, const Eigen::Vector2d& unconstrained,
                                 MatchResult& result) const;
  /// True when H's translation block has a direction the scan barely constrains (degeneracy_ratio); that
  /// direction (unit) into *weak.
  bool degenerate(const Eigen::Matrix3d& hessian, Eigen::Vector2d* weak) const;
  /// degenerate(), or else `unconstrained` when non-zero (a direction the caller knows is not measured).
  bool weakDirection(const Eigen::Matrix3d& hessian, const Eigen::Vector2d& unconstrained, Eigen::Vector2d* weak) const;
  /// Weight w of the motion prior's penalty ½·w·|xy − prior|² in h's units (Σ = α·H⁻¹ ⇒ information α⁻¹·H);
  /// 0 without a prior.
  double priorWeight(double prior_sigma_xy) const {
    return prior_sigma_xy > 0.0 ? config_.covariance_scale / (prior_sigma_xy * prior_sigma_xy) : 0.0;
  }

  ScanMatcherConfig config_;
  std::vector<NdtGrid> grids_;
  NdtScoreRaster raster_;
};

}  // namespace laser_dpslam
