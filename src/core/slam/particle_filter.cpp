#include "laser_dpslam/slam/particle_filter.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "laser_dpslam/odometry/wheel_motion.h"

namespace laser_dpslam {

double GaussianSampler::uniform() { return static_cast<double>(rng_() >> 11) * (1.0 / 9007199254740992.0); }

double GaussianSampler::normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  double u1 = uniform();
  while (u1 <= 0.0) u1 = uniform();
  const double u2 = uniform();
  const double r = std::sqrt(-2.0 * std::log(u1));
  spare_ = r * std::sin(2.0 * M_PI * u2);
  has_spare_ = true;
  return r * std::cos(2.0 * M_PI * u2);
}

Eigen::Matrix3d proposalFactor(const Pose2D& delta, const Eigen::Matrix3d& delta_cov, const ProposalNoise& n, int scans) {
  Eigen::Matrix3d cov = 0.5 * (delta_cov + delta_cov.transpose());
  bool ok = cov.allFinite();
  if (ok) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov, Eigen::EigenvaluesOnly);
    ok = es.eigenvalues().minCoeff() >= -1e-12 * std::max(1.0, es.eigenvalues().maxCoeff());
  }
  if (!ok) {
    Eigen::Matrix3d d = Eigen::Matrix3d::Zero();
    for (int i = 0; i < 3; ++i) d(i, i) = std::isfinite(delta_cov(i, i)) ? std::abs(delta_cov(i, i)) : 0.0;
    cov = d;
  }
  const double t = std::hypot(delta.x, delta.y), r = std::abs(delta.theta);
  Eigen::Matrix3d sigma = n.covariance_scale * cov;
  Eigen::Vector3d f = Eigen::Vector3d::Ones();
  for (int i = 0; i < 3; ++i) {
    const double cap = i < 2 ? n.max_sigma_xy : n.max_sigma_theta;
    const double sd = std::sqrt(std::max(0.0, sigma(i, i)));
    if (sd > cap) f(i) = cap / sd;
  }
  sigma = f.asDiagonal() * sigma * f.asDiagonal();
  const double sxy = scans * n.min_sigma_xy * n.min_sigma_xy + std::pow(n.sigma_xy_per_m * t, 2);
  sigma(0, 0) += sxy;
  sigma(1, 1) += sxy;
  sigma(2, 2) += scans * n.min_sigma_theta * n.min_sigma_theta + std::pow(n.sigma_theta_per_rad * r, 2);
  if (n.bounded_by_wheels) sigma = boundedByWheels(sigma, wheelMotionSigma(delta, scans));
  Eigen::LLT<Eigen::Matrix3d> llt(sigma);
  if (llt.info() == Eigen::Success) return llt.matrixL();
  Eigen::Matrix3d diag = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 3; ++i) diag(i, i) = std::sqrt(std::max(0.0, sigma(i, i)));
  return diag;
}

Pose2D sampleMotion(const Pose2D& delta, const Eigen::Matrix3d& L, GaussianSampler& rng) {
  Eigen::Vector3d nvec;
  nvec.x() = rng.normal();
  nvec.y() = rng.normal();
  nvec.z() = rng.normal();
  const Eigen::Vector3d v = delta.vector() + L * nvec;
  return Pose2D(v.x(), v.y(), normalizeAngle(v.z()));
}

NormalizedWeights normalizeLogWeights(const std::vector<double>& logw) {
  NormalizedWeights out;
  const std::size_t n = logw.size();
  out.w.assign(n, 0.0);
  if (n == 0) return out;
  double mx = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    if (std::isfinite(logw[i]) && logw[i] > mx) {
      mx = logw[i];
      out.best = static_cast<int>(i);
    }
  }
  double sum = 0.0;
  if (std::isfinite(mx)) {
    for (std::size_t i = 0; i < n; ++i) {
      out.w[i] = std::isfinite(logw[i]) ? std::exp(logw[i] - mx) : 0.0;
      sum += out.w[i];
    }
  } else {
    std::fill(out.w.begin(), out.w.end(), 1.0);
    sum = static_cast<double>(n);
    out.best = 0;
  }
  double sq = 0.0;
  for (double& w : out.w) {
    w /= sum;
    sq += w * w;
  }
  out.neff = 1.0 / sq;
  return out;
}

std::vector<int> lowVarianceResample(const std::vector<double>& w, std::size_t n, double u0) {
  std::vector<int> parents(n, 0);
  if (w.empty() || n == 0) return parents;
  double total = 0.0;
  for (double x : w) total += x;
  const double step = total / static_cast<double>(n);
  double u = u0 * step, c = w[0];
  std::size_t i = 0;
  for (std::size_t k = 0; k < n; ++k) {
    while (u > c && i + 1 < w.size()) c += w[++i];
    parents[k] = static_cast<int>(i);
    u += step;
  }
  return parents;
}

std::vector<double> inheritHeldSpeedErrors(const std::vector<int>& parents, const std::vector<double>& errors,
                                           GaussianSampler& rng) {
  std::vector<int> children(errors.size(), 0);
  for (int p : parents) ++children[static_cast<std::size_t>(p)];
  std::vector<double> orphaned;
  for (std::size_t i = 0; i < errors.size(); ++i) {
    if (children[i] == 0) orphaned.push_back(errors[i]);
  }
  for (std::size_t k = orphaned.size(); k > 1; --k) {  // Fisher-Yates
    std::swap(orphaned[k - 1], orphaned[std::min(k - 1, static_cast<std::size_t>(rng.uniform() * k))]);
  }
  std::vector<double> out(parents.size());
  std::vector<bool> first(errors.size(), true);
  std::size_t next = 0;
  for (std::size_t j = 0; j < parents.size(); ++j) {
    const std::size_t p = static_cast<std::size_t>(parents[j]);
    const bool keep = first[p] || next >= orphaned.size();
    out[j] = keep ? errors[p] : orphaned[next++];
    first[p] = false;
  }
  return out;
}

Eigen::Matrix3d weightedPoseCovariance(const std::vector<Pose2D>& poses, const std::vector<double>& w, Pose2D* mean) {
  double sw = 0.0, mx = 0.0, my = 0.0, sc = 0.0, ss = 0.0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    sw += w[i];
    mx += w[i] * poses[i].x;
    my += w[i] * poses[i].y;
    sc += w[i] * std::cos(poses[i].theta);
    ss += w[i] * std::sin(poses[i].theta);
  }
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  if (sw <= 0.0) return cov;
  const Pose2D m(mx / sw, my / sw, std::atan2(ss, sc));
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Eigen::Vector3d d(poses[i].x - m.x, poses[i].y - m.y, normalizeAngle(poses[i].theta - m.theta));
    cov += (w[i] / sw) * d * d.transpose();
  }
  if (mean) *mean = m;
  return cov;
}

}  // namespace laser_dpslam
