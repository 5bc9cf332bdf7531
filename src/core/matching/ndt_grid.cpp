#include "laser_dpslam/matching/ndt_grid.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

#include "laser_dpslam/common/fast_exp.h"

namespace laser_dpslam {

namespace {
struct Accumulator {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  Eigen::Matrix2d sum_sq = Eigen::Matrix2d::Zero();
  int n = 0;
};

// A cell counts as a line (a wall) when its smaller eigenvalue is below this × the larger one: σ across
// under a third of σ along.
constexpr double kTruncatedLineRatio = 0.1;
// σ along a truncated line cell, in cells: the density then varies by < 0.5 % over the cell (no pull
// along it), while across the line it is unchanged.
constexpr double kTruncatedAlongSigmaCells = 10.0;

// True when every corner of the square [lo, lo + L]² lies within the range of one of the views.
bool seenWhole(const Eigen::Vector2d& lo, double L, const std::vector<NdtView>& views) {
  for (const NdtView& v : views) {
    bool inside = true;
    for (int k = 0; k < 4 && inside; ++k) {
      inside = (lo + L * Eigen::Vector2d(k & 1, k >> 1) - v.origin).squaredNorm() <= v.range * v.range;
    }
    if (inside) return true;
  }
  return false;
}
}  // namespace

void NdtGrid::build(const std::vector<Eigen::Vector2d>& points, const NdtGridConfig& config,
                    const std::vector<NdtView>& views) {
  config_ = config;
  valid_cells_ = 0;
  for (auto& layer : layers_) {
    layer.nx = layer.ny = 0;
    layer.cells.clear();
  }
  if (points.empty() || !(config.cell_size > 0.0)) return;

  Eigen::Vector2d lo(std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (const auto& p : points) {
    if (!p.allFinite()) continue;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  if (!lo.allFinite()) return;

  const double L = config.cell_size, inv = 1.0 / L;
  std::vector<Accumulator> acc;
  for (int k = 0; k < 4; ++k) {
    Layer& layer = layers_[k];
    // Shift by L/2 in x and/or y (Biber & Straßer): every point falls in four cells.
    const Eigen::Vector2d shift(0.5 * L * (k & 1), 0.5 * L * (k >> 1));
    layer.origin = (Eigen::Vector2d((std::floor(lo.x() * inv)), std::floor(lo.y() * inv)) * L) - Eigen::Vector2d(L, L) + shift;
    layer.nx = static_cast<int>(std::floor((hi.x() - layer.origin.x()) * inv)) + 2;
    layer.ny = static_cast<int>(std::floor((hi.y() - layer.origin.y()) * inv)) + 2;
    const std::size_t n_cells = static_cast<std::size_t>(layer.nx) * layer.ny;
    acc.assign(n_cells, Accumulator());
    for (const auto& p : points) {
      if (!p.allFinite()) continue;
      const int ix = static_cast<int>((p.x() - layer.origin.x()) * inv);
      const int iy = static_cast<int>((p.y() - layer.origin.y()) * inv);
      if (ix < 0 || iy < 0 || ix >= layer.nx || iy >= layer.ny) continue;
      Accumulator& a = acc[static_cast<std::size_t>(iy) * layer.nx + ix];
      a.sum += p;
      a.sum_sq += p * p.transpose();
      ++a.n;
    }
    layer.cells.assign(n_cells, NdtCell());
    for (std::size_t i = 0; i < n_cells; ++i) {
      const Accumulator& a = acc[i];
      if (a.n < config.min_points) continue;
      NdtCell& c = layer.cells[i];
      c.count = a.n;
      c.mean = a.sum / a.n;
      // Sample covariance (K − n·μμᵀ)/(n − 1): the minus sign matters (doc/algorithms.md §2, known bug).
      Eigen::Matrix2d cov = (a.sum_sq - a.n * c.mean * c.mean.transpose()) / (a.n - 1);
      // Regularise by rebuilding from the eigenvectors with a clamped smallest eigenvalue.
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es;
      es.computeDirect(cov);  // closed form for 2×2
      Eigen::Vector2d ev = es.eigenvalues();
      const double lmax = std::max(ev.maxCoeff(), config.min_eigen);
      const double floor_ev = std::max(config.eigen_ratio * lmax, config.min_eigen);
      ev = ev.cwiseMax(floor_ev);
      if (!ev.allFinite()) continue;
      if (!views.empty() && ev(0) < kTruncatedLineRatio * ev(1)) {
        const int ix = static_cast<int>(i % layer.nx), iy = static_cast<int>(i / layer.nx);
        c.truncated = !seenWhole(layer.origin + L * Eigen::Vector2d(ix, iy), L, views);
        if (c.truncated) ev(1) = std::max(ev(1), std::pow(kTruncatedAlongSigmaCells * L, 2));
      }
      const Eigen::Matrix2d& V = es.eigenvectors();
      c.covariance = V * ev.asDiagonal() * V.transpose();
      c.information = V * ev.cwiseInverse().asDiagonal() * V.transpose();
      // A point with isotropic noise σ at its true place scores E[exp(−½qᵀΣ⁻¹q)] = det(I + σ²Σ⁻¹)^(−½)
      // on average: less in a thin wall cell than in a fat corner cell, so the plain score pulls noisy
      // scans towards corners, along corridors most of all. The weight undoes that.
      const double s2 = config.point_sigma * config.point_sigma;
      c.weight = std::sqrt((1.0 + s2 / ev(0)) * (1.0 + s2 / ev(1)));
      c.valid = true;
      ++valid_cells_;
    }
  }
}

double NdtGrid::density(const Eigen::Vector2d& p) const {
  const double inv = 1.0 / config_.cell_size;
  double s = 0.0;
  for (const Layer& layer : layers_) {
    const NdtCell* c = layer.cellAt(p, inv);
    if (!c) continue;
    const Eigen::Vector2d q = p - c->mean;
    s += c->weight * negExp(0.5 * q.dot(c->information * q));
  }
  return s;
}

NdtScore NdtGrid::score(const Pose2D& pose, const std::vector<Eigen::Vector2d>& points,
                        bool derivatives) const {
  NdtTerms terms;
  evaluate(pose, points, &terms);
  if (derivatives) return this->derivatives(points, terms);
  NdtScore out;
  out.h = terms.h;
  out.matched = terms.matched;
  return out;
}

void NdtGrid::evaluate(const Pose2D& pose, const std::vector<Eigen::Vector2d>& points, NdtTerms* out) const {
  out->pose = pose;
  out->h = 0.0;
  out->matched = 0;
  out->terms.clear();
  if (valid_cells_ == 0) return;
  const double inv = 1.0 / config_.cell_size;
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  double h = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d& a = points[i];
    const Eigen::Vector2d x(c * a.x() - s * a.y() + pose.x, s * a.x() + c * a.y() + pose.y);
    // The point's terms are computed for all four layers first and summed after, in layer order: the four
    // exp() are then independent of the sums, and the CPU overlaps them. (Skipping a far cell inside this
    // first loop, rather than flagging it, put the branch back before the exp() and lost the gain.)
    const NdtCell* cells[4];
    int n = 0;
    for (const Layer& layer : layers_) {
      if (const NdtCell* cell = layer.cellAt(x, inv)) cells[n++] = cell;
    }
    double e[4], iq[4][2];
    bool near[4];
    bool matched = false;
    for (int k = 0; k < n; ++k) {
      const NdtCell* cell = cells[k];
      const double qx = x.x() - cell->mean.x(), qy = x.y() - cell->mean.y();
      const double a00 = cell->information(0, 0), a01 = cell->information(0, 1), a11 = cell->information(1, 1);
      iq[k][0] = a00 * qx + a01 * qy;  // Σ⁻¹q
      iq[k][1] = a01 * qx + a11 * qy;
      const double m2 = qx * iq[k][0] + qy * iq[k][1];
      if (m2 < 9.0) matched = true;
      // exp(−20) ≈ 2e-9: no contribution worth an exp()
      near[k] = m2 <= 40.0;
      e[k] = near[k] ? cell->weight * negExp(0.5 * m2) : 0.0;
    }
    for (int k = 0; k < n; ++k) {
      if (!near[k]) continue;
      h -= e[k];
      out->terms.emplace_back(cells[k], e[k], iq[k][0], iq[k][1], static_cast<int>(i));
    }
    if (matched) ++out->matched;
  }
  out->h = h;
}

NdtScore NdtGrid::derivatives(const std::vector<Eigen::Vector2d>& points, const NdtTerms& terms) const {
  NdtScore out;
  out.h = terms.h;
  out.matched = terms.matched;
  const double c = std::cos(terms.pose.theta), s = std::sin(terms.pose.theta);
  // Per point, the gradient and Hessian of its term of h in the plane, v = Σ_k e_k Σ_k⁻¹q_k and
  // M = Σ_k e_k (Σ_k⁻¹ − Σ_k⁻¹q_k q_kᵀΣ_k⁻¹); the pose's follow through J = [e_x, e_y, j_θ] (doc/algorithms.md §2):
  // g = Jᵀv, H = JᵀMJ + (v·∂²x'/∂θ²) in the θθ entry. Accumulated in scalars (the upper triangle of H).
  double g0 = 0, g1 = 0, g2 = 0, H00 = 0, H01 = 0, H02 = 0, H11 = 0, H12 = 0, H22 = 0;
  const std::vector<NdtTerms::Term>& t = terms.terms;
  for (std::size_t i = 0; i < t.size();) {
    const int point = t[i].point;
    double vx = 0, vy = 0, m00 = 0, m01 = 0, m11 = 0;
    for (; i < t.size() && t[i].point == point; ++i) {
      const Eigen::Matrix2d& A = t[i].cell->information;
      const double e = t[i].e, ex = e * t[i].iqx, ey = e * t[i].iqy;
      vx += ex;
      vy += ey;
      m00 += e * A(0, 0) - ex * t[i].iqx;
      m01 += e * A(0, 1) - ex * t[i].iqy;
      m11 += e * A(1, 1) - ey * t[i].iqy;
    }
    // Jacobian column for θ and the only non-zero second derivative (∂²x'/∂θ²), at the scan-frame point.
    const Eigen::Vector2d& a = points[point];
    const double jx = -s * a.x() - c * a.y(), jy = c * a.x() - s * a.y();
    const double hx = -c * a.x() + s * a.y(), hy = -s * a.x() - c * a.y();
    const double mjx = m00 * jx + m01 * jy, mjy = m01 * jx + m11 * jy;  // M j_θ
    g0 += vx;
    g1 += vy;
    g2 += vx * jx + vy * jy;
    H00 += m00;
    H01 += m01;
    H02 += mjx;
    H11 += m11;
    H12 += mjy;
    H22 += jx * mjx + jy * mjy + vx * hx + vy * hy;
  }
  out.gradient << g0, g1, g2;
  out.hessian << H00, H01, H02, H01, H11, H12, H02, H12, H22;
  return out;
}

}  // namespace laser_dpslam
