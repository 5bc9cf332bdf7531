// One entry point for the scan resamplings compared in the thesis (none / every k-th / uniform / saliency).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "laser_dpslam/scan/saliency_resampler.h"
#include "laser_dpslam/scan/scan_preprocessor.h"
#include "laser_dpslam/scan/uniform_resampler.h"

namespace laser_dpslam {

enum class ResamplingMethod { kNone, kEveryKth, kUniform, kSaliency };

/// "none", "every_kth", "uniform", "saliency"; anything else throws std::invalid_argument naming the valid ones.
ResamplingMethod parseResamplingMethod(const std::string& name);

/// The inverse of parseResamplingMethod (for logs and stats).
const char* resamplingMethodName(ResamplingMethod method);

/// Indices into scan.points chosen by `method` (ascending); kNone returns every index and ignores budget.
std::vector<int> resampleIndices(const PreprocessedScan& scan, ResamplingMethod method, std::size_t budget,
                                 const SaliencyConfig& saliency, std::uint64_t seed);

/// The chosen points themselves, in beam order.
std::vector<Eigen::Vector2d> resampleScan(const PreprocessedScan& scan, ResamplingMethod method, std::size_t budget,
                                          const SaliencyConfig& saliency, std::uint64_t seed);

}  // namespace laser_dpslam
