// Tests of the Differential Evolution optimiser (include/laser_dpslam/matching/differential_evolution.h).
#include "laser_dpslam/matching/differential_evolution.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using laser_dpslam::DifferentialEvolution;
using DE3 = DifferentialEvolution<3>;
using DEX = DifferentialEvolution<Eigen::Dynamic>;
using V3 = DE3::Vector;
using Strategy = DE3::Strategy;

// ---- standard test functions (3-D) ----------------------------------------------------------------------
double sphere(const V3& x) { return x.squaredNorm(); }

double rosenbrock(const V3& x) {
  double s = 0.0;
  for (int j = 0; j + 1 < 3; ++j) {
    s += 100.0 * std::pow(x(j + 1) - x(j) * x(j), 2) + std::pow(1.0 - x(j), 2);
  }
  return s;
}

double rastrigin(const V3& x) {
  double s = 10.0 * 3;
  for (int j = 0; j < 3; ++j) s += x(j) * x(j) - 10.0 * std::cos(2.0 * M_PI * x(j));
  return s;
}

const V3 kAckleyShift(1.3, -0.7, 2.1);
double shiftedAckley(const V3& x) {
  const V3 z = x - kAckleyShift;
  const double a = -20.0 * std::exp(-0.2 * std::sqrt(z.squaredNorm() / 3.0));
  double c = 0.0;
  for (int j = 0; j < 3; ++j) c += std::cos(2.0 * M_PI * z(j));
  return a - std::exp(c / 3.0) + 20.0 + std::exp(1.0);
}

// ---- variants -------------------------------------------------------------------------------------------
struct Variant {
  Strategy strategy;
  bool dither;
  bool jde;
  std::string name;
};

const std::vector<Variant>& allVariants() {
  static const std::vector<Variant> v = {
      {Strategy::kRand1Bin, false, false, "rand1"},
      {Strategy::kRand1Bin, true, false, "rand1_dither"},
      {Strategy::kRand1Bin, false, true, "rand1_jde"},
      {Strategy::kBest1Bin, false, false, "best1"},
      {Strategy::kBest1Bin, true, false, "best1_dither"},
      {Strategy::kBest1Bin, false, true, "best1_jde"},
      {Strategy::kCurrentToBest1Bin, false, false, "ctb1"},
      {Strategy::kCurrentToBest1Bin, true, false, "ctb1_dither"},
      {Strategy::kCurrentToBest1Bin, false, true, "ctb1_jde"},
  };
  return v;
}

DE3::Config makeConfig(const Variant& v, int np, int gens, double F = 0.6, double CR = 0.9) {
  DE3::Config c;
  c.population = np;
  c.max_generations = gens;
  c.F = F;
  c.CR = CR;
  c.strategy = v.strategy;
  c.dither = v.dither;
  c.jde = v.jde;
  return c;
}

// Cost wrapper that records every evaluated vector (in call order) and its cost.
struct Recorder {
  std::function<double(const V3&)> f;
  std::vector<V3> xs;
  std::vector<double> cs;
  double operator()(const V3& x) {
    xs.push_back(x);
    cs.push_back(f(x));
    return cs.back();
  }
};

V3 box(double v) { return V3::Constant(v); }

class DEVariantTest : public ::testing::TestWithParam<Variant> {};

// ---- convergence on standard functions ----------------------------------------------------------------
TEST_P(DEVariantTest, Sphere) {
  DE3 de(makeConfig(GetParam(), 30, 150));
  std::mt19937_64 rng(1);
  const auto r = de.minimize(sphere, box(-5), box(5), {}, rng);
  EXPECT_LT(r.best_cost, 1e-10);
  EXPECT_LT(r.best.norm(), 1e-5);
  EXPECT_DOUBLE_EQ(r.best_cost, sphere(r.best));
  EXPECT_EQ(r.generations, 150);
  EXPECT_EQ(r.evaluations, 30 * 151);
}

TEST_P(DEVariantTest, Rosenbrock) {
  DE3 de(makeConfig(GetParam(), 50, 1000, 0.7, 0.9));
  std::mt19937_64 rng(2);
  const auto r = de.minimize(rosenbrock, box(-2), box(2), {}, rng);
  EXPECT_LT(r.best_cost, 1e-8);
  EXPECT_LT((r.best - V3(1, 1, 1)).norm(), 1e-3);
}

TEST_P(DEVariantTest, Rastrigin) {
  // Rastrigin is separable and multimodal: a low CR (per-coordinate moves) is the classic setting.
  DE3 de(makeConfig(GetParam(), 40, 400, 0.5, 0.2));
  std::mt19937_64 rng(3);
  const auto r = de.minimize(rastrigin, box(-5.12), box(5.12), {}, rng);
  EXPECT_LT(r.best_cost, 1e-8);
  EXPECT_LT(r.best.norm(), 1e-4);
}

TEST_P(DEVariantTest, ShiftedAckley) {
  DE3 de(makeConfig(GetParam(), 40, 300, 0.5, 0.9));
  std::mt19937_64 rng(4);
  const auto r = de.minimize(shiftedAckley, box(-5), box(5), {}, rng);
  EXPECT_LT(r.best_cost, 1e-6);
  EXPECT_LT((r.best - kAckleyShift).norm(), 1e-6);
}

// ---- bounds ---------------------------------------------------------------------------------------------
// The optimum lies outside the box, so mutants leave it all the time: every evaluated vector and every
// member of the final population must still be inside, and (bounce-back, not clipping) practically none may
// sit exactly on a bound. The best must approach the corner nearest the optimum.
void checkBounds(const Variant& v, DE3::BoundHandling handling, double corner_tolerance) {
  auto cfg = makeConfig(v, 20, 60);
  cfg.bounds = handling;
  DE3 de(cfg);
  const V3 lo(-1, -2, 0.5), hi(1, 2, 3);
  Recorder rec{[](const V3& x) { return (x - V3(10, -10, -10)).squaredNorm(); }, {}, {}};
  std::mt19937_64 rng(5);
  const auto r = de.minimize(std::ref(rec), lo, hi, {}, rng);
  ASSERT_EQ(static_cast<int>(rec.xs.size()), r.evaluations);
  int on_bound = 0, on_bound_gen1 = 0;
  for (size_t k = 0; k < rec.xs.size(); ++k) {
    const V3& x = rec.xs[k];
    for (int j = 0; j < 3; ++j) {
      ASSERT_GE(x(j), lo(j)) << v.name;
      ASSERT_LE(x(j), hi(j)) << v.name;
      const bool on = x(j) == lo(j) || x(j) == hi(j);
      on_bound += on && k < 11 * static_cast<size_t>(cfg.population);
      on_bound_gen1 += on && k < 2 * static_cast<size_t>(cfg.population);
    }
  }
  // No member of the initial population is on a bound, so no first-generation trial may be; later a base
  // vector converging onto the corner can make a bounce land on it by rounding (best/1), but rarely in the
  // first 10 generations. Clipping puts ~70-90 % of all components there (checked when writing this test).
  EXPECT_EQ(on_bound_gen1, 0) << v.name << ": looks like clipping";
  EXPECT_LT(on_bound, 11 * cfg.population * 3 / 10) << v.name << ": looks like clipping";
  for (const V3& x : r.population) {
    EXPECT_TRUE((x.array() >= lo.array()).all() && (x.array() <= hi.array()).all()) << v.name;
  }
  EXPECT_LT((r.best - V3(1, -2, 0.5)).norm(), corner_tolerance) << v.name;
}

TEST_P(DEVariantTest, BounceBackStaysInsideWithoutClipping) {
  checkBounds(GetParam(), DE3::BoundHandling::kBounceBack, 0.2);
}
// Re-drawing loses the information of how far outside the mutant was: slower towards the corner.
TEST_P(DEVariantTest, RedrawStaysInsideWithoutClipping) {
  checkBounds(GetParam(), DE3::BoundHandling::kRedraw, 0.5);
}

// ---- determinism ----------------------------------------------------------------------------------------
TEST_P(DEVariantTest, SameSeedSameResultDifferentSeedDifferentTrajectory) {
  DE3 de(makeConfig(GetParam(), 12, 20));
  auto run = [&](uint64_t seed, Recorder& rec) {
    std::mt19937_64 rng(seed);
    return de.minimize(std::ref(rec), box(-3), box(3), {V3(0.1, 0.2, 0.3)}, rng);
  };
  Recorder a{rastrigin, {}, {}}, b{rastrigin, {}, {}}, c{rastrigin, {}, {}};
  const auto ra = run(42, a), rb = run(42, b), rc = run(43, c);
  ASSERT_EQ(a.xs.size(), b.xs.size());
  for (size_t k = 0; k < a.xs.size(); ++k) ASSERT_EQ(a.xs[k], b.xs[k]) << "evaluation " << k;
  EXPECT_EQ(ra.best, rb.best);
  EXPECT_EQ(ra.best_cost, rb.best_cost);
  EXPECT_EQ(ra.costs, rb.costs);
  EXPECT_EQ(ra.population, rb.population);
  EXPECT_EQ(ra.generations, rb.generations);
  EXPECT_EQ(ra.evaluations, rb.evaluations);
  size_t same = 0;
  for (size_t k = 1; k < std::min(a.xs.size(), c.xs.size()); ++k) same += (a.xs[k] == c.xs[k]);
  EXPECT_LT(same, a.xs.size() / 10) << "a different seed must give a different trajectory";
  EXPECT_EQ(a.xs[0], c.xs[0]) << "the seed vector is the first member whatever the rng";
}

// ---- crossover: j_rand, CR, synchronous greedy selection ------------------------------------------------
// Replays the run from the recorded evaluations (documented order: NP initial members, then trial i of each
// generation) and counts how many components each trial takes from its mutant, i.e. differ from its target.
// In the first generation (a uniform random population) the count is exact. Later, a member left unchanged
// since an earlier generation can be re-created exactly (same r1, r2, r3 over unchanged members), and equal
// coordinates make a difference vector zero, so a mutant component may equal the target's: there only a
// small share of the trials of the next generations may fall below the expected count (best/1 collapses
// fast on a sphere, so only the first 5 generations are counted). Returns the histogram (all generations).
std::vector<int> checkCrossover(const Variant& v, double CR, int expect_min, int expect_max) {
  std::vector<int> histogram(4, 0);
  const int np = 10, gens = 20;
  DE3 de(makeConfig(v, np, gens, 0.6, CR));
  Recorder rec{sphere, {}, {}};
  std::mt19937_64 rng(7);
  const auto r = de.minimize(std::ref(rec), box(-100), box(100), {}, rng);
  EXPECT_EQ(static_cast<int>(rec.xs.size()), np * (gens + 1));
  if (static_cast<int>(rec.xs.size()) != np * (gens + 1)) return histogram;
  std::vector<V3> pop(rec.xs.begin(), rec.xs.begin() + np);
  std::vector<double> costs(rec.cs.begin(), rec.cs.begin() + np);
  int below = 0;
  for (int g = 0; g < gens; ++g) {
    std::vector<V3> next = pop;
    std::vector<double> next_costs = costs;
    for (int i = 0; i < np; ++i) {
      const size_t k = static_cast<size_t>(np + g * np + i);
      const V3& trial = rec.xs[k];
      int changed = 0;
      for (int j = 0; j < 3; ++j) changed += (trial(j) != pop[i](j));
      ++histogram[changed];
      EXPECT_LE(changed, expect_max) << v.name << " gen " << g << " member " << i;
      if (g == 0) {
        EXPECT_GE(changed, expect_min) << v.name << " member " << i;
      }
      below += g < 5 && changed < expect_min;
      if (rec.cs[k] <= costs[i]) {
        next[i] = trial;
        next_costs[i] = rec.cs[k];
      }
    }
    pop.swap(next);
    costs.swap(next_costs);
  }
  EXPECT_LE(below, np * 5 / 10) << v.name;
  EXPECT_EQ(pop, r.population) << v.name << ": greedy synchronous selection replay differs";
  EXPECT_EQ(costs, r.costs);
  return histogram;
}

TEST_P(DEVariantTest, JRandGuaranteesOneMutantComponentAtCR0) {
  // jDE re-draws CR per trial, so only the lower limit (j_rand) holds there.
  checkCrossover(GetParam(), 0.0, 1, GetParam().jde ? 3 : 1);
}
TEST_P(DEVariantTest, CR1TakesEveryComponentFromTheMutant) {
  if (!GetParam().jde) {
    checkCrossover(GetParam(), 1.0, 3, 3);
  } else {
    // jDE re-draws CR ~ U(0, 1) with probability 0.1 per trial, and a redrawn CR survives with its trial:
    // some trials must then take fewer than all components.
    const auto h = checkCrossover(GetParam(), 1.0, 1, 3);
    EXPECT_GT(h[1] + h[2], 0);
    EXPECT_GT(h[3], 0);
  }
}

INSTANTIATE_TEST_SUITE_P(AllStrategies, DEVariantTest, ::testing::ValuesIn(allVariants()),
                         [](const ::testing::TestParamInfo<Variant>& info) { return info.param.name; });

// ---- mutation formulas ----------------------------------------------------------------------------------
// With CR = 1 and a box too wide to be left, each first-generation trial must be exactly the mutant of its
// strategy built from the initial population (distinct indices, all ≠ i).
TEST(DifferentialEvolution, MutationFormulas) {
  const int np = 8;
  const double F = 0.7;
  for (Strategy s : {Strategy::kRand1Bin, Strategy::kBest1Bin, Strategy::kCurrentToBest1Bin}) {
    DE3 de(makeConfig({s, false, false, ""}, np, 1, F, 1.0));
    Recorder rec{sphere, {}, {}};
    std::mt19937_64 rng(11);
    // Initial population in [-1, 1]^3 (seeds), box ±1000 so no bound handling can happen.
    std::vector<V3> seeds;
    std::mt19937_64 srng(99);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int i = 0; i < np; ++i) seeds.emplace_back(u(srng), u(srng), u(srng));
    de.minimize(std::ref(rec), box(-1000), box(1000), seeds, rng);
    ASSERT_EQ(static_cast<int>(rec.xs.size()), 2 * np);
    int best = 0;
    for (int i = 1; i < np; ++i) best = rec.cs[i] < rec.cs[best] ? i : best;
    for (int i = 0; i < np; ++i) {
      const V3& t = rec.xs[np + i];
      bool found = false;
      for (int a = 0; a < np && !found; ++a) {
        for (int b = 0; b < np && !found; ++b) {
          for (int c = 0; c < np && !found; ++c) {
            const std::vector<int> idx = s == Strategy::kRand1Bin ? std::vector<int>{a, b, c}
                                                                 : std::vector<int>{a, b};
            if (s != Strategy::kRand1Bin && c > 0) continue;
            bool ok = true;
            for (size_t p = 0; p < idx.size(); ++p) {
              ok = ok && idx[p] != i;
              for (size_t q = p + 1; q < idx.size(); ++q) ok = ok && idx[p] != idx[q];
            }
            if (!ok) continue;
            const V3& xa = seeds[a];
            const V3& xb = seeds[b];
            V3 v;
            if (s == Strategy::kRand1Bin) {
              v = xa + F * (xb - seeds[c]);
            } else if (s == Strategy::kBest1Bin) {
              v = seeds[best] + F * (xa - xb);
            } else {
              v = seeds[i] + F * (seeds[best] - seeds[i]) + F * (xa - xb);
            }
            found = (v - t).norm() < 1e-12;
          }
        }
      }
      EXPECT_TRUE(found) << "strategy " << static_cast<int>(s) << " trial " << i;
    }
  }
}

// jDE: a trial's F is the member's F, or with probability τ1 = 0.1 a fresh F ~ U(0.1, 1.0). Recover each
// first-generation rand/1 trial's F from its mutant components and check both kinds occur, all in range.
TEST(DifferentialEvolution, JdeRedrawsFWithinRange) {
  const int np = 40;
  auto cfg = makeConfig(allVariants()[2], np, 1, 0.6, 1.0);
  ASSERT_TRUE(cfg.jde);
  Recorder rec{sphere, {}, {}};
  std::vector<V3> seeds;
  std::mt19937_64 srng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < np; ++i) seeds.emplace_back(u(srng), u(srng), u(srng));
  std::mt19937_64 rng(12);
  DE3(cfg).minimize(std::ref(rec), box(-1000), box(1000), seeds, rng);
  ASSERT_EQ(static_cast<int>(rec.xs.size()), 2 * np);
  int configured = 0, redrawn = 0, explained = 0;
  for (int i = 0; i < np; ++i) {
    const V3& t = rec.xs[np + i];
    std::vector<int> changed;
    for (int j = 0; j < 3; ++j) {
      if (t(j) != seeds[i](j)) changed.push_back(j);
    }
    if (changed.size() < 2) continue;  // CR re-drawn low: F not identifiable
    bool found = false;
    for (int a = 0; a < np && !found; ++a) {
      for (int b = 0; b < np && !found; ++b) {
        for (int c = 0; c < np && !found; ++c) {
          if (a == i || b == i || c == i || a == b || a == c || b == c) continue;
          const int j0 = changed[0];
          const double f = (t(j0) - seeds[a](j0)) / (seeds[b](j0) - seeds[c](j0));
          bool ok = f > 0.0;  // (a, c, b) explains the same trial with −F
          for (int j : changed) ok = ok && std::abs(seeds[a](j) + f * (seeds[b](j) - seeds[c](j)) - t(j)) < 1e-9;
          if (!ok) continue;
          found = true;
          EXPECT_GE(f, 0.1 - 1e-9);
          EXPECT_LE(f, 1.0 + 1e-9);
          (std::abs(f - 0.6) < 1e-9 ? configured : redrawn)++;
        }
      }
    }
    explained += found;
  }
  EXPECT_GT(explained, np / 2);
  EXPECT_GT(configured, redrawn);
  EXPECT_GT(redrawn, 0);
}

// ---- selection uses ≤ ------------------------------------------------------------------------------------
TEST(DifferentialEvolution, EqualCostTrialReplacesTarget) {
  DE3 de(makeConfig(allVariants()[0], 10, 1));
  Recorder rec{[](const V3&) { return 1.0; }, {}, {}};
  std::mt19937_64 rng(3);
  const auto r = de.minimize(std::ref(rec), box(-1), box(1), {}, rng);
  ASSERT_EQ(rec.xs.size(), 20u);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(r.population[i], rec.xs[10 + i]);
}

// ---- seeds ----------------------------------------------------------------------------------------------
TEST(DifferentialEvolution, SeedsAreInTheInitialPopulationClampedIntoBounds) {
  DE3 de(makeConfig(allVariants()[0], 6, 0));
  std::mt19937_64 rng(5);
  const std::vector<V3> seeds = {V3(0.5, -0.25, 0.125), V3(10, -10, 0.2)};
  const auto r = de.minimize(sphere, box(-1), box(1), seeds, rng);
  ASSERT_EQ(r.population.size(), 6u);
  EXPECT_EQ(r.generations, 0);
  EXPECT_EQ(r.evaluations, 6);
  EXPECT_EQ(r.population[0], seeds[0]);
  EXPECT_EQ(r.population[1], V3(1, -1, 0.2));
  for (size_t i = 2; i < r.population.size(); ++i) {
    EXPECT_NE(r.population[i], seeds[0]);
    EXPECT_TRUE((r.population[i].array().abs() <= 1.0).all());
  }
  // The best of the initial population is reported.
  int best = 0;
  for (int i = 1; i < 6; ++i) best = r.costs[i] < r.costs[best] ? i : best;
  EXPECT_EQ(r.best, r.population[best]);
}

TEST(DifferentialEvolution, SeededOptimumIsKeptExactly) {
  DE3 de(makeConfig(allVariants()[0], 10, 5));
  std::mt19937_64 rng(6);
  const V3 opt(0.3, -0.2, 0.1);
  const auto r = de.minimize([&](const V3& x) { return (x - opt).squaredNorm(); }, box(-1), box(1), {opt}, rng);
  EXPECT_EQ(r.best_cost, 0.0);
  EXPECT_EQ(r.best, opt);
}

TEST(DifferentialEvolution, MoreSeedsThanPopulationUsesTheFirstOnes) {
  DE3 de(makeConfig(allVariants()[0], 4, 0));
  std::vector<V3> seeds;
  for (int i = 0; i < 7; ++i) seeds.push_back(box(0.1 * i));
  std::mt19937_64 rng(1);
  const auto r = de.minimize(sphere, box(-1), box(1), seeds, rng);
  ASSERT_EQ(r.population.size(), 4u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(r.population[i], seeds[i]);
}

// ---- stopping -------------------------------------------------------------------------------------------
TEST(DifferentialEvolution, StopsOnSpreadTolerance) {
  auto cfg = makeConfig(allVariants()[0], 20, 2000);
  cfg.spread_tolerance = V3(1e-4, 1e-4, 1e-5);
  DE3 de(cfg);
  std::mt19937_64 rng(8);
  const auto r = de.minimize(sphere, box(-5), box(5), {}, rng);
  EXPECT_GT(r.generations, 0);
  EXPECT_LT(r.generations, 2000);
  EXPECT_EQ(r.evaluations, 20 * (r.generations + 1));
  for (int j = 0; j < 3; ++j) {
    double lo = 1e300, hi = -1e300;
    for (const V3& x : r.population) {
      lo = std::min(lo, x(j));
      hi = std::max(hi, x(j));
    }
    EXPECT_LT(hi - lo, cfg.spread_tolerance(j));
  }
  // Off (zero tolerance): all generations are run.
  cfg.spread_tolerance = V3::Zero();
  std::mt19937_64 rng2(8);
  EXPECT_EQ(DE3(cfg).minimize(sphere, box(-5), box(5), {}, rng2).generations, 2000);
}

TEST(DifferentialEvolution, StopsOnStall) {
  auto cfg = makeConfig(allVariants()[0], 20, 1000);
  cfg.stall_generations = 25;
  std::mt19937_64 rng(9);
  // Nothing can ever improve: exactly k generations.
  const auto flat = DE3(cfg).minimize([](const V3&) { return 3.0; }, box(-1), box(1), {}, rng);
  EXPECT_EQ(flat.generations, 25);
  // A floored sphere improves for a while, then stalls at the floor.
  const auto floored =
      DE3(cfg).minimize([](const V3& x) { return std::max(x.squaredNorm(), 1e-4); }, box(-5), box(5), {}, rng);
  EXPECT_GT(floored.generations, 25);
  EXPECT_LT(floored.generations, 1000);
  EXPECT_EQ(floored.best_cost, 1e-4);
}

// ---- invalid input --------------------------------------------------------------------------------------
TEST(DifferentialEvolution, RejectsInvalidInput) {
  std::mt19937_64 rng(1);
  for (int np : {-1, 0, 1, 2, 3}) {
    auto cfg = makeConfig(allVariants()[0], np, 5);
    EXPECT_THROW(DE3(cfg).minimize(sphere, box(-1), box(1), {}, rng), std::invalid_argument) << np;
  }
  auto cfg = makeConfig(allVariants()[0], 4, 5);
  EXPECT_NO_THROW(DE3(cfg).minimize(sphere, box(-1), box(1), {}, rng));
  EXPECT_THROW(DE3(cfg).minimize(sphere, box(1), box(-1), {}, rng), std::invalid_argument);
  auto bad_cr = cfg;
  bad_cr.CR = 1.5;
  EXPECT_THROW(DE3(bad_cr).minimize(sphere, box(-1), box(1), {}, rng), std::invalid_argument);
  DEX::Config xc;
  xc.population = 5;
  DEX dx(xc);
  const Eigen::VectorXd lo = Eigen::VectorXd::Constant(3, -1), hi = Eigen::VectorXd::Constant(3, 1);
  auto xs = [](const Eigen::VectorXd& x) { return x.squaredNorm(); };
  EXPECT_THROW(dx.minimize(xs, lo, Eigen::VectorXd::Constant(2, 1), {}, rng), std::invalid_argument);
  EXPECT_THROW(dx.minimize(xs, lo, hi, {Eigen::VectorXd::Zero(2)}, rng), std::invalid_argument);
}

// ---- dynamic dimension ----------------------------------------------------------------------------------
TEST(DifferentialEvolution, DynamicDimensionMatchesFixedAndSolves5D) {
  const auto v = allVariants()[2];  // rand1 + jDE
  DE3 fixed(makeConfig(v, 15, 40));
  DEX::Config xc;
  xc.population = 15;
  xc.max_generations = 40;
  xc.jde = true;
  DEX dyn(xc);
  std::mt19937_64 r1(21), r2(21);
  const auto rf = fixed.minimize(rastrigin, box(-3), box(3), {}, r1);
  const auto rd = dyn.minimize([](const Eigen::VectorXd& x) { return rastrigin(V3(x)); },
                               Eigen::VectorXd::Constant(3, -3), Eigen::VectorXd::Constant(3, 3), {}, r2);
  EXPECT_EQ(rf.best, V3(rd.best));
  EXPECT_EQ(rf.costs, rd.costs);

  xc.max_generations = 300;
  std::mt19937_64 r3(22);
  const auto r5 = DEX(xc).minimize([](const Eigen::VectorXd& x) { return (x.array() - 0.5).square().sum(); },
                                   Eigen::VectorXd::Constant(5, -2), Eigen::VectorXd::Constant(5, 2), {}, r3);
  ASSERT_EQ(r5.best.size(), 5);
  EXPECT_LT((r5.best.array() - 0.5).abs().maxCoeff(), 1e-3);
}

// ---- dither and jDE change the search -------------------------------------------------------------------
TEST(DifferentialEvolution, DitherAndJdeChangeTheTrajectory) {
  auto trajectory = [](const Variant& v) {
    Recorder rec{sphere, {}, {}};
    std::mt19937_64 rng(31);
    DE3(makeConfig(v, 10, 3)).minimize(std::ref(rec), box(-1), box(1), {}, rng);
    return rec.xs;
  };
  const auto plain = trajectory(allVariants()[0]);
  const auto dither = trajectory(allVariants()[1]);
  const auto jde = trajectory(allVariants()[2]);
  EXPECT_NE(plain, dither);
  EXPECT_NE(plain, jde);
  EXPECT_NE(dither, jde);
}

}  // namespace
