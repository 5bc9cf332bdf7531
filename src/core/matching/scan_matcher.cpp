#include "laser_dpslam/matching/scan_matcher.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace laser_dpslam {

ScanMatcher::ScanMatcher(const ScanMatcherConfig& config) : config_(config) {
  if (config_.cell_sizes.empty()) throw std::invalid_argument("ScanMatcher: cell_sizes is empty");
  for (double L : config_.cell_sizes) {
    if (!(L > 0.0)) throw std::invalid_argument("ScanMatcher: cell sizes must be positive");
  }
}

void ScanMatcher::setReference(const std::vector<Eigen::Vector2d>& points, const std::vector<NdtView>& views) {
  grids_.resize(config_.cell_sizes.size());
  for (std::size_t i = 0; i < grids_.size(); ++i) {
    NdtGridConfig c = config_.ndt;
    c.cell_size = config_.cell_sizes[i];
    grids_[i].build(points, c, views);
  }
  if (config_.use_de) raster_.build(grids_.front(), kRasterResolution);
}

bool ScanMatcher::hasReference() const { return !grids_.empty() && !grids_.back().empty(); }

Eigen::Vector3d ScanMatcher::newtonStep(const NdtScore& s, const Eigen::Matrix<double, 3, Eigen::Dynamic>* basis) {
  // Newton with the Hessian made positive definite (doc/algorithms.md §2).
  Eigen::Matrix3d H = s.hessian;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
  es.computeDirect(H, Eigen::EigenvaluesOnly);
  const double lmin = es.eigenvalues()(0);
  if (lmin <= 0.0) H += (1.0 - 1.1 * lmin) * Eigen::Matrix3d::Identity();
  if (!basis) return -H.ldlt().solve(s.gradient);
  // Newton in the subspace: Δ = B (BᵀHB)⁻¹ Bᵀ(−g).
  const Eigen::MatrixXd Hb = basis->transpose() * H * *basis;
  return -*basis * Hb.ldlt().solve(basis->transpose() * s.gradient);
}

Pose2D ScanMatcher::polish(const std::vector<Eigen::Vector2d>& points, const Pose2D& start, std::size_t level,
                           int* iterations, const Eigen::Matrix<double, 3, Eigen::Dynamic>* basis,
                           const Pose2D* prior, double prior_sigma_xy, NdtScore* final_score) const {
  const NdtGrid& grid = grids_.at(level);
  // The motion prior as a quadratic term in h's units, see prior_sigma_xy.
  const double w = prior ? priorWeight(prior_sigma_xy) : 0.0;
  auto priorTerm = [&](const Pose2D& p) {
    const Eigen::Vector2d d(p.x - prior->x, p.y - prior->y);
    return 0.5 * w * d.squaredNorm();
  };
  // The score with its derivatives at the terms' pose; `raw` receives it without the prior's term.
  auto score = [&](const NdtTerms& t, NdtScore* raw) {
    NdtScore r = grid.derivatives(points, t);
    *raw = r;
    if (w > 0.0) {
      r.h += priorTerm(t.pose);
      r.gradient.head<2>() += w * Eigen::Vector2d(t.pose.x - prior->x, t.pose.y - prior->y);
      r.hessian.topLeftCorner<2, 2>() += w * Eigen::Matrix2d::Identity();
    }
    return r;
  };
  NdtTerms terms, trial;
  terms.terms.reserve(4 * points.size());
  trial.terms.reserve(4 * points.size());
  grid.evaluate(start, points, &terms);
  NdtScore raw;
  NdtScore s = score(terms, &raw);
  int it = 0;
  for (; it < config_.newton_iterations; ++it) {
    const Eigen::Vector3d delta = newtonStep(s, basis);
    if (!delta.allFinite()) break;
    // Backtracking: a Newton step on a sum of Gaussians can overshoot (and h jumps where a point changes
    // cell). A trial is scored by h alone; the derivatives only for the step taken.
    double step = 1.0;
    bool improved = false;
    for (int k = 0; k < 6; ++k) {
      grid.evaluate(Pose2D(terms.pose.x + step * delta.x(), terms.pose.y + step * delta.y(),
                           normalizeAngle(terms.pose.theta + step * delta.z())),
                    points, &trial);
      if (trial.h + (w > 0.0 ? priorTerm(trial.pose) : 0.0) <= s.h) {
        std::swap(terms, trial);
        s = score(terms, &raw);
        improved = true;
        break;
      }
      step *= 0.5;
    }
    if (!improved) break;
    if ((step * delta).head<2>().norm() < config_.newton_tolerance &&
        std::abs(step * delta.z()) < config_.newton_tolerance) {
      ++it;
      break;
    }
  }
  const Pose2D pose = terms.pose;
  if (iterations) *iterations += it;
  if (final_score) *final_score = raw;
  return pose;
}

bool ScanMatcher::degenerate(const Eigen::Matrix3d& hessian, Eigen::Vector2d* weak) const {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> et;
  et.computeDirect(Eigen::Matrix2d(0.5 * (hessian.topLeftCorner<2, 2>() + hessian.topLeftCorner<2, 2>().transpose())));
  *weak = et.eigenvectors().col(0);
  return !(et.eigenvalues()(0) > config_.degeneracy_ratio * std::max(et.eigenvalues()(1), 1e-12));
}

bool ScanMatcher::weakDirection(const Eigen::Matrix3d& hessian, const Eigen::Vector2d& unconstrained,
                                Eigen::Vector2d* weak) const {
  if (degenerate(hessian, weak)) return true;
  if (unconstrained.squaredNorm() == 0.0) return false;
  *weak = unconstrained;
  return true;
}

Eigen::Matrix3d ScanMatcher::covarianceFrom(const Eigen::Matrix3d& hessian, bool with_prior,
                                            const Eigen::Vector2d& unconstrained, MatchResult& r) const {
  // Σ = α·H⁻¹ + Σ_min (doc/algorithms.md §2): h is not a normalised likelihood, so H⁻¹ alone is
  // over-confident. H's eigenvalues are floored so that a singular H still gives a finite (large) Σ.
  const Eigen::Matrix3d Hs = 0.5 * (hessian + hessian.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
  es.computeDirect(Hs);
  const double floor = 1e-9 * std::max(es.eigenvalues().maxCoeff(), 1e-9);
  // Degeneracy (corridors, a single wall): a translation direction the scan barely constrains. Say so in
  // the covariance with a large σ along it, rather than trusting a tiny curvature.
  Eigen::Vector2d v;
  r.degenerate = weakDirection(Hs, unconstrained, &v);
  if (r.degenerate) r.weak_direction = v;
  auto fromEigenvalues = [&](const Eigen::Vector3d& ev) {
    Eigen::Matrix3d cov = config_.covariance_scale * es.eigenvectors() * ev.cwiseMax(floor).cwiseInverse().asDiagonal() *
                          es.eigenvectors().transpose();
    if (r.degenerate) {
      const double sigma = with_prior ? config_.degenerate_sigma_with_prior : config_.degenerate_sigma;
      cov.topLeftCorner<2, 2>() += sigma * sigma * v * v.transpose();
    }
    cov(0, 0) += config_.min_sigma_xy * config_.min_sigma_xy;
    cov(1, 1) += config_.min_sigma_xy * config_.min_sigma_xy;
    cov(2, 2) += config_.min_sigma_theta * config_.min_sigma_theta;
    if (r.weak) cov *= config_.weak_inflation;
    return Eigen::Matrix3d(0.5 * (cov + cov.transpose()));
  };
  // Where the polish ended on a ridge (H indefinite: h curves down, typically in heading) a negative
  // eigenvalue is floored to nothing, which says "unknown" along it; the SLAM's proposal spreads its
  // particles along that direction and is better for it (doc/reliability.md). The pose covariance takes
  // the curvature's magnitude instead (how fast h changes there: saddle-free, Dauphin et al. 2014), within
  // the search window.
  r.bounded_covariance = boundedByWindow(fromEigenvalues(es.eigenvalues().cwiseAbs()));
  return fromEigenvalues(es.eigenvalues());
}

Eigen::Matrix3d ScanMatcher::boundedByWindow(const Eigen::Matrix3d& cov) const {
  // The search knows the pose lies within ±window of the prior (±rescue_window_theta for a retried weak
  // match), at worst uniformly: σ = w/√3 (in translation no less than degenerate_sigma, the σ a corridor
  // is given). Translation (by its largest σ, so its direction is kept) and heading are scaled down to
  // that; the correlations are kept.
  const double wt = config_.rescue_margin > 0.0 ? std::max(config_.window_theta, config_.rescue_window_theta) : config_.window_theta;
  const double cap_xy = std::max(config_.window_xy / std::sqrt(3.0), config_.degenerate_sigma);
  const double cap_theta = wt / std::sqrt(3.0);
  Eigen::Matrix3d c = 0.5 * (cov + cov.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> et;
  et.computeDirect(Eigen::Matrix2d(c.topLeftCorner<2, 2>()), Eigen::EigenvaluesOnly);
  const double sd_xy = std::sqrt(std::max(0.0, et.eigenvalues()(1))), sd_theta = std::sqrt(std::max(0.0, c(2, 2)));
  const double fxy = sd_xy > cap_xy ? cap_xy / sd_xy : 1.0, ftheta = sd_theta > cap_theta ? cap_theta / sd_theta : 1.0;
  const Eigen::Vector3d f(fxy, fxy, ftheta);
  return f.asDiagonal() * c * f.asDiagonal();
}

Pose2D ScanMatcher::deSearch(const MatchInput& in, const Eigen::Vector3d& w, std::mt19937_64& rng,
                             MatchResult& r) const {
  using DE = DifferentialEvolution<3>;
  DE::Config dc;
  dc.population = config_.de_population;
  dc.max_generations = config_.de_generations;
  dc.CR = config_.de_CR;
  // The scale factor drawn from U(0.5, 1) per generation (dither, Das et al. 2005): no fixed F to tune.
  dc.dither = true;
  dc.strategy = DE::Strategy::kRand1Bin;
  dc.spread_tolerance = Eigen::Vector3d(config_.de_spread_xy, config_.de_spread_xy, config_.de_spread_theta);
  dc.stall_generations = config_.de_stall_generations;
  const Eigen::Vector3d p0 = in.prior.vector();
  // θ is searched unwrapped around the prior; normalised when the pose is formed.
  auto cost = [&](const Eigen::Vector3d& x) { return raster_.cost(Pose2D(x.x(), x.y(), x.z()), in.search_points); };
  const DE de(dc);
  const DE::Result res = de.minimize(cost, p0 - w, p0 + w, {p0}, rng);
  r.de_generations += res.generations;
  r.de_evaluations += res.evaluations;
  return Pose2D(res.best.x(), res.best.y(), normalizeAngle(res.best.z()));
}

Pose2D ScanMatcher::polishAll(const MatchInput& in, Pose2D pose, NdtScore* s, MatchResult& r, bool with_prior) const {
  // (The finest level's polish already scored its final pose: that score is reused.)
  bool scored = false;
  for (std::size_t level = 0; level < grids_.size(); ++level) {
    if (grids_[level].empty()) continue;
    pose = polish(in.polish_points, pose, level, &r.newton_iterations, nullptr, with_prior ? &in.prior : nullptr,
                  in.prior_sigma_xy, s);
    scored = level + 1 == grids_.size();
  }
  if (!scored) *s = grids_.back().score(pose, in.polish_points, true);
  return pose;
}

double ScanMatcher::scorePerPoint(const MatchInput& in, const NdtScore& s) {
  return -s.h / (4.0 * in.n);  // in [0, 1]
}

bool ScanMatcher::isWeak(const MatchInput& in, const NdtScore& s) const {
  return scorePerPoint(in, s) < config_.weak_score || s.matched / in.n < config_.weak_matched_fraction;
}

void ScanMatcher::polishFromPrior(const MatchInput& in, Pose2D* pose, NdtScore* s, MatchResult& r) const {
  const Pose2D& prior = in.prior;
  const double w = priorWeight(in.prior_sigma_xy);
  auto objective = [&](const Pose2D& p, const NdtScore& sc) {
    return sc.h + 0.5 * w * ((p.x - prior.x) * (p.x - prior.x) + (p.y - prior.y) * (p.y - prior.y));
  };
  NdtScore ps;
  const Pose2D from_prior = polishAll(in, prior, &ps, r);
  if (objective(from_prior, ps) < objective(*pose, *s)) {
    *pose = from_prior;
    *s = ps;
  }
}

void ScanMatcher::rescueWeak(const MatchInput& in, const std::mt19937_64& rng, Pose2D* pose, NdtScore* s,
                             MatchResult& r) const {
  // A copy of the generator: a retry leaves the caller's random stream, and so every later match, as it
  // would be without it.
  std::mt19937_64 retry_rng = rng;
  retry_rng.discard(1);
  const Pose2D wide = deSearch(in, Eigen::Vector3d(config_.window_xy, config_.window_xy, config_.rescue_window_theta),
                               retry_rng, r);
  for (const Pose2D& st : {in.prior, wide}) {
    NdtScore cs;
    const Pose2D cand = polishAll(in, st, &cs, r);
    if (scorePerPoint(in, cs) > scorePerPoint(in, *s) + config_.rescue_margin) {
      *pose = cand;
      *s = cs;
    }
  }
}

void ScanMatcher::keepPriorAlongWeak(const MatchInput& in, Pose2D* pose, NdtScore* s, MatchResult& r) const {
  Eigen::Vector2d v;
  if (!weakDirection(s->hessian, in.unconstrained, &v)) return;
  const Eigen::Vector2d d(pose->x - in.prior.x, pose->y - in.prior.y);
  const Eigen::Vector2d xy = Eigen::Vector2d(pose->x, pose->y) - v * v.dot(d);
  Eigen::Matrix<double, 3, Eigen::Dynamic> basis(3, 2);
  basis << -v.y(), 0.0, v.x(), 0.0, 0.0, 1.0;
  const Pose2D held(xy.x(), xy.y(), pose->theta);
  const Pose2D polished = polish(in.polish_points, held, grids_.size() - 1, &r.newton_iterations, &basis);
  // Where the score does constrain the direction held (a forced `unconstrained`), the pose moved along it
  // can sit on a slope that sends the polish far in heading, even to the corridor's mirror image (π): a
  // step beyond the search window is not a refinement, so the held pose stays as it is.
  *pose = std::abs(normalizeAngle(polished.theta - held.theta)) <= config_.window_theta ? polished : held;
  *s = grids_.back().score(*pose, in.polish_points, true);
}

void ScanMatcher::releasePrior(const MatchInput& in, const Eigen::Vector2d& weak, double prior_sigma, Pose2D* pose,
                               NdtScore* s, MatchResult& r) const {
  NdtScore fs;
  const Pose2D free = polishAll(in, *pose, &fs, r, false);
  if (scorePerPoint(in, fs) > scorePerPoint(in, *s) + kPriorReleaseMargin &&
      std::abs(weak.dot(Eigen::Vector2d(free.x - pose->x, free.y - pose->y))) > kPriorReleaseSigmas * prior_sigma) {
    *pose = free;
    *s = fs;
    r.prior_released = true;
  }
}

MatchResult ScanMatcher::match(const std::vector<Eigen::Vector2d>& points,
                               const std::vector<Eigen::Vector2d>& polish_points, const Pose2D& prior,
                               std::mt19937_64& rng, double prior_sigma_xy, bool allow_prior_release,
                               bool hold_prior_when_degenerate, const Eigen::Vector2d& unconstrained) const {
  MatchResult r;
  r.pose = prior;
  if (!hasReference() || points.empty() || polish_points.empty()) return r;
  const Eigen::Vector2d along = hold_prior_when_degenerate && unconstrained.squaredNorm() > 0.0
                                    ? Eigen::Vector2d(unconstrained.normalized())
                                    : Eigen::Vector2d::Zero();
  const MatchInput in{points, polish_points, prior, prior_sigma_xy, static_cast<double>(polish_points.size()), along};

  // DE over a window around the prior (doc/algorithms.md §3), the prior seeded into the population; then
  // the Newton polish coarse to fine, and the exact score at the finest resolution.
  const bool de = config_.use_de && !raster_.empty();
  NdtScore s;
  Pose2D pose = polishAll(in, de ? deSearch(in, Eigen::Vector3d(config_.window_xy, config_.window_xy, config_.window_theta), rng, r) : prior, &s, r);
  if (de && prior_sigma_xy > 0.0 && std::hypot(pose.x - prior.x, pose.y - prior.y) > 3.0 * prior_sigma_xy) {
    // The polish minimises h plus the soft prior, but DE searched h alone (on the raster) and may hand it a
    // basin far from the prior (a corridor's flat score, a false optimum 0.2 m back). Polish from the prior
    // too and keep the lower value of that same objective.
    polishFromPrior(in, &pose, &s, r);
  }
  if (config_.rescue_margin > 0.0 && de && isWeak(in, s)) {
    // A weak match is often a wrong one (a fast turn starting: the constant-velocity prior is off and the
    // search ends on a false optimum). Try the prior itself and a search over a wider window; take one only
    // if it scores clearly better, so that the flat optima of corridors are not traded for one another.
    // (Without DE the match already started from the prior: nothing to retry.)
    rescueWeak(in, rng, &pose, &s, r);
  }
  if (hold_prior_when_degenerate) {
    // In a corridor the score is flat along it: DE and Newton wander there, while the constant-velocity
    // prior is the better guess. Keep the prior along the weak translation direction, re-polish across it
    // (LOAM-style solution remapping, Zhang et al. 2016).
    keepPriorAlongWeak(in, &pose, &s, r);
  }
  Eigen::Vector2d weak;
  if (allow_prior_release && prior_sigma_xy > 0.0 && degenerate(s.hessian, &weak)) {
    // Along a corridor the soft prior holds the pose to the constant-velocity guess. When that guess is
    // wrong (the robot starts to move while the estimate says it is at rest), the velocity smoothing
    // follows the held motion only slowly and metres are lost in seconds (the loop building's start). The
    // scan then fits clearly better where it really is: polish again without the prior and take that
    // when it scores higher and lies well outside the prior's σ along the weak direction.
    releasePrior(in, weak, prior_sigma_xy, &pose, &s, r);
  }
  // The widest search turns the prior by ±rescue_window_theta (a retried weak match), and the polish may
  // converge a little beyond DE's window. But where h is nearly flat in heading (a featureless corridor) a
  // Newton step can be huge and backtracking accepts any decrease, down to the corridor's mirror image half
  // a turn away. A heading beyond the widest search is not a match.
  const double max_turn = std::max(config_.window_theta, config_.rescue_window_theta);
  const bool beyond_search = std::abs(normalizeAngle(pose.theta - prior.theta)) > max_turn;
  r.pose = pose;

  r.hessian = s.hessian;
  r.score_per_point = scorePerPoint(in, s);
  r.matched_fraction = static_cast<double>(s.matched) / in.n;
  r.weak = isWeak(in, s);
  r.covariance = covarianceFrom(s.hessian, prior_sigma_xy > 0.0, in.unconstrained, r);
  r.valid = r.pose.vector().allFinite() && r.covariance.allFinite() && !beyond_search;
  if (!r.valid) r.pose = prior;
  return r;
}

}  // namespace laser_dpslam
