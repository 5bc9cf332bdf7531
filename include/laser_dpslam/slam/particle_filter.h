// Particle-filter building blocks used by DpSlam: a portable seeded Gaussian sampler, the scan-match
// proposal, log-weight normalisation with the effective sample size, low-variance resampling and the
// weighted spread of the particles. No ROS.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <vector>

#include "laser_dpslam/common/pose2d.h"

namespace laser_dpslam {

/// Uniform and standard-normal variates from a std::mt19937_64, by portable code (53-bit uniforms,
/// Box–Muller), so the same seed gives the same numbers everywhere.
class GaussianSampler {
 public:
  explicit GaussianSampler(std::uint64_t seed = 1) : rng_(seed) {}
  void seed(std::uint64_t s) {
    rng_.seed(s);
    has_spare_ = false;
  }
  double uniform();  ///< [0, 1)
  double normal();   ///< N(0, 1)

 private:
  std::mt19937_64 rng_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

/// The proposal's noise: Σ = F·(scale·Σ_Δ)·F + diag(min_xy², min_xy², min_θ²) + diag((k_xy·|t|)², (k_xy·|t|)², (k_θ·|Δθ|)²),
/// with |t| the translation and |Δθ| the rotation of the delta, and F a diagonal scaling that brings the
/// standard deviations of scale·Σ_Δ down to at most max_sigma_xy / max_sigma_theta (correlations kept), so
/// that a wild covariance from a failed match cannot scatter the particles. With bounded_by_wheels the whole Σ,
/// floors included, is then cut to the wheels' error along every direction (boundedByWheels). Returns the lower Cholesky
/// factor L (Σ = L·Lᵀ); an invalid Σ_Δ (not finite or not positive semi-definite) is replaced by its
/// diagonal's absolute values.
struct ProposalNoise {
  double covariance_scale = 1.0;  ///< multiplies the scan matcher's covariance
  double min_sigma_xy = 0.01;     ///< m
  double min_sigma_theta = 0.005; ///< rad
  double sigma_xy_per_m = 0.0;    ///< m of standard deviation per m travelled
  double sigma_theta_per_rad = 0.0;  ///< rad of standard deviation per rad turned
  double max_sigma_xy = 0.1;      ///< m, cap of the scan matcher's translation standard deviation
  double max_sigma_theta = 0.1;   ///< rad, cap of the scan matcher's rotation standard deviation
  /// The odometry fuses wheel odometry: the particles never spread beyond the wheels' error (wheel_motion.h).
  /// The floors hedge against an optimistic scan match; where the wheels know the motion better than the floor
  /// (along a corridor, at rest) the floor's spread is only a random walk the map cannot take back.
  bool bounded_by_wheels = false;
};
Eigen::Matrix3d proposalFactor(const Pose2D& delta, const Eigen::Matrix3d& delta_cov, const ProposalNoise& noise,
                               int scans = 1);

/// One draw of the motion: delta + L·n (n ~ N(0, I)), to be applied in the particle's own frame.
Pose2D sampleMotion(const Pose2D& delta, const Eigen::Matrix3d& L, GaussianSampler& rng);

/// Normalised weights w_i ∝ exp(logw_i − max), the effective sample size 1 / Σ w_i² and the index of the
/// largest weight (the first one on ties). Non-finite log-weights count as −∞; if all are, weights are uniform.
struct NormalizedWeights {
  std::vector<double> w;
  double neff = 0.0;
  int best = 0;
};
NormalizedWeights normalizeLogWeights(const std::vector<double>& logw);

/// Low-variance (systematic) resampling: n draws at (u0 + k) / n, k = 0…n−1, on the cumulative weights;
/// u0 ∈ [0, 1). Returns, for each new particle, the index of its parent (non-decreasing).
std::vector<int> lowVarianceResample(const std::vector<double>& w, std::size_t n, double u0);

/// The held speed errors (HeldMotion) after a resampling: particle j of the new generation descends from
/// parents[j]; a parent's first child keeps its error, its other children take, in random order, the errors
/// of the particles left without a child. The set of errors is the one drawn at the hold's start. Where no
/// scan can place the particles along a corridor, resampling selects on their other coordinates, and
/// inheriting the errors as they are let a few of them survive by chance (on a generated building, 30 became
/// 2 within 6 s and 1 within 18 s of resampling): the spread that should grow with the time held stopped
/// growing, and the lineage left kept its error to the stretch's end (doc/experiments.md, "Held speed
/// errors lost to resampling").
std::vector<double> inheritHeldSpeedErrors(const std::vector<int>& parents, const std::vector<double>& errors,
                                           GaussianSampler& rng);

/// Weighted mean pose (angle: circular mean) and covariance of (x, y, θ) around it.
Eigen::Matrix3d weightedPoseCovariance(const std::vector<Pose2D>& poses, const std::vector<double>& w,
                                       Pose2D* mean = nullptr);

}  // namespace laser_dpslam
