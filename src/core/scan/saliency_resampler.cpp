#include "laser_dpslam/scan/saliency_resampler.h"

#include <Eigen/Core>
#ifdef __SSE2__
#include <emmintrin.h>
#endif
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

namespace laser_dpslam {

namespace {

double rangeOf(const PreprocessedScan& scan, std::size_t i) {
  return scan.ranges.size() == scan.points.size() ? scan.ranges[i] : scan.points[i].norm();
}

long beamOf(const PreprocessedScan& scan, std::size_t i) {
  return scan.beams.size() == scan.points.size() ? scan.beams[i] : static_cast<long>(i);
}

// Angle of a line's normal, folded into [0, π) (a surface seen from either side is the same orientation).
double foldAngle(double a) {
  a = std::fmod(a, M_PI);
  if (a < 0.0) a += M_PI;
  return a >= M_PI ? 0.0 : a;
}

// Soft (linear) binning into a circular histogram over [0, π): no aliasing at bin borders.
void binOf(double angle, int bins, int& b0, int& b1, double& w1) {
  const double x = angle / M_PI * bins - 0.5;
  const double f = std::floor(x);
  w1 = x - f;
  b0 = ((static_cast<int>(f) % bins) + bins) % bins;
  b1 = (b0 + 1) % bins;
}

// §4.2 Segments and edges. Near endpoint of a jump = occluding edge; far endpoint = shadow (the first
// background point behind an occluder moves with the viewpoint). Shadow wins when a point is both (a mixed
// pixel floating between two surfaces).
void findSegmentsAndEdges(const PreprocessedScan& scan, const SaliencyConfig& cfg, SaliencyFeatures& f) {
  const std::size_t n = scan.points.size();
  std::vector<char> occluding(n, 0), shadow(n, 0);
  int seg = 0;
  for (std::size_t i = 1; i < n; ++i) {
    const double ra = rangeOf(scan, i - 1), rb = rangeOf(scan, i);
    const long gap = std::abs(beamOf(scan, i) - beamOf(scan, i - 1)) - 1;
    if (std::abs(rb - ra) > cfg.jump_abs + cfg.jump_rel * std::min(ra, rb)) {
      ++seg;
      (ra < rb ? occluding[i - 1] : occluding[i]) = 1;
      (ra < rb ? shadow[i] : shadow[i - 1]) = 1;
    } else if (gap > cfg.max_beam_gap) {
      ++seg;
    }
    f.segment[i] = seg;
  }
  for (std::size_t i = 0; i < n; ++i)
    f.edge[i] = shadow[i] ? EdgeType::kShadow : occluding[i] ? EdgeType::kOccluding : EdgeType::kNone;
}

// The arc length each point stands for: half its two gaps within its segment, at most the radius.
std::vector<double> arcLengths(const std::vector<Eigen::Vector2d>& p, const std::vector<int>& segment, double radius) {
  const std::size_t n = p.size();
  std::vector<double> arc(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    double w = 0.0;
    if (i > 0 && segment[i - 1] == segment[i]) w += 0.5 * (p[i] - p[i - 1]).norm();
    if (i + 1 < n && segment[i + 1] == segment[i]) w += 0.5 * (p[i + 1] - p[i]).norm();
    arc[i] = std::min(w, std::max(radius, 0.0)) + 1e-9;  // > 0: isolated points still count
  }
  return arc;
}

// The weighted PCA of point i's neighbourhood (same segment, within √r2, at most ±k beams): its curvature
// and normal angle into f (left as they are with fewer than 2 neighbours).
void neighbourhoodPca(const std::vector<Eigen::Vector2d>& p, const std::vector<double>& arc, std::size_t i,
                      std::size_t k, double r2, SaliencyFeatures& f) {
  const std::size_t n = p.size();
  const std::size_t j0 = i >= k ? i - k : 0;
  const std::size_t j1 = std::min(n - 1, i + k);
  double sw = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0, syy = 0.0;
  int cnt = 0;
  std::size_t other = i;  // some neighbour other than i, for the 2-point case
  for (std::size_t j = j0; j <= j1; ++j) {
    if (f.segment[j] != f.segment[i]) continue;
    const Eigen::Vector2d d = p[j] - p[i];  // centred on p_i for numerical stability
    if (d.squaredNorm() > r2) continue;
    const double w = arc[j];
    sw += w;
    sx += w * d.x();
    sy += w * d.y();
    sxx += w * d.x() * d.x();
    sxy += w * d.x() * d.y();
    syy += w * d.y() * d.y();
    ++cnt;
    if (j != i) other = j;
  }
  if (cnt >= 3) {
    const double mx = sx / sw, my = sy / sw;
    const double a = sxx / sw - mx * mx, b = sxy / sw - mx * my, d = syy / sw - my * my;
    const double tr = a + d;
    const double disc = std::sqrt(0.25 * (a - d) * (a - d) + b * b);
    const double l2 = std::max(0.0, 0.5 * tr - disc);
    if (tr > 1e-12) f.curvature[i] = std::min(0.5, l2 / tr);
    // Major axis at 0.5·atan2(2b, a−d); the normal is perpendicular to it.
    f.normal_angle[i] = foldAngle(0.5 * std::atan2(2.0 * b, a - d) + 0.5 * M_PI);
  } else if (cnt == 2) {
    const Eigen::Vector2d d = p[other] - p[i];
    if (d.squaredNorm() > 0.0) f.normal_angle[i] = foldAngle(std::atan2(d.y(), d.x()) + 0.5 * M_PI);
  }
}

// §4.3 Curvature from a PCA of the neighbourhood: c = λ2/(λ1+λ2) is 0 on a line and 0.5 on an isotropic
// blob. Each neighbour is weighted by the arc length it stands for, so the PCA sees the surface, not the
// sampling density: unweighted, the denser wall of a corner dominates and the curvature peak slides off the
// corner. Returns the largest curvature.
double curvatureAndNormals(const std::vector<Eigen::Vector2d>& p, const SaliencyConfig& cfg, SaliencyFeatures& f) {
  const std::vector<double> arc = arcLengths(p, f.segment, cfg.neighbour_radius);
  const std::size_t k = static_cast<std::size_t>(std::max(1, cfg.neighbours));
  const double r2 = cfg.neighbour_radius * cfg.neighbour_radius;
  double c_max = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    neighbourhoodPca(p, arc, i, k, r2, f);
    c_max = std::max(c_max, f.curvature[i]);
  }
  return c_max;
}

// §4.4 Orientation rarity: points facing a rare direction (a corridor's end wall) constrain the direction
// the rest of the scan leaves unobservable.
void orientationRarity(const SaliencyConfig& cfg, SaliencyFeatures& f) {
  const std::size_t n = f.normal_angle.size();
  const int bins = std::max(1, cfg.orientation_bins);
  std::vector<double> hist(bins, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    if (f.normal_angle[i] < 0.0) continue;
    int b0, b1;
    double w1;
    binOf(f.normal_angle[i], bins, b0, b1, w1);
    hist[b0] += 1.0 - w1;
    hist[b1] += w1;
  }
  const double h_max = *std::max_element(hist.begin(), hist.end());
  for (std::size_t i = 0; i < n; ++i) {
    if (f.normal_angle[i] < 0.0 || h_max <= 0.0) continue;
    int b0, b1;
    double w1;
    binOf(f.normal_angle[i], bins, b0, b1, w1);
    const double h = (1.0 - w1) * hist[b0] + w1 * hist[b1];
    f.rarity[i] = std::clamp(1.0 - h / h_max, 0.0, 1.0);
  }
}

// Phase 1's keys: the score itself, or Efraimidis–Spirakis keys log(u)/w for weighted sampling without
// replacement (one u per point, drawn in index order).
std::vector<double> samplingKeys(const SaliencyFeatures& f, const SaliencyConfig& cfg, std::uint64_t seed) {
  std::vector<double> key(f.score);
  if (cfg.weighted_sampling) {
    std::mt19937_64 rng(seed);
    for (std::size_t i = 0; i < key.size(); ++i) {
      // u in (0, 1] from the raw 64 bits: identical on every standard library, unlike the distributions.
      const double u = (static_cast<double>(rng() >> 11) + 1.0) * 0x1.0p-53;
      const double w = std::pow(f.score[i], cfg.sampling_exponent);
      key[i] = (w > 0.0 && std::isfinite(w)) ? std::log(u) / w : -std::numeric_limits<double>::infinity();
    }
  }
  return key;
}

// Phase 1's candidates: local score maxima (over the PCA neighbourhood), in index order. The points around a
// corner share its high score, and without this the sampler often takes one of them and the spacing then
// blocks the corner itself.
std::vector<int> localScoreMaxima(const std::vector<Eigen::Vector2d>& p, const SaliencyFeatures& f,
                                  const SaliencyConfig& cfg, const std::vector<char>& eligible) {
  const std::size_t n = p.size();
  const std::size_t k = static_cast<std::size_t>(std::max(1, cfg.neighbours));
  const double r2 = cfg.neighbour_radius * cfg.neighbour_radius;
  std::vector<int> order;
  order.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!eligible[i] || !(f.score[i] > 0.0)) continue;
    bool is_max = true;
    const std::size_t j1 = std::min(n - 1, i + k);
    for (std::size_t j = i >= k ? i - k : 0; j <= j1 && is_max; ++j)
      is_max = !(f.segment[j] == f.segment[i] && f.score[j] > f.score[i] && (p[j] - p[i]).squaredNorm() <= r2);
    if (is_max) order.push_back(static_cast<int>(i));
  }
  return order;
}

// Phase 1: about salient_fraction·budget points by key, no two closer than min_spacing (so one corner does
// not take several slots), into out and chosen.
void pickSalient(const std::vector<Eigen::Vector2d>& p, const SaliencyFeatures& f, const SaliencyConfig& cfg,
                 const std::vector<char>& eligible, std::size_t budget, std::uint64_t seed, std::vector<int>& out,
                 std::vector<char>& chosen) {
  const double frac = std::clamp(std::isfinite(cfg.salient_fraction) ? cfg.salient_fraction : 0.0, 0.0, 1.0);
  const std::size_t n_salient = std::min(budget, static_cast<std::size_t>(std::lround(frac * budget)));
  const std::vector<double> key = samplingKeys(f, cfg, seed);
  std::vector<int> order = localScoreMaxima(p, f, cfg, eligible);
  std::stable_sort(order.begin(), order.end(), [&key](int a, int b) { return key[a] > key[b]; });
  const double sp2 = std::max(0.0, cfg.min_spacing) * std::max(0.0, cfg.min_spacing);
  for (int i : order) {
    if (out.size() >= n_salient) break;
    bool far_enough = true;
    for (int j : out) {
      if ((p[i] - p[j]).squaredNorm() < sp2) {
        far_enough = false;
        break;
      }
    }
    if (!far_enough) continue;
    out.push_back(i);
    chosen[i] = 1;
  }
}

// d2[i] = min(d2[i], |(xs[i], ys[i]) − q|²) for every point; returns the largest d2 (−1 when n = 0). Two
// points per SSE2 instruction: no index is carried from one point to the next, the arg-max is found after.
double updateDistances(const double* xs, const double* ys, double qx, double qy, std::size_t n, double* d2) {
  std::size_t i = 0;
  double best = -1.0;
#ifdef __SSE2__
  const __m128d vqx = _mm_set1_pd(qx), vqy = _mm_set1_pd(qy);
  __m128d vbest = _mm_set1_pd(-1.0);
  for (; i + 2 <= n; i += 2) {
    const __m128d dx = _mm_sub_pd(_mm_loadu_pd(xs + i), vqx), dy = _mm_sub_pd(_mm_loadu_pd(ys + i), vqy);
    const __m128d d = _mm_add_pd(_mm_mul_pd(dx, dx), _mm_mul_pd(dy, dy));
    const __m128d m = _mm_min_pd(d, _mm_loadu_pd(d2 + i));  // d < d2 ? d : d2 (−inf stays)
    _mm_storeu_pd(d2 + i, m);
    vbest = _mm_max_pd(vbest, m);
  }
  double lanes[2];
  _mm_storeu_pd(lanes, vbest);
  best = std::max(lanes[0], lanes[1]);
#endif
  for (; i < n; ++i) {
    const double dx = xs[i] - qx, dy = ys[i] - qy;
    const double d = dx * dx + dy * dy;
    d2[i] = d < d2[i] ? d : d2[i];
    best = std::max(best, d2[i]);
  }
  return best;
}

// Phase 2: coverage by farthest-point sampling from what is already chosen, until out holds the budget:
// spatially uniform, so the dense clusters near the laser do not take the budget (the thesis's URG-04LX
// problem). O(n) per pick over plain arrays (the scan's hot loop after the NDT score): points that may not
// be picked carry −inf, which min() keeps and the arg-max never takes.
void coverFarthest(const std::vector<Eigen::Vector2d>& p, const std::vector<char>& eligible, std::size_t budget,
                   std::vector<int>& out, std::vector<char>& chosen) {
  const std::size_t n = p.size();
  std::vector<double> xs(n), ys(n), dist2(n, std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < n; ++i) {
    xs[i] = p[i].x();
    ys[i] = p[i].y();
    if (!eligible[i] || chosen[i]) dist2[i] = -std::numeric_limits<double>::infinity();
  }
  // Adds point j to the picks; returns the farthest point from all picks (−1: none left).
  auto pick = [&](std::size_t j) {
    const double best_d = updateDistances(xs.data(), ys.data(), xs[j], ys[j], n, dist2.data());
    if (!(best_d > -1.0)) return -1;
    std::size_t best = 0;  // the first point at the maximum, as a single arg-max pass would find
    while (dist2[best] != best_d) ++best;
    return static_cast<int>(best);
  };
  int best = -1;
  if (out.empty()) {
    for (std::size_t i = 0; i < n && best < 0; ++i)
      if (dist2[i] > 0.0) best = static_cast<int>(i);
  }
  for (int j : out) best = pick(static_cast<std::size_t>(j));
  while (out.size() < budget && best >= 0) {
    out.push_back(best);
    chosen[best] = 1;
    dist2[best] = -std::numeric_limits<double>::infinity();
    best = pick(static_cast<std::size_t>(best));
  }
}

}  // namespace

SaliencyFeatures computeSaliency(const PreprocessedScan& scan, const SaliencyConfig& cfg) {
  const std::size_t n = scan.points.size();
  SaliencyFeatures f;
  f.segment.assign(n, 0);
  f.curvature.assign(n, 0.0);
  f.normal_angle.assign(n, -1.0);
  f.rarity.assign(n, 0.0);
  f.edge.assign(n, EdgeType::kNone);
  f.score.assign(n, 0.0);
  if (n == 0) return f;
  findSegmentsAndEdges(scan, cfg, f);
  const double c_max = curvatureAndNormals(scan.points, cfg, f);
  orientationRarity(cfg, f);

  // §4.5 Score.
  for (std::size_t i = 0; i < n; ++i) {
    const double c = c_max > 0.0 ? f.curvature[i] / c_max : 0.0;
    double s = cfg.weight_curvature * c + cfg.weight_rarity * f.rarity[i] +
               cfg.weight_edge * (f.edge[i] == EdgeType::kOccluding ? 1.0 : 0.0);
    if (f.edge[i] == EdgeType::kShadow) s = cfg.drop_shadow_points ? 0.0 : s * cfg.shadow_weight;
    f.score[i] = std::isfinite(s) ? std::max(0.0, s) : 0.0;
  }
  return f;
}

std::vector<int> saliencyResample(const PreprocessedScan& scan, std::size_t budget, const SaliencyConfig& cfg,
                                  std::uint64_t seed) {
  const std::size_t n = scan.points.size();
  if (n == 0 || budget == 0) return {};
  const SaliencyFeatures f = computeSaliency(scan, cfg);

  std::vector<char> eligible(n, 1);
  std::size_t n_eligible = n;
  if (cfg.drop_shadow_points) {
    for (std::size_t i = 0; i < n; ++i)
      if (f.edge[i] == EdgeType::kShadow) eligible[i] = 0, --n_eligible;
  }
  std::vector<int> out;
  if (budget >= n_eligible) {
    for (std::size_t i = 0; i < n; ++i)
      if (eligible[i]) out.push_back(static_cast<int>(i));
    return out;
  }
  out.reserve(budget);
  std::vector<char> chosen(n, 0);
  pickSalient(scan.points, f, cfg, eligible, budget, seed, out, chosen);
  coverFarthest(scan.points, eligible, budget, out, chosen);
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace laser_dpslam
