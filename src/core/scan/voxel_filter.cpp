#include "laser_dpslam/scan/voxel_filter.h"

#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace laser_dpslam {

std::vector<Eigen::Vector2d> voxelFilter(const std::vector<Eigen::Vector2d>& points, double voxel) {
  if (!(voxel > 0.0)) return points;
  const double inv = 1.0 / voxel;
  std::unordered_map<std::uint64_t, std::size_t> index;
  index.reserve(points.size());
  std::vector<Eigen::Vector2d> sum;
  std::vector<int> count;
  for (const auto& p : points) {
    if (!p.allFinite()) continue;
    const auto ix = static_cast<std::int64_t>(std::floor(p.x() * inv));
    const auto iy = static_cast<std::int64_t>(std::floor(p.y() * inv));
    const std::uint64_t key = (static_cast<std::uint64_t>(ix) << 32) ^ (static_cast<std::uint64_t>(iy) & 0xffffffffULL);
    auto it = index.find(key);
    if (it == index.end()) {
      index.emplace(key, sum.size());
      sum.push_back(p);
      count.push_back(1);
    } else {
      sum[it->second] += p;
      ++count[it->second];
    }
  }
  for (std::size_t i = 0; i < sum.size(); ++i) sum[i] /= count[i];
  return sum;
}

}  // namespace laser_dpslam
