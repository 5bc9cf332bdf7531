// Spatially uniform and every-k-th point resampling of a preprocessed scan.
//
// Why: a low-cost LRF (URG-04LX) returns dense point clusters near the laser that dominate NDT cells;
// the thesis resamples the scan uniformly in space before matching (594 -> 85 points, doc/algorithms.md §0).
#pragma once

#include <cstddef>
#include <vector>

#include "laser_dpslam/scan/scan_preprocessor.h"

namespace laser_dpslam {

/// Indices into scan.points (ascending, unique, at most `budget` of them) spaced uniformly along the scan:
/// walking in beam order, a point is kept when its distance to the last kept point is at least a spacing
/// s. s starts at (polyline length, ignoring jumps > 0.5 m) / budget and is then searched so that as close
/// to `budget` points as possible (never more) are kept. The first point is always kept.
/// budget >= n returns every index; budget == 0 returns none. Deterministic.
std::vector<int> uniformResample(const PreprocessedScan& scan, std::size_t budget);

/// Every k-th point (0, k, 2k, ...) with k = ceil(n / budget): at most `budget` indices, ascending.
/// budget >= n returns every index; budget == 0 returns none.
std::vector<int> everyKthResample(const PreprocessedScan& scan, std::size_t budget);

}  // namespace laser_dpslam
