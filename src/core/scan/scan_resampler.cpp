#include "laser_dpslam/scan/scan_resampler.h"

#include <numeric>
#include <stdexcept>

namespace laser_dpslam {

ResamplingMethod parseResamplingMethod(const std::string& name) {
  if (name == "none") return ResamplingMethod::kNone;
  if (name == "every_kth") return ResamplingMethod::kEveryKth;
  if (name == "uniform") return ResamplingMethod::kUniform;
  if (name == "saliency") return ResamplingMethod::kSaliency;
  throw std::invalid_argument("unknown resampling method '" + name +
                              "' (valid: none, every_kth, uniform, saliency)");
}

const char* resamplingMethodName(ResamplingMethod method) {
  switch (method) {
    case ResamplingMethod::kNone: return "none";
    case ResamplingMethod::kEveryKth: return "every_kth";
    case ResamplingMethod::kUniform: return "uniform";
    case ResamplingMethod::kSaliency: return "saliency";
  }
  return "unknown";
}

std::vector<int> resampleIndices(const PreprocessedScan& scan, ResamplingMethod method, std::size_t budget,
                                 const SaliencyConfig& saliency, std::uint64_t seed) {
  switch (method) {
    case ResamplingMethod::kEveryKth: return everyKthResample(scan, budget);
    case ResamplingMethod::kUniform: return uniformResample(scan, budget);
    case ResamplingMethod::kSaliency: return saliencyResample(scan, budget, saliency, seed);
    case ResamplingMethod::kNone: break;
  }
  std::vector<int> all(scan.points.size());
  std::iota(all.begin(), all.end(), 0);
  return all;
}

std::vector<Eigen::Vector2d> resampleScan(const PreprocessedScan& scan, ResamplingMethod method, std::size_t budget,
                                          const SaliencyConfig& saliency, std::uint64_t seed) {
  if (method == ResamplingMethod::kNone) return scan.points;
  const std::vector<int> idx = resampleIndices(scan, method, budget, saliency, seed);
  std::vector<Eigen::Vector2d> out;
  out.reserve(idx.size());
  for (int i : idx) out.push_back(scan.points[static_cast<std::size_t>(i)]);
  return out;
}

}  // namespace laser_dpslam
