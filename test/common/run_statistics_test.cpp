#include "laser_dpslam/common/run_statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace laser_dpslam;

TEST(RunStatistics, SummaryIsMedianNearestRankP95AndMax) {
  const TimingSummary empty = summarize({});
  EXPECT_EQ(empty.median, 0.0);
  EXPECT_EQ(empty.p95, 0.0);
  EXPECT_EQ(empty.max, 0.0);
  const TimingSummary odd = summarize({5.0, 1.0, 3.0});
  EXPECT_EQ(odd.median, 3.0);
  EXPECT_EQ(odd.p95, 5.0);
  EXPECT_EQ(odd.max, 5.0);
  EXPECT_EQ(summarize({4.0, 1.0, 2.0, 3.0}).median, 2.5);  // even count: mean of the middle two
  std::vector<double> hundred;
  for (int i = 100; i >= 1; --i) hundred.push_back(i);
  const TimingSummary h = summarize(hundred);
  EXPECT_EQ(h.p95, 95.0);  // nearest rank: ceil(0.95 n)-th smallest
  EXPECT_EQ(h.median, 50.5);
  EXPECT_EQ(h.max, 100.0);
  EXPECT_EQ(summarize({7.0}).p95, 7.0);
}

TEST(RunStatistics, JsonHelpersWriteValidJson) {
  EXPECT_EQ(jsonNumber(1.5), "1.5");
  EXPECT_EQ(jsonNumber(0.0001234567), "0.000123457");
  EXPECT_EQ(jsonNumber(std::nan("")), "null");
  EXPECT_EQ(jsonNumber(std::numeric_limits<double>::infinity()), "null");
  EXPECT_EQ(jsonString("a\"b\\c"), "\"a\\\"b\\\\c\"");
  EXPECT_EQ(jsonString("line\nnext"), "\"line\\u000anext\"");
  EXPECT_EQ(jsonTiming({1.0, 2.5, 3.0}), "{\"median\": 1, \"p95\": 2.5, \"max\": 3}");
  EXPECT_EQ(jsonCounts({}), "{}");
  EXPECT_EQ(jsonCounts({{"too_few_points", 2}, {"match_failed", 1}}), "{\"match_failed\": 1, \"too_few_points\": 2}");
}

TEST(RunStatistics, ClocksAndMemoryMove) {
  const double thread0 = threadCpuSeconds(), process0 = processCpuSeconds();
  volatile double x = 0.0;
  for (int i = 0; i < 20000000; ++i) x = x + std::sqrt(static_cast<double>(i));
  EXPECT_GT(threadCpuSeconds(), thread0);
  EXPECT_GE(processCpuSeconds(), process0 + (threadCpuSeconds() - thread0) * 0.5);
  const double before = currentRssMb();
  ASSERT_TRUE(std::isfinite(before));  // Linux: /proc/self/status has VmRSS
  std::vector<char> block(64 << 20, 1);  // 64 MB, touched
  EXPECT_GT(currentRssMb(), before + 32.0) << static_cast<int>(block[12345]);
  EXPECT_GE(peakRssMb(), currentRssMb() - 1.0);
}
