// Saliency-based resampling: keep points at corners, occluding edges and rare surface orientations,
// then fill the rest of the budget for spatial coverage (doc/algorithms.md §4; the thesis's exact measure is
// not available, so this is the proposal there: 594 -> 134 points in the thesis's Fig. 83).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "laser_dpslam/scan/scan_preprocessor.h"

namespace laser_dpslam {

struct SaliencyConfig {
  // Segmentation (doc/algorithms.md §4.2): consecutive points split when |Δρ| > jump_abs + jump_rel·min(ρ).
  double jump_abs = 0.1;   ///< m
  double jump_rel = 0.03;  ///< dimensionless, fraction of the nearer range
  int max_beam_gap = 3;    ///< beams; more invalid beams than this between two points also splits (no edge)
  // Curvature (§4.3): arc-length-weighted PCA over the points of the same segment within
  // neighbour_radius, at most ±neighbours beams. §4 suggests ±4 beams within 0.25 m; a fixed beam count
  // makes the neighbourhood lopsided where one wall of a corner is sampled far more densely than the
  // other (URG-04LX at grazing incidence), moving the curvature peak off the corner: the radius decides.
  int neighbours = 30;             ///< beams on each side (a cap; the radius normally limits first)
  double neighbour_radius = 0.15;  ///< m
  // Orientation rarity (§4.4): histogram of normal angles mod π.
  int orientation_bins = 18;  ///< bins over [0, π) (10° each by default)
  // Score (§4.5): S = w_c·c/max c + w_r·rarity + w_e·edge, all terms in [0, 1].
  double weight_curvature = 0.5;  ///< dimensionless
  double weight_rarity = 0.3;     ///< dimensionless
  double weight_edge = 0.2;       ///< dimensionless
  // Selection.
  double salient_fraction = 0.5;  ///< fraction of the budget taken by score; the rest fills for coverage
  double min_spacing = 0.15;      ///< m, minimum distance between two score-selected points
  bool drop_shadow_points = true; ///< far endpoints of jumps are never selected; false: score × shadow_weight
  double shadow_weight = 0.1;     ///< dimensionless, score multiplier for shadow points when not dropped
  /// false: take the highest scores (deterministic, seed unused). true: weighted sampling without
  /// replacement (Efraimidis–Spirakis keys, std::mt19937_64(seed)) with weight S^sampling_exponent.
  bool weighted_sampling = false;
  double sampling_exponent = 2.0;  ///< dimensionless, sharpens the weights in weighted mode
};

/// What a point of a jump is (doc/algorithms.md §4.2).
enum class EdgeType : std::uint8_t {
  kNone = 0,
  kOccluding = 1,  ///< near endpoint of a range jump: a real object boundary, salient
  kShadow = 2,     ///< far endpoint of a range jump: depends on the viewpoint, unreliable
};

/// Per-point saliency terms, one entry per scan.points element (exposed for tests and visualisation).
struct SaliencyFeatures {
  std::vector<int> segment;          ///< segment id, increasing in beam order
  std::vector<double> curvature;     ///< c = λ2/(λ1+λ2) in [0, 0.5]; 0 with fewer than 3 neighbours
  std::vector<double> normal_angle;  ///< rad in [0, π); -1 when the point has no neighbour to define it
  std::vector<double> rarity;        ///< [0, 1]: 1 − (histogram at the normal)/(histogram maximum)
  std::vector<EdgeType> edge;
  std::vector<double> score;         ///< S; 0 for dropped shadow points
};

/// Computes the saliency terms of every point. Never throws; tolerates scans whose `ranges`/`beams`
/// are missing (then derived from the points / assumed consecutive).
SaliencyFeatures computeSaliency(const PreprocessedScan& scan, const SaliencyConfig& cfg);

/// Indices into scan.points: about salient_fraction·budget chosen by score among local score maxima
/// (within the PCA neighbourhood) with min_spacing between them, the rest by farthest-point sampling (each new point is the one farthest from all chosen ones)
/// for coverage. Sorted ascending, unique, size <= budget; if budget covers every eligible point, all of
/// them are returned (shadow points excluded when dropped). Same inputs and seed -> same output.
std::vector<int> saliencyResample(const PreprocessedScan& scan, std::size_t budget, const SaliencyConfig& cfg,
                                  std::uint64_t seed);

}  // namespace laser_dpslam
