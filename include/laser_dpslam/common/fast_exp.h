// exp(−x) for x ≥ 0 without a call into libm: the DP-SLAM beam model takes two per cell near each return
// (17 % of the SLAM's CPU with glibc's exp; the NDT score uses it too). A table of exp(−k/32) times a
// degree-4 Taylor polynomial of the remainder r ∈ [0, 1/32): relative error below 3e-10 (r⁵/120), inlined,
// about twice as fast per call as glibc's exp on the x86-64 baseline (doc/experiments.md). No ROS.
#pragma once

#include <array>
#include <cmath>

namespace laser_dpslam {

namespace fast_exp_detail {
constexpr int kStepsPerUnit = 32;  ///< table step 1/32: the polynomial's remainder stays below 1/32
constexpr int kRange = 32;         ///< x ≥ 32 (exp < 1.3e-14) falls back to std::exp
struct Table {
  std::array<double, kRange * kStepsPerUnit + 1> v;
  Table() {
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = std::exp(-static_cast<double>(i) / kStepsPerUnit);
  }
};
inline const Table kTable;  // filled at start-up (no guard on each call, as a function-local static has)
}  // namespace fast_exp_detail

/// exp(−x) for x ≥ 0 (relative error < 3e-10); also right, through std::exp, for x < 0, x ≥ 32 and NaN.
inline double negExp(double x) {
  using namespace fast_exp_detail;
  if (!(x >= 0.0 && x < kRange)) return std::exp(-x);
  const double y = x * kStepsPerUnit;
  const int k = static_cast<int>(y);
  const double r = (y - k) * (1.0 / kStepsPerUnit);
  const double p = 1.0 + r * (-1.0 + r * (0.5 + r * (-1.0 / 6.0 + r * (1.0 / 24.0))));
  return kTable.v[k] * p;
}

}  // namespace laser_dpslam
