// Saliency-based resampling (saliency_resampler.h, doc/algorithms.md §4) and the resampling facade.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "laser_dpslam/scan/saliency_resampler.h"
#include "laser_dpslam/scan/scan_preprocessor.h"
#include "laser_dpslam/scan/scan_resampler.h"
#include "laser_dpslam/scan/uniform_resampler.h"

namespace laser_dpslam {
namespace {

using Eigen::Vector2d;

struct Segment {
  Vector2d a, b;
};

// Distance along the ray from the origin at angle `ang` to the nearest segment (1e9 if none).
double castRay(const std::vector<Segment>& segs, double ang) {
  const Vector2d d(std::cos(ang), std::sin(ang));
  double best = 1e9;
  for (const Segment& s : segs) {
    const Vector2d e = s.b - s.a;
    const double den = d.y() * e.x() - d.x() * e.y();  // cross(e, d)
    if (std::abs(den) < 1e-12) continue;
    const double t = (s.a.y() * e.x() - s.a.x() * e.y()) / den;  // cross(e, a) / cross(e, d)
    const double u = (d.x() * s.a.y() - d.y() * s.a.x()) / den;  // cross(d, a) / cross(e, d)
    if (t > 0.0 && u >= 0.0 && u <= 1.0) best = std::min(best, t);
  }
  return best;
}

void addBox(std::vector<Segment>& v, double x0, double y0, double x1, double y1) {
  v.push_back({{x0, y0}, {x1, y0}});
  v.push_back({{x1, y0}, {x1, y1}});
  v.push_back({{x1, y1}, {x0, y1}});
  v.push_back({{x0, y1}, {x0, y0}});
}

// The test room, in the laser frame (laser at the origin looking along +x): a 4.5 m × 3.6 m room whose
// back wall is 0.5 m behind the laser, so that all four corners are inside the URG-04LX's 240° field of
// view, and a 0.6 m × 0.5 m box at the lower left whose shadow falls on the side wall, not on a corner.
// Visible box features: its convex corner (0.3, −0.8) and two occluding edges, (0.3, −1.3) and (0.9, −0.8).
const std::vector<Vector2d> kRoomCorners = {{-0.5, -1.8}, {4.0, -1.8}, {4.0, 1.8}, {-0.5, 1.8}};
const std::vector<Vector2d> kOccludingEdges = {{0.3, -1.3}, {0.9, -0.8}};
const Vector2d kBoxCorner(0.3, -0.8);

LaserScan roomLaserScan(double noise_sigma, std::uint64_t seed = 7) {
  std::vector<Segment> segs;
  addBox(segs, -0.5, -1.8, 4.0, 1.8);
  addBox(segs, 0.3, -1.3, 0.9, -0.8);
  LaserScan s;  // URG-04LX: 683 beams at 0.3516°, 0.02–5.6 m (doc/algorithms.md §0)
  s.angle_increment = 0.00613592315;
  s.angle_min = -341 * s.angle_increment;
  s.angle_max = 341 * s.angle_increment;
  s.range_min = 0.02;
  s.range_max = 5.6;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int i = 0; i < 683; ++i) {
    double r = castRay(segs, s.angle_min + i * s.angle_increment);
    if (noise_sigma > 0.0) r += noise_sigma * noise(rng);
    s.ranges.push_back(static_cast<float>(r));
  }
  return s;
}

PreprocessedScan roomScan(double noise_sigma, std::uint64_t seed = 7) {
  return preprocessScan(roomLaserScan(noise_sigma, seed), ScanPreprocessorConfig{});
}

double nearestKept(const PreprocessedScan& p, const std::vector<int>& idx, const Vector2d& target) {
  double best = 1e9;
  for (int i : idx) best = std::min(best, (p.points[i] - target).norm());
  return best;
}

int nearestPoint(const PreprocessedScan& p, const Vector2d& target) {
  int best = 0;
  for (std::size_t i = 0; i < p.points.size(); ++i)
    if ((p.points[i] - target).norm() < (p.points[best] - target).norm()) best = static_cast<int>(i);
  return best;
}

void expectSortedUnique(const std::vector<int>& idx, std::size_t n) {
  for (std::size_t i = 0; i < idx.size(); ++i) {
    ASSERT_GE(idx[i], 0);
    ASSERT_LT(static_cast<std::size_t>(idx[i]), n);
    if (i > 0) {
      ASSERT_LT(idx[i - 1], idx[i]);
    }
  }
}

TEST(SaliencyResampler, SceneIsWhatTheTestsAssume) {
  const PreprocessedScan p = roomScan(0.0);
  ASSERT_TRUE(p.ok()) << p.error;
  EXPECT_EQ(p.points.size(), 683u);  // every beam hits a wall within 5.6 m
  // Every feature is actually seen: a scan point lies within 3 cm of it.
  for (const Vector2d& t : kRoomCorners) EXPECT_LT((p.points[nearestPoint(p, t)] - t).norm(), 0.03);
  for (const Vector2d& t : kOccludingEdges) EXPECT_LT((p.points[nearestPoint(p, t)] - t).norm(), 0.03);
  EXPECT_LT((p.points[nearestPoint(p, kBoxCorner)] - kBoxCorner).norm(), 0.03);
}

TEST(SaliencyResampler, JumpsGiveOccludingEdgesAndShadowPoints) {
  const PreprocessedScan p = roomScan(0.0);
  const SaliencyFeatures f = computeSaliency(p, SaliencyConfig{});
  ASSERT_EQ(f.score.size(), p.points.size());
  for (const Vector2d& t : kOccludingEdges) {
    const int i = nearestPoint(p, t);
    EXPECT_EQ(f.edge[i], EdgeType::kOccluding) << t.transpose();
    // Its neighbour across the jump is on the wall behind: a shadow point, further away, never kept.
    const int j = f.segment[std::max(i - 1, 0)] != f.segment[i] ? i - 1 : i + 1;
    ASSERT_NE(f.segment[j], f.segment[i]);
    EXPECT_EQ(f.edge[j], EdgeType::kShadow);
    EXPECT_GT(p.ranges[j], p.ranges[i] + 0.3);
    EXPECT_EQ(f.score[j], 0.0);
  }
  // Exactly two jumps in this scene: room wall -> box -> room wall, so three segments.
  EXPECT_EQ(f.segment.back(), 2);
  EXPECT_EQ(std::count(f.edge.begin(), f.edge.end(), EdgeType::kShadow), 2);
  EXPECT_EQ(std::count(f.edge.begin(), f.edge.end(), EdgeType::kOccluding), 2);
}

TEST(SaliencyResampler, CurvaturePeaksAtCorners) {
  const PreprocessedScan p = roomScan(0.005);
  const SaliencyFeatures f = computeSaliency(p, SaliencyConfig{});
  std::vector<Vector2d> corners = kRoomCorners;
  corners.push_back(kBoxCorner);
  std::vector<double> sorted = f.curvature;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double median = sorted[sorted.size() / 2];
  for (const Vector2d& t : corners) {
    // The curvature maximum among the points within 0.3 m of the corner is within 5 cm of it.
    int best = -1;
    for (std::size_t i = 0; i < p.points.size(); ++i)
      if ((p.points[i] - t).norm() < 0.3 && (best < 0 || f.curvature[i] > f.curvature[best])) best = static_cast<int>(i);
    ASSERT_GE(best, 0);
    EXPECT_LT((p.points[best] - t).norm(), 0.05) << t.transpose();
    EXPECT_GT(f.curvature[best], 5.0 * median) << t.transpose();
  }
}

TEST(SaliencyResampler, RarityFavoursTheRareOrientation) {
  // A corridor 2 m wide, 30 m long, whose end wall is 3 m ahead: the end wall is the only thing that
  // constrains motion along the corridor (the case laser-only SLAM users run into), and few beams see it.
  std::vector<Segment> segs = {{{-15, -1}, {15, -1}}, {{-15, 1}, {15, 1}}, {{3, -1}, {3, 1}}};
  LaserScan s = roomLaserScan(0.0);
  for (int i = 0; i < 683; ++i) s.ranges[i] = static_cast<float>(castRay(segs, s.angle_min + i * s.angle_increment));
  const PreprocessedScan p = preprocessScan(s, ScanPreprocessorConfig{});
  ASSERT_TRUE(p.ok());
  const SaliencyFeatures f = computeSaliency(p, SaliencyConfig{});
  double end_wall = 0.0, side_walls = 0.0;
  int n_end = 0, n_side = 0;
  for (std::size_t i = 0; i < p.points.size(); ++i) {
    const Vector2d& q = p.points[i];
    if (std::abs(q.x() - 3.0) < 1e-3 && std::abs(q.y()) < 0.8) end_wall += f.rarity[i], ++n_end;
    if (std::abs(std::abs(q.y()) - 1.0) < 1e-3 && q.x() < 2.7) side_walls += f.rarity[i], ++n_side;
  }
  ASSERT_GT(n_end, 10);
  ASSERT_GT(n_side, 100);
  EXPECT_GT(end_wall / n_end, 0.5);
  EXPECT_LT(side_walls / n_side, 0.1);
}

// The acceptance test: with 40 of 683 points, saliency keeps a point within 5 cm of every room corner
// and of both occluding edges of the box, while uniform and every-k-th resampling each drop at least one.
TEST(SaliencyResampler, KeepsCornerPointsThatUniformResamplingDrops) {
  const std::size_t budget = 40;
  for (double sigma : {0.0, 0.005}) {
    SCOPED_TRACE("noise sigma " + std::to_string(sigma));
    const PreprocessedScan p = roomScan(sigma);
    ASSERT_GT(p.points.size(), 600u);
    std::vector<Vector2d> features = kRoomCorners;
    features.insert(features.end(), kOccludingEdges.begin(), kOccludingEdges.end());
    features.push_back(kBoxCorner);

    for (bool weighted : {false, true}) {
      SaliencyConfig cfg;
      cfg.weighted_sampling = weighted;
      const std::vector<int> sal = saliencyResample(p, budget, cfg, 1234);
      EXPECT_LE(sal.size(), budget);
      EXPECT_GE(sal.size(), budget - 1);
      for (const Vector2d& t : features)
        EXPECT_LT(nearestKept(p, sal, t), 0.05) << "saliency (weighted " << weighted << ") lost " << t.transpose();
    }

    const auto droppedSome = [&](const std::vector<int>& idx) {
      EXPECT_LE(idx.size(), budget);
      int dropped = 0;
      for (const Vector2d& t : features) dropped += nearestKept(p, idx, t) >= 0.05;
      return dropped;
    };
    EXPECT_GE(droppedSome(uniformResample(p, budget)), 1);
    EXPECT_GE(droppedSome(everyKthResample(p, budget)), 1);
  }
}

TEST(SaliencyResampler, KeepsCoverageOfTheWholeRoom) {
  // The fill half must cover the room: no scan point is farther than 0.5 m from a kept one
  // (the uniform spacing at this budget is ~0.45 m).
  const PreprocessedScan p = roomScan(0.005);
  const std::vector<int> idx = saliencyResample(p, 40, SaliencyConfig{}, 1);
  double worst = 0.0;
  for (const Vector2d& q : p.points) worst = std::max(worst, nearestKept(p, idx, q));
  EXPECT_LT(worst, 0.5);
}

// With no share for the score, the picks are plain farthest-point sampling from the first eligible point:
// each next pick the point farthest from all picks so far, the lower index on a tie.
TEST(SaliencyResampler, CoverageIsFarthestPointSampling) {
  PreprocessedScan p = roomScan(0.005);
  // Repeated points make ties.
  for (std::size_t i = 0; i < p.points.size(); i += 7) p.points[i] = p.points[i / 2];
  SaliencyConfig cfg;
  cfg.salient_fraction = 0.0;
  const SaliencyFeatures f = computeSaliency(p, cfg);
  const std::size_t n = p.points.size();
  for (std::size_t budget : {std::size_t{1}, std::size_t{17}, std::size_t{100}, std::size_t{300}}) {
    std::vector<int> expected;
    std::vector<double> d2(n, std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < n; ++i)
      if (f.edge[i] == EdgeType::kShadow) d2[i] = -1.0;
    int next = -1;
    for (std::size_t i = 0; i < n && next < 0; ++i)
      if (d2[i] >= 0.0) next = static_cast<int>(i);
    while (expected.size() < budget && next >= 0) {
      expected.push_back(next);
      d2[next] = -1.0;
      int best = -1;
      for (std::size_t i = 0; i < n; ++i) {
        if (d2[i] < 0.0) continue;
        d2[i] = std::min(d2[i], (p.points[i] - p.points[next]).squaredNorm());
        if (best < 0 || d2[i] > d2[best]) best = static_cast<int>(i);
      }
      next = best;
    }
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(saliencyResample(p, budget, cfg, 5), expected) << "budget " << budget;
  }
}

TEST(SaliencyResampler, BudgetSortedUniqueForEveryBudgetAndMode) {
  const PreprocessedScan p = roomScan(0.005);
  const std::size_t n = p.points.size();
  const SaliencyFeatures f = computeSaliency(p, SaliencyConfig{});
  const std::size_t eligible = n - static_cast<std::size_t>(std::count(f.edge.begin(), f.edge.end(), EdgeType::kShadow));
  for (bool weighted : {false, true}) {
    SaliencyConfig cfg;
    cfg.weighted_sampling = weighted;
    for (std::size_t budget : {std::size_t{0}, std::size_t{1}, std::size_t{5}, std::size_t{40}, std::size_t{134},
                               std::size_t{400}, eligible - 1, eligible, n, n + 10}) {
      const std::vector<int> idx = saliencyResample(p, budget, cfg, 99);
      EXPECT_LE(idx.size(), budget);
      EXPECT_EQ(idx.size(), std::min(budget, eligible)) << "budget " << budget;
      expectSortedUnique(idx, n);
      for (int i : idx) EXPECT_NE(f.edge[i], EdgeType::kShadow);
    }
  }
  // Not dropping shadow points: a budget covering the scan returns every point.
  SaliencyConfig keep;
  keep.drop_shadow_points = false;
  EXPECT_EQ(saliencyResample(p, n, keep, 0).size(), n);
  EXPECT_TRUE(saliencyResample(PreprocessedScan{}, 10, SaliencyConfig{}, 0).empty());
}

TEST(SaliencyResampler, DeterministicForASeed) {
  const PreprocessedScan p = roomScan(0.005);
  SaliencyConfig cfg;
  EXPECT_EQ(saliencyResample(p, 40, cfg, 5), saliencyResample(p, 40, cfg, 5));
  cfg.weighted_sampling = true;
  const std::vector<int> a = saliencyResample(p, 40, cfg, 5);
  EXPECT_EQ(a, saliencyResample(p, 40, cfg, 5));
  // The seed is actually used in weighted mode: some other seed gives another selection.
  int differing = 0;
  for (std::uint64_t seed = 6; seed < 16; ++seed) differing += saliencyResample(p, 40, cfg, seed) != a;
  EXPECT_GT(differing, 0);
}

TEST(SaliencyResampler, MixedPixelBetweenSurfacesIsAShadowNotAnEdge) {
  // A wall at 2 m, an object at 1 m, and one "mixed pixel" at 1.5 m between them on the boundary.
  LaserScan s = roomLaserScan(0.0);
  for (int i = 0; i < 683; ++i) s.ranges[i] = i < 300 ? 2.0f : (i == 300 ? 1.5f : 1.0f);
  const PreprocessedScan p = preprocessScan(s, ScanPreprocessorConfig{});
  const SaliencyFeatures f = computeSaliency(p, SaliencyConfig{});
  EXPECT_EQ(f.edge[300], EdgeType::kShadow);
  EXPECT_EQ(f.edge[301], EdgeType::kOccluding);
  EXPECT_EQ(f.edge[299], EdgeType::kShadow);
  const std::vector<int> idx = saliencyResample(p, 100, SaliencyConfig{}, 0);
  EXPECT_EQ(std::count(idx.begin(), idx.end(), 300), 0);
}

TEST(SaliencyResampler, WorksWithoutRangesAndBeams) {
  // Code that builds a PreprocessedScan from points alone still gets a valid selection.
  const PreprocessedScan full = roomScan(0.0);
  PreprocessedScan bare;
  bare.points = full.points;
  EXPECT_EQ(saliencyResample(bare, 40, SaliencyConfig{}, 3), saliencyResample(full, 40, SaliencyConfig{}, 3));
}

TEST(ScanResampler, ParseMethodNames) {
  EXPECT_EQ(parseResamplingMethod("none"), ResamplingMethod::kNone);
  EXPECT_EQ(parseResamplingMethod("every_kth"), ResamplingMethod::kEveryKth);
  EXPECT_EQ(parseResamplingMethod("uniform"), ResamplingMethod::kUniform);
  EXPECT_EQ(parseResamplingMethod("saliency"), ResamplingMethod::kSaliency);
  for (ResamplingMethod m : {ResamplingMethod::kNone, ResamplingMethod::kEveryKth, ResamplingMethod::kUniform,
                             ResamplingMethod::kSaliency})
    EXPECT_EQ(parseResamplingMethod(resamplingMethodName(m)), m);
  try {
    parseResamplingMethod("Saliency ");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    for (const char* name : {"none", "every_kth", "uniform", "saliency"}) EXPECT_NE(what.find(name), std::string::npos);
  }
  EXPECT_THROW(parseResamplingMethod(""), std::invalid_argument);
}

TEST(ScanResampler, ResampleScanReturnsTheChosenPoints) {
  const PreprocessedScan p = roomScan(0.005);
  const SaliencyConfig cfg;
  EXPECT_EQ(resampleScan(p, ResamplingMethod::kNone, 10, cfg, 0).size(), p.points.size());
  for (ResamplingMethod m : {ResamplingMethod::kEveryKth, ResamplingMethod::kUniform, ResamplingMethod::kSaliency}) {
    const std::vector<int> idx = resampleIndices(p, m, 40, cfg, 8);
    const std::vector<Vector2d> pts = resampleScan(p, m, 40, cfg, 8);
    ASSERT_EQ(pts.size(), idx.size()) << resamplingMethodName(m);
    EXPECT_LE(pts.size(), 40u);
    EXPECT_GT(pts.size(), 30u);
    for (std::size_t i = 0; i < idx.size(); ++i) EXPECT_EQ(pts[i], p.points[idx[i]]);
  }
}

}  // namespace
}  // namespace laser_dpslam
