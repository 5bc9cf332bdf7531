// Differential Evolution (Storn & Price 1997) for small box-constrained minimisation problems, e.g. the
// 3-DoF NDT scan match. Header-only, no ROS. Generic over the dimension (fixed or Eigen::Dynamic) and the
// cost (any callable `double(const Vector&)`).
//
// References:
//   R. Storn, K. Price, "Differential Evolution - A Simple and Efficient Heuristic for Global Optimization
//     over Continuous Spaces", J. Global Optimization 11:341-359, 1997 (DE/rand/1/bin, DE/best/1/bin).
//   J. Brest, S. Greiner, B. Boskovic, M. Mernik, V. Zumer, "Self-Adapting Control Parameters in
//     Differential Evolution", IEEE Trans. Evol. Comput. 10(6), 2006 (jDE).
//
// Evaluation order (documented because tests and callers may rely on it): the NP initial members are
// evaluated in index order, then, for each generation, trial i is evaluated for i = 0 … NP−1. Selection is
// synchronous as in Storn & Price: the trials of one generation are all built from the population at the
// start of that generation, and the survivors form the next one.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace laser_dpslam {

template <int Dim>  // Eigen::Dynamic allowed
class DifferentialEvolution {
 public:
  using Vector = Eigen::Matrix<double, Dim, 1>;

  enum class Strategy {
    kRand1Bin,           ///< v = x_r1 + F·(x_r2 − x_r3)                      (Storn & Price 1997)
    kBest1Bin,           ///< v = x_best + F·(x_r1 − x_r2)                     (Storn & Price 1997)
    kCurrentToBest1Bin,  ///< v = x_i + F·(x_best − x_i) + F·(x_r1 − x_r2)
  };

  enum class BoundHandling {
    kBounceBack,  ///< component outside → base + U(0,1)·(bound − base), base = the mutation's base vector
    kRedraw,      ///< component outside → uniform in [lower, upper]
  };

  struct Config {
    int population = 30;       ///< NP, at least 4
    int max_generations = 50;  ///< G; 0 = only evaluate the initial population
    double F = 0.6;            ///< scale factor, (0, 2]
    double CR = 0.9;           ///< crossover rate, [0, 1]
    Strategy strategy = Strategy::kRand1Bin;
    BoundHandling bounds = BoundHandling::kBounceBack;
    /// F ~ U(0.5, 1) drawn once per generation (Storn & Price's "dither"). Ignored when jde is set.
    bool dither = false;
    /// jDE (Brest et al. 2006): every member carries its own F and CR (initialised to F, CR above); for each
    /// trial F' = 0.1 + 0.9·U with probability τ1 = 0.1 (else inherited), CR' = U with probability τ2 = 0.1;
    /// the new values survive only with the trial.
    bool jde = false;
    /// Stop when, in every dimension d, the population range max−min is below spread_tolerance(d).
    /// Empty (dynamic size) or all zero = off. A zero component never satisfies "below", so set all of them.
    Vector spread_tolerance = defaultTolerance();
    /// Stop after this many consecutive generations without a strict improvement of the best cost; 0 = off.
    int stall_generations = 0;
  };

  struct Result {
    Vector best;
    double best_cost = std::numeric_limits<double>::infinity();
    int generations = 0;  ///< generations performed (≤ max_generations)
    int evaluations = 0;  ///< calls of the cost function
    std::vector<Vector> population;  ///< final population (all inside [lower, upper])
    std::vector<double> costs;       ///< its costs (NaN costs are stored as +inf)
  };

  DifferentialEvolution() : config_() {}
  explicit DifferentialEvolution(const Config& config) : config_(config) {}

  const Config& config() const { return config_; }
  void setConfig(const Config& config) { config_ = config; }

  /// Minimises cost over the box [lower, upper]. `seeds` (e.g. a motion prior) are clamped into the box and
  /// become the first members of the initial population (seeds beyond NP are ignored); the remaining
  /// members are uniform in the box. Deterministic for a given rng state (own uniform draws from the raw
  /// 64-bit output, so also independent of the standard library's distributions).
  /// Throws std::invalid_argument on NP < 4, bad F/CR/generations, mismatched sizes or an empty/invalid box.
  template <class Cost>
  Result minimize(Cost&& cost, const Vector& lower, const Vector& upper, const std::vector<Vector>& seeds,
                  std::mt19937_64& rng) const;

 private:
  static Vector defaultTolerance() {
    if constexpr (Dim == Eigen::Dynamic) {
      return Vector();
    } else {
      return Vector::Zero();
    }
  }

  /// U[0, 1) with 53 random bits.
  static double uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }
  /// Integer in [0, n).
  static int uniformIndex(std::mt19937_64& rng, int n) {
    const int k = static_cast<int>(uniform(rng) * static_cast<double>(n));
    return k < n ? k : n - 1;
  }

  void validate(const Vector& lower, const Vector& upper, const std::vector<Vector>& seeds) const;

  /// Storage beside the population, allocated once: the next generation (selection is synchronous) and
  /// jDE's per-member F and CR, current and next.
  struct Work {
    std::vector<Vector> next;
    std::vector<double> next_costs;
    std::vector<double> f, cr, next_f, next_cr;
  };
  /// Whether spread_tolerance is set (its size is dim and some component is positive).
  bool spreadCheckOn(Eigen::Index dim) const;
  /// Every dimension's population range max−min is below spread_tolerance.
  bool spreadConverged(const std::vector<Vector>& pop) const;
  /// Index of the lowest cost (the first of equal ones).
  static int bestIndex(const std::vector<double>& costs);
  /// Clamped seeds first, then uniform in the box.
  void initialPopulation(const Vector& lower, const Vector& upper, const std::vector<Vector>& seeds,
                         std::vector<Vector>& pop, std::mt19937_64& rng) const;
  /// One generation: a trial for every member, greedy selection, the survivors become r.population.
  template <class Evaluate>
  void generation(Evaluate& evaluate, const Vector& lower, const Vector& upper, int best, Result& r, Work& w,
                  std::mt19937_64& rng) const;
  /// Member i's trial vector: mutation by the strategy, binomial crossover, bound handling.
  void buildTrial(int i, const std::vector<Vector>& pop, const Vector& xb, double f, double cr, const Vector& lower,
                  const Vector& upper, Vector& trial, std::mt19937_64& rng) const;

  Config config_;
};

// ---------------------------------------------------------------------------------------------------------

template <int Dim>
void DifferentialEvolution<Dim>::validate(const Vector& lower, const Vector& upper,
                                          const std::vector<Vector>& seeds) const {
  const Config& c = config_;
  if (c.population < 4) {
    throw std::invalid_argument("DifferentialEvolution: population must be at least 4, got " +
                                std::to_string(c.population));
  }
  if (c.max_generations < 0) throw std::invalid_argument("DifferentialEvolution: max_generations < 0");
  if (!(c.F > 0.0 && c.F <= 2.0)) throw std::invalid_argument("DifferentialEvolution: F must be in (0, 2]");
  if (!(c.CR >= 0.0 && c.CR <= 1.0)) throw std::invalid_argument("DifferentialEvolution: CR must be in [0, 1]");
  if (c.stall_generations < 0) throw std::invalid_argument("DifferentialEvolution: stall_generations < 0");
  if (lower.size() == 0 || lower.size() != upper.size()) {
    throw std::invalid_argument("DifferentialEvolution: lower/upper must be non-empty and of equal size");
  }
  for (Eigen::Index j = 0; j < lower.size(); ++j) {
    if (!std::isfinite(lower(j)) || !std::isfinite(upper(j)) || !(lower(j) <= upper(j))) {
      throw std::invalid_argument("DifferentialEvolution: bounds must be finite with lower <= upper");
    }
  }
  if (c.spread_tolerance.size() != 0 && c.spread_tolerance.size() != lower.size()) {
    throw std::invalid_argument("DifferentialEvolution: spread_tolerance has the wrong size");
  }
  for (const Vector& s : seeds) {
    if (s.size() != lower.size()) throw std::invalid_argument("DifferentialEvolution: seed of wrong size");
  }
}

template <int Dim>
bool DifferentialEvolution<Dim>::spreadCheckOn(Eigen::Index dim) const {
  const Config& c = config_;
  bool use_spread = c.spread_tolerance.size() == dim;
  if (use_spread) {
    use_spread = false;
    for (Eigen::Index j = 0; j < dim; ++j) use_spread = use_spread || c.spread_tolerance(j) > 0.0;
  }
  return use_spread;
}

template <int Dim>
bool DifferentialEvolution<Dim>::spreadConverged(const std::vector<Vector>& pop) const {
  const int np = static_cast<int>(pop.size());
  for (Eigen::Index j = 0; j < pop[0].size(); ++j) {
    double lo = pop[0](j), hi = pop[0](j);
    for (int i = 1; i < np; ++i) {
      lo = std::min(lo, pop[i](j));
      hi = std::max(hi, pop[i](j));
    }
    if (!(hi - lo < config_.spread_tolerance(j))) return false;
  }
  return true;
}

template <int Dim>
int DifferentialEvolution<Dim>::bestIndex(const std::vector<double>& costs) {
  int b = 0;
  for (int i = 1; i < static_cast<int>(costs.size()); ++i) {
    if (costs[i] < costs[b]) b = i;
  }
  return b;
}

template <int Dim>
void DifferentialEvolution<Dim>::initialPopulation(const Vector& lower, const Vector& upper,
                                                   const std::vector<Vector>& seeds, std::vector<Vector>& pop,
                                                   std::mt19937_64& rng) const {
  const size_t n_seeds = std::min(seeds.size(), pop.size());
  for (size_t k = 0; k < pop.size(); ++k) {
    Vector& x = pop[k];
    for (Eigen::Index j = 0; j < lower.size(); ++j) {
      if (k < n_seeds) {
        x(j) = std::min(std::max(seeds[k](j), lower(j)), upper(j));
      } else {
        x(j) = lower(j) + uniform(rng) * (upper(j) - lower(j));
      }
    }
  }
}

template <int Dim>
template <class Cost>
typename DifferentialEvolution<Dim>::Result DifferentialEvolution<Dim>::minimize(
    Cost&& cost, const Vector& lower, const Vector& upper, const std::vector<Vector>& seeds,
    std::mt19937_64& rng) const {
  validate(lower, upper, seeds);
  const Config& c = config_;
  const int np = c.population;
  const double inf = std::numeric_limits<double>::infinity();
  auto evaluate = [&cost, inf](const Vector& x) -> double {
    const double v = cost(static_cast<const Vector&>(x));
    return std::isnan(v) ? inf : v;  // NaN would defeat the greedy comparison
  };
  const bool use_spread = spreadCheckOn(lower.size());

  // All storage is allocated here; the generation loop below allocates nothing (also for Eigen::Dynamic).
  Result r;
  r.population.assign(static_cast<size_t>(np), lower);
  r.costs.assign(static_cast<size_t>(np), inf);
  Work w;
  w.next.assign(static_cast<size_t>(np), lower);
  w.next_costs.assign(static_cast<size_t>(np), inf);
  // jDE per-member parameters (Brest et al. 2006); unused otherwise.
  if (c.jde) {
    w.f.assign(static_cast<size_t>(np), c.F);
    w.cr.assign(static_cast<size_t>(np), c.CR);
    w.next_f = w.f;
    w.next_cr = w.cr;
  }

  initialPopulation(lower, upper, seeds, r.population, rng);
  for (int i = 0; i < np; ++i) r.costs[i] = evaluate(r.population[i]);
  r.evaluations = np;

  int best = bestIndex(r.costs);
  double best_cost = r.costs[best];
  int stall = 0;
  for (int gen = 0; gen < c.max_generations; ++gen) {
    if (use_spread && spreadConverged(r.population)) break;
    if (c.stall_generations > 0 && stall >= c.stall_generations) break;
    generation(evaluate, lower, upper, best, r, w, rng);
    ++r.generations;
    best = bestIndex(r.costs);
    if (r.costs[best] < best_cost) {
      best_cost = r.costs[best];
      stall = 0;
    } else {
      ++stall;
    }
  }

  r.best = r.population[best];
  r.best_cost = r.costs[best];
  return r;
}

template <int Dim>
template <class Evaluate>
void DifferentialEvolution<Dim>::generation(Evaluate& evaluate, const Vector& lower, const Vector& upper, int best,
                                            Result& r, Work& w, std::mt19937_64& rng) const {
  const Config& c = config_;
  const int np = c.population;
  constexpr double kTau1 = 0.1, kTau2 = 0.1, kFl = 0.1, kFu = 0.9;  // jDE constants (Brest et al. 2006)
  // Dither (Storn & Price): one F ~ U(0.5, 1) for the whole generation.
  const double f_gen = (c.dither && !c.jde) ? 0.5 + 0.5 * uniform(rng) : c.F;
  const std::vector<Vector>& pop = r.population;
  const Vector& xb = pop[best];

  for (int i = 0; i < np; ++i) {
    double f = f_gen, cr = c.CR;
    if (c.jde) {
      f = uniform(rng) < kTau1 ? kFl + kFu * uniform(rng) : w.f[i];
      cr = uniform(rng) < kTau2 ? uniform(rng) : w.cr[i];
    }
    Vector& trial = w.next[i];
    buildTrial(i, pop, xb, f, cr, lower, upper, trial, rng);

    // Greedy selection (≤, Storn & Price): the trial replaces its target if it is not worse.
    const double tc = evaluate(trial);
    ++r.evaluations;
    if (tc <= r.costs[i]) {
      w.next_costs[i] = tc;
      if (c.jde) {
        w.next_f[i] = f;
        w.next_cr[i] = cr;
      }
    } else {
      trial = pop[i];
      w.next_costs[i] = r.costs[i];
      if (c.jde) {
        w.next_f[i] = w.f[i];
        w.next_cr[i] = w.cr[i];
      }
    }
  }

  r.population.swap(w.next);
  r.costs.swap(w.next_costs);
  if (c.jde) {
    w.f.swap(w.next_f);
    w.cr.swap(w.next_cr);
  }
}

template <int Dim>
void DifferentialEvolution<Dim>::buildTrial(int i, const std::vector<Vector>& pop, const Vector& xb, double f,
                                            double cr, const Vector& lower, const Vector& upper, Vector& trial,
                                            std::mt19937_64& rng) const {
  const Config& c = config_;
  const int np = c.population;
  // Distinct random indices, all different from i (r3 only needed by rand/1).
  int r1, r2, r3 = -1;
  do { r1 = uniformIndex(rng, np); } while (r1 == i);
  do { r2 = uniformIndex(rng, np); } while (r2 == i || r2 == r1);
  if (c.strategy == Strategy::kRand1Bin) {
    do { r3 = uniformIndex(rng, np); } while (r3 == i || r3 == r1 || r3 == r2);
  }
  const Vector& xi = pop[i];
  const Vector& a = pop[r1];
  const Vector& b = pop[r2];
  // The base vector of the mutation (inside the box): bounce-back moves towards it.
  const Vector& base = c.strategy == Strategy::kRand1Bin ? a
                       : c.strategy == Strategy::kBest1Bin ? xb
                                                            : xi;

  // Binomial crossover with a guaranteed j_rand (Storn & Price 1997): the trial differs from x_i in
  // at least one component even when CR = 0.
  const Eigen::Index dim = lower.size();
  const Eigen::Index j_rand = uniformIndex(rng, static_cast<int>(dim));
  for (Eigen::Index j = 0; j < dim; ++j) {
    if (j != j_rand && !(uniform(rng) < cr)) {
      trial(j) = xi(j);
      continue;
    }
    double v;
    switch (c.strategy) {
      case Strategy::kRand1Bin: v = a(j) + f * (b(j) - pop[r3](j)); break;
      case Strategy::kBest1Bin: v = xb(j) + f * (a(j) - b(j)); break;
      default: v = xi(j) + f * (xb(j) - xi(j)) + f * (a(j) - b(j)); break;
    }
    if (v < lower(j) || v > upper(j)) {
      const double bound = v < lower(j) ? lower(j) : upper(j);
      if (c.bounds == BoundHandling::kBounceBack) {
        v = base(j) + uniform(rng) * (bound - base(j));
      } else {
        v = lower(j) + uniform(rng) * (upper(j) - lower(j));
      }
      // Only guards against floating-point rounding of the lines above (at most an ulp).
      v = std::min(std::max(v, lower(j)), upper(j));
    }
    trial(j) = v;
  }
}

}  // namespace laser_dpslam
