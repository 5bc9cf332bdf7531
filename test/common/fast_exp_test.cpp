#include "laser_dpslam/common/fast_exp.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

using laser_dpslam::negExp;

TEST(FastExp, MatchesStdExpToARelativeErrorOfThreeTenBillionths) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 40.0);
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    const double x = u(rng);
    worst = std::max(worst, std::abs(negExp(x) - std::exp(-x)) / std::exp(-x));
  }
  EXPECT_LT(worst, 3e-10);
}

TEST(FastExp, IsExactAtTheTableNodesAndContinuousAcrossThem) {
  for (int k = 0; k <= 32 * 32; ++k) {
    const double x = k / 32.0;
    EXPECT_DOUBLE_EQ(negExp(x), std::exp(-x)) << x;
    const double below = std::nextafter(x, -1.0);
    if (below >= 0.0) {
      EXPECT_NEAR(negExp(below) / negExp(x), 1.0, 1e-9) << x;
    }
  }
}

TEST(FastExp, FallsBackToStdExpOutsideTheTable) {
  EXPECT_DOUBLE_EQ(negExp(-2.0), std::exp(2.0));
  EXPECT_DOUBLE_EQ(negExp(50.0), std::exp(-50.0));
  EXPECT_EQ(negExp(std::numeric_limits<double>::infinity()), 0.0);
  EXPECT_TRUE(std::isnan(negExp(std::numeric_limits<double>::quiet_NaN())));
  EXPECT_EQ(negExp(0.0), 1.0);
}
