#include "laser_dpslam/slam/particle_filter.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "laser_dpslam/odometry/wheel_motion.h"

using namespace laser_dpslam;

namespace {
std::vector<int> counts(const std::vector<int>& parents, std::size_t n) {
  std::vector<int> c(n, 0);
  for (int p : parents) ++c[p];
  return c;
}
}  // namespace

// Systematic resampling: each particle gets floor(n·w) or ceil(n·w) children, whatever u0 is, and on
// average exactly n·w.
TEST(LowVarianceResample, ChildCountsAreWithinOneOfTheExpectation) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 500; ++trial) {
    const std::size_t m = 1 + rng() % 40, n = 1 + rng() % 60;
    std::vector<double> w(m);
    double sum = 0.0;
    for (double& x : w) sum += (x = std::pow(u(rng), 4));  // skewed weights
    for (double& x : w) x /= sum;
    const std::vector<int> parents = lowVarianceResample(w, n, u(rng));
    ASSERT_EQ(parents.size(), n);
    ASSERT_TRUE(std::is_sorted(parents.begin(), parents.end()));
    const std::vector<int> c = counts(parents, m);
    for (std::size_t i = 0; i < m; ++i) ASSERT_LT(std::abs(c[i] - n * w[i]), 1.0 + 1e-9) << "trial " << trial;
  }
}

TEST(LowVarianceResample, IsUnbiasedOverTheRandomOffset) {
  const std::vector<double> w{0.05, 0.4, 0.013, 0.237, 0.3};
  const std::size_t n = 7;
  std::vector<double> mean(w.size(), 0.0);
  GaussianSampler rng(3);
  const int runs = 20000;
  for (int r = 0; r < runs; ++r) {
    const std::vector<int> c = counts(lowVarianceResample(w, n, rng.uniform()), w.size());
    for (std::size_t i = 0; i < w.size(); ++i) mean[i] += c[i] / static_cast<double>(runs);
  }
  for (std::size_t i = 0; i < w.size(); ++i) EXPECT_NEAR(mean[i], n * w[i], 0.03) << i;
  // A particle with zero weight never survives; a certain one takes everything.
  EXPECT_EQ(counts(lowVarianceResample({0.0, 1.0, 0.0}, 5, 0.999), 3), (std::vector<int>{0, 5, 0}));
  EXPECT_EQ(counts(lowVarianceResample({1.0, 0.0, 0.0}, 5, 0.0), 3), (std::vector<int>{5, 0, 0}));
}

// Resampling keeps the held speed errors that were drawn: a parent's first child keeps its error, the other
// children take those of the particles left without one, so the set is unchanged however often the filter
// resamples on its other coordinates.
TEST(ParticleFilter, ResamplingKeepsTheSetOfHeldSpeedErrors) {
  GaussianSampler rng(7);
  std::vector<double> errors(30);
  for (double& e : errors) e = 0.01 * rng.normal();
  const std::vector<double> drawn = errors;
  for (int round = 0; round < 200; ++round) {
    std::vector<double> w(errors.size());
    for (double& x : w) x = std::exp(2.0 * rng.normal());  // weights that know nothing of the errors
    const std::vector<int> parents = lowVarianceResample(w, w.size(), rng.uniform());
    const std::vector<double> next = inheritHeldSpeedErrors(parents, errors, rng);
    for (std::size_t j = 0; j < parents.size(); ++j) {
      if (j == 0 || parents[j] != parents[j - 1]) {
        EXPECT_EQ(next[j], errors[parents[j]]) << "first child of " << parents[j];
      }
    }
    errors = next;
  }
  std::vector<double> a = errors, b = drawn;
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  EXPECT_EQ(a, b);
  // Without a resampling (parents = identity) nothing moves.
  std::vector<int> same(errors.size());
  for (std::size_t j = 0; j < same.size(); ++j) same[j] = static_cast<int>(j);
  EXPECT_EQ(inheritHeldSpeedErrors(same, errors, rng), errors);
}

TEST(NormalizeLogWeights, EffectiveSampleSizeAndRobustness) {
  NormalizedWeights a = normalizeLogWeights({-3.0, -3.0, -3.0, -3.0});
  EXPECT_NEAR(a.neff, 4.0, 1e-12);
  for (double w : a.w) EXPECT_NEAR(w, 0.25, 1e-12);
  // Huge magnitudes (sums of hundreds of beams) must not underflow; a constant shift changes nothing.
  NormalizedWeights b = normalizeLogWeights({-1e6, -1e6 - std::log(3.0)});
  EXPECT_NEAR(b.w[0], 0.75, 1e-9);
  EXPECT_NEAR(b.neff, 1.0 / (0.75 * 0.75 + 0.25 * 0.25), 1e-9);
  EXPECT_EQ(b.best, 0);
  NormalizedWeights c = normalizeLogWeights({0.0, -800.0, -std::numeric_limits<double>::infinity(), std::nan("")});
  EXPECT_NEAR(c.w[0], 1.0, 1e-12);
  EXPECT_EQ(c.w[2], 0.0);
  EXPECT_EQ(c.w[3], 0.0);
  EXPECT_NEAR(c.neff, 1.0, 1e-12);
  NormalizedWeights d = normalizeLogWeights({-std::numeric_limits<double>::infinity(), std::nan("")});
  EXPECT_NEAR(d.neff, 2.0, 1e-12);  // nothing finite: uniform
  EXPECT_EQ(normalizeLogWeights({-2.0, 5.0, 5.0}).best, 1);
}

TEST(GaussianSampler, SeededMomentsAndReproducibility) {
  GaussianSampler a(11), b(11), c(12);
  double m = 0.0, v = 0.0, um = 0.0;
  const int n = 200000;
  bool differs = false;
  for (int i = 0; i < n; ++i) {
    const double x = a.normal();
    ASSERT_EQ(x, b.normal());
    differs = differs || x != c.normal();
    m += x / n;
    v += x * x / n;
    const double u = a.uniform();
    ASSERT_EQ(u, b.uniform());
    c.uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    um += u / n;
  }
  EXPECT_TRUE(differs);
  EXPECT_NEAR(m, 0.0, 0.01);
  EXPECT_NEAR(v, 1.0, 0.01);
  EXPECT_NEAR(um, 0.5, 0.005);
}

TEST(Proposal, SamplesHaveTheInflatedCovarianceInTheParticleFrame) {
  Eigen::Matrix3d cov;
  cov << 4e-4, 1e-4, 0, 1e-4, 1e-4, 2e-5, 0, 2e-5, 1e-4;
  ProposalNoise noise;
  noise.covariance_scale = 2.0;
  noise.min_sigma_xy = 0.01;
  noise.min_sigma_theta = 0.005;
  noise.sigma_xy_per_m = 0.1;
  const Pose2D delta(0.3, 0.0, 0.1);
  const Eigen::Matrix3d L = proposalFactor(delta, cov, noise);
  Eigen::Matrix3d expected = 2.0 * cov;
  expected(0, 0) += 1e-4 + 9e-4;
  expected(1, 1) += 1e-4 + 9e-4;
  expected(2, 2) += 2.5e-5;
  EXPECT_LT((L * L.transpose() - expected).norm(), 1e-12);
  GaussianSampler rng(5);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sample = Eigen::Matrix3d::Zero();
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d d = sampleMotion(delta, L, rng).vector() - delta.vector();
    mean += d / n;
    sample += d * d.transpose() / n;
  }
  EXPECT_LT(mean.norm(), 3e-4);
  EXPECT_LT((sample - expected).norm(), 0.03 * expected.norm());
  // Applied in the particle's own frame: a particle facing +y moves along +y.
  const Pose2D moved = Pose2D(1.0, 1.0, M_PI / 2) * Pose2D(0.3, 0.0, 0.0);
  EXPECT_NEAR(moved.x, 1.0, 1e-12);
  EXPECT_NEAR(moved.y, 1.3, 1e-12);
}

TEST(Proposal, WildOrInvalidCovariancesAreTamed) {
  ProposalNoise noise;  // caps 0.1 m, 0.1 rad
  Eigen::Matrix3d wild = Eigen::Matrix3d::Identity() * 1800.0;  // σ = 42 m, as a failed match reported
  wild(0, 1) = wild(1, 0) = 900.0;
  Eigen::Matrix3d L = proposalFactor(Pose2D(), wild, noise);
  Eigen::Matrix3d s = L * L.transpose();
  EXPECT_NEAR(std::sqrt(s(0, 0)), std::hypot(0.1, noise.min_sigma_xy), 1e-9);
  EXPECT_NEAR(std::sqrt(s(2, 2)), std::hypot(0.1, noise.min_sigma_theta), 1e-9);
  EXPECT_NEAR(s(0, 1), 0.5 * 0.01, 1e-9);  // correlation kept
  Eigen::Matrix3d bad = Eigen::Matrix3d::Zero();
  bad(0, 0) = std::nan("");
  bad(1, 1) = -1e-4;  // not positive semi-definite
  L = proposalFactor(Pose2D(), bad, noise);
  EXPECT_TRUE(L.allFinite());
  s = L * L.transpose();
  EXPECT_NEAR(s(1, 1), 1e-4 + 1e-4, 1e-12);
}

// The noise floor is per scan: a motion composed over n scans (the filter updated by travel) gets n times the
// floor's variance, as n updates of one scan each would have spread the particles; the rest is unchanged.
TEST(Proposal, NoiseFloorAddsUpOverTheScansComposed) {
  ProposalNoise noise;
  noise.min_sigma_xy = 0.01;
  noise.min_sigma_theta = 0.005;
  noise.sigma_xy_per_m = 0.1;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  cov.diagonal() << 4e-4, 1e-4, 1e-5;
  const Pose2D delta(0.3, 0.0, 0.0);
  const Eigen::Matrix3d L1 = proposalFactor(delta, cov, noise), L4 = proposalFactor(delta, cov, noise, 4);
  const Eigen::Matrix3d s1 = L1 * L1.transpose(), s4 = L4 * L4.transpose();
  EXPECT_NEAR(s4(0, 0) - s1(0, 0), 3 * 1e-4, 1e-12);
  EXPECT_NEAR(s4(1, 1) - s1(1, 1), 3 * 1e-4, 1e-12);
  EXPECT_NEAR(s4(2, 2) - s1(2, 2), 3 * 2.5e-5, 1e-12);
  EXPECT_NEAR(s1(0, 0), 4e-4 + 1e-4 + 9e-4, 1e-12);
}

// With wheel odometry fused, no direction of the proposal spreads beyond the wheels' error: at rest the 1 cm
// floor shrinks to the wheels' millimetre; moving, the heading floor below the wheels' own heading error stays.
TEST(Proposal, WheelsBoundTheWholeNoiseFloorsIncluded) {
  ProposalNoise noise;
  noise.min_sigma_xy = 0.01;
  noise.min_sigma_theta = 0.005;
  noise.bounded_by_wheels = true;
  const Eigen::Matrix3d tiny = Eigen::Matrix3d::Identity() * 1e-8;
  const auto covariance = [&](const Pose2D& delta, int scans) {
    const Eigen::Matrix3d L = proposalFactor(delta, tiny, noise, scans);
    return Eigen::Matrix3d(L * L.transpose());
  };
  const auto withinWheels = [](const Eigen::Matrix3d& s, const Eigen::Vector3d& w) {
    const Eigen::Matrix3d scaled = w.cwiseInverse().asDiagonal() * s * w.cwiseInverse().asDiagonal();
    return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scaled).eigenvalues().maxCoeff() <= 1.0 + 1e-9;
  };
  const Eigen::Matrix3d rest = covariance(Pose2D(), 1);
  EXPECT_TRUE(withinWheels(rest, wheelMotionSigma(Pose2D())));
  EXPECT_NEAR(std::sqrt(rest(0, 0)), wheelMotionSigma(Pose2D())(0), 1e-9);  // the floor's 1 cm cut to 1 mm
  const Pose2D step(0.03, 0.0, 0.0);  // 0.3 m/s at 10 Hz
  const Eigen::Matrix3d moving = covariance(step, 1);
  EXPECT_TRUE(withinWheels(moving, wheelMotionSigma(step)));
  EXPECT_NEAR(std::sqrt(moving(0, 0)), wheelMotionSigma(step)(0), 1e-9);
  EXPECT_NEAR(moving(2, 2), 2.5e-5 + 1e-8, 1e-12);  // 0.005 rad is inside the wheels' 0.0068 rad: kept
  // Composed over 4 scans the wheels' floors add up in variance, as the proposal's do.
  EXPECT_NEAR(std::sqrt(covariance(Pose2D(), 4)(0, 0)), 2.0 * wheelMotionSigma(Pose2D())(0), 1e-9);
  noise.bounded_by_wheels = false;
  EXPECT_NEAR(covariance(Pose2D(), 1)(0, 0), 1e-4 + 1e-8, 1e-12);
}

TEST(WeightedPoseCovariance, WrapsAnglesAroundPi) {
  const std::vector<Pose2D> poses{Pose2D(0, 0, M_PI - 0.01), Pose2D(2, 0, -M_PI + 0.01)};
  Pose2D mean;
  const Eigen::Matrix3d c = weightedPoseCovariance(poses, {0.5, 0.5}, &mean);
  EXPECT_NEAR(mean.x, 1.0, 1e-12);
  EXPECT_NEAR(std::abs(mean.theta), M_PI, 1e-9);
  EXPECT_NEAR(c(0, 0), 1.0, 1e-12);
  EXPECT_NEAR(c(2, 2), 1e-4, 1e-9);
}
