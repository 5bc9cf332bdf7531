#include "laser_dpslam/slam/slam_load_monitor.h"

#include <gtest/gtest.h>

using namespace laser_dpslam;

TEST(SlamLoadMonitor, SummaryKeepsLastMeanAndMax) {
  RunningSummary s;
  EXPECT_EQ(s.max, 0.0);
  s.add(-2.0);
  EXPECT_EQ(s.max, -2.0);  // the first value, even below zero
  s.add(4.0);
  s.add(1.0);
  EXPECT_EQ(s.count, 3u);
  EXPECT_EQ(s.last, 1.0);
  EXPECT_DOUBLE_EQ(s.mean, 1.0);
  EXPECT_EQ(s.max, 4.0);
}

TEST(SlamLoadMonitor, KeepingUpIsOk) {
  SlamLoadMonitor m(1.0);
  for (int i = 0; i < 10; ++i) {
    m.received(100.0 + 0.1 * i);
    m.processed(100.0 + 0.1 * i, 0.03, 100.0 + 0.1 * i + 0.05);
  }
  const SlamLoadReport r = m.report(0);
  EXPECT_FALSE(r.warn);
  EXPECT_EQ(r.message, "keeping up");
  EXPECT_EQ(r.received, 10u);
  EXPECT_EQ(r.processed, 10u);
  EXPECT_NEAR(r.lag_s.mean, 0.05, 1e-9);
  EXPECT_NEAR(r.processing_s.max, 0.03, 1e-12);
  EXPECT_NEAR(r.backlog_s, 0.0, 1e-12);
}

// A warning lasts while its cause does: skips and lags are counted per reporting window.
TEST(SlamLoadMonitor, SkipsAndLagWarnUntilAWindowWithout) {
  SlamLoadMonitor m(1.0);
  m.received(10.0);
  m.processed(10.0, 0.2, 10.3);
  SlamLoadReport r = m.report(2);
  EXPECT_TRUE(r.warn);
  EXPECT_EQ(r.skipped, 2u);
  EXPECT_EQ(r.skipped_recent, 2u);
  EXPECT_NE(r.message.find("2 scans skipped"), std::string::npos);
  r = m.report(2);
  EXPECT_FALSE(r.warn) << r.message;
  EXPECT_EQ(r.skipped_recent, 0u);
  EXPECT_EQ(r.skipped, 2u);

  m.received(11.0);
  m.processed(11.0, 1.5, 12.5);
  r = m.report(2);
  EXPECT_TRUE(r.warn);
  EXPECT_NEAR(r.lag_recent_max_s, 1.5, 1e-12);
  EXPECT_NE(r.message.find("lag 1.50 s"), std::string::npos) << r.message;
  r = m.report(2);
  EXPECT_FALSE(r.warn) << r.message;
  EXPECT_NEAR(r.lag_s.max, 1.5, 1e-12);  // the run's max stays
}

// A step that never ends shows as scans arriving far ahead of the last output.
TEST(SlamLoadMonitor, AStuckStepWarnsBeforeItEnds) {
  SlamLoadMonitor m(1.0);
  m.received(20.0);
  m.processed(20.0, 0.05, 20.1);
  for (int i = 1; i <= 15; ++i) m.received(20.0 + 0.1 * i);
  const SlamLoadReport r = m.report(0);
  EXPECT_TRUE(r.warn);
  EXPECT_NEAR(r.backlog_s, 1.5, 1e-9);
  EXPECT_NE(r.message.find("ahead of map->odom"), std::string::npos) << r.message;
}
