#include "laser_dpslam/scan/scan_resampler.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

using namespace laser_dpslam;

namespace {
// 360 beams from the middle of a 4 m x 4 m square room.
PreprocessedScan squareRoom() {
  LaserScan s;
  s.angle_min = -M_PI;
  s.angle_increment = 2.0 * M_PI / 360.0;
  s.angle_max = s.angle_min + 359 * s.angle_increment;
  s.range_min = 0.02;
  s.range_max = 5.6;
  for (int i = 0; i < 360; ++i) {
    const double a = s.angle_min + i * s.angle_increment;
    s.ranges.push_back(static_cast<float>(std::min(2.0 / std::fabs(std::cos(a)), 2.0 / std::fabs(std::sin(a)))));
  }
  return preprocessScan(s, ScanPreprocessorConfig());
}

const ResamplingMethod kAll[] = {ResamplingMethod::kNone, ResamplingMethod::kEveryKth, ResamplingMethod::kUniform,
                                 ResamplingMethod::kSaliency};
}  // namespace

TEST(ScanResampler, NamesReadBackAndUnknownOnesListTheValidOnes) {
  for (ResamplingMethod m : kAll) EXPECT_EQ(parseResamplingMethod(resamplingMethodName(m)), m);
  EXPECT_STREQ(resamplingMethodName(ResamplingMethod::kSaliency), "saliency");
  try {
    parseResamplingMethod("Saliency");
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("none, every_kth, uniform, saliency"), std::string::npos) << e.what();
  }
}

TEST(ScanResampler, NoneKeepsEveryPointWhateverTheBudget) {
  const PreprocessedScan scan = squareRoom();
  ASSERT_EQ(scan.points.size(), 360u);
  const std::vector<int> idx = resampleIndices(scan, ResamplingMethod::kNone, 10, SaliencyConfig(), 1);
  ASSERT_EQ(idx.size(), 360u);
  for (int i = 0; i < 360; ++i) EXPECT_EQ(idx[static_cast<std::size_t>(i)], i);
  EXPECT_EQ(resampleScan(scan, ResamplingMethod::kNone, 10, SaliencyConfig(), 1).size(), 360u);
}

// Every method: ascending, distinct, valid indices, at most the budget, and the points are those indices'.
TEST(ScanResampler, MethodsKeepAtMostTheBudgetInBeamOrder) {
  const PreprocessedScan scan = squareRoom();
  for (ResamplingMethod m : {ResamplingMethod::kEveryKth, ResamplingMethod::kUniform, ResamplingMethod::kSaliency}) {
    SCOPED_TRACE(resamplingMethodName(m));
    const std::vector<int> idx = resampleIndices(scan, m, 50, SaliencyConfig(), 7);
    EXPECT_LE(idx.size(), 50u);
    EXPECT_GE(idx.size(), 25u);  // a budget is a target, not a loose bound
    for (std::size_t i = 0; i < idx.size(); ++i) {
      EXPECT_GE(idx[i], 0);
      EXPECT_LT(idx[i], 360);
      if (i > 0) {
        EXPECT_LT(idx[i - 1], idx[i]);
      }
    }
    const std::vector<Eigen::Vector2d> pts = resampleScan(scan, m, 50, SaliencyConfig(), 7);
    ASSERT_EQ(pts.size(), idx.size());
    for (std::size_t i = 0; i < idx.size(); ++i) EXPECT_EQ(pts[i], scan.points[static_cast<std::size_t>(idx[i])]);
  }
}

TEST(ScanResampler, SameSeedSameChoiceAndEveryKthIsRegular) {
  const PreprocessedScan scan = squareRoom();
  EXPECT_EQ(resampleIndices(scan, ResamplingMethod::kSaliency, 40, SaliencyConfig(), 3),
            resampleIndices(scan, ResamplingMethod::kSaliency, 40, SaliencyConfig(), 3));
  const std::vector<int> kth = resampleIndices(scan, ResamplingMethod::kEveryKth, 90, SaliencyConfig(), 1);
  ASSERT_EQ(kth.size(), 90u);  // k = ceil(360 / 90) = 4
  for (std::size_t i = 0; i < kth.size(); ++i) EXPECT_EQ(kth[i], static_cast<int>(4 * i));
  EXPECT_TRUE(resampleIndices(scan, ResamplingMethod::kUniform, 0, SaliencyConfig(), 1).empty());
  EXPECT_EQ(resampleIndices(scan, ResamplingMethod::kUniform, 1000, SaliencyConfig(), 1).size(), 360u);
}
