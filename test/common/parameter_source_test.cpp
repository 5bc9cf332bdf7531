#include "laser_dpslam/common/parameter_source.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "laser_dpslam/odometry/odometry_parameters.h"
#include "laser_dpslam/slam/dpslam_parameters.h"

using namespace laser_dpslam;

namespace {
YamlParameterSource yaml(const std::string& text) { return YamlParameterSource(YAML::Load(text)); }
}  // namespace

TEST(ParameterSource, EditDistanceCountsInsertionsDeletionsAndSubstitutions) {
  EXPECT_EQ(editDistance("", ""), 0);
  EXPECT_EQ(editDistance("seed", "seed"), 0);
  EXPECT_EQ(editDistance("keyframe_distanse", "keyframe_distance"), 1);
  EXPECT_EQ(editDistance("partcles", "particles"), 1);
  EXPECT_EQ(editDistance("particles", "particles_"), 1);
  EXPECT_EQ(editDistance("kitten", "sitting"), 3);
  EXPECT_EQ(editDistance("", "abc"), 3);
}

TEST(ParameterSource, KeysThatNobodyAskedForAreReportedWithTheClosestKnownOne) {
  const YamlParameterSource s = yaml("keyframe_distanse: 0.3\nseed: 2\nwhatever_this_is: 1\n");
  std::vector<std::string> keys = s.keys();
  EXPECT_EQ(keys.size(), 3u);
  double d = 0.0;
  int seed = 0;
  EXPECT_FALSE(s.get("keyframe_distance", d));  // the misspelt key does not set it
  EXPECT_TRUE(s.get("seed", seed));
  EXPECT_EQ(seed, 2);
  const std::vector<std::string> unknown = s.unknownKeys();
  ASSERT_EQ(unknown.size(), 2u);
  EXPECT_NE(unknown[0].find("'keyframe_distanse'"), std::string::npos) << unknown[0];
  EXPECT_NE(unknown[0].find("did you mean 'keyframe_distance'"), std::string::npos) << unknown[0];
  EXPECT_NE(unknown[1].find("'whatever_this_is'"), std::string::npos) << unknown[1];
  EXPECT_EQ(unknown[1].find("did you mean"), std::string::npos) << unknown[1];  // nothing close
}

TEST(ParameterSource, MarkedKeysCountAsKnown) {
  const YamlParameterSource s = yaml("base_frame: base_footprint\n");
  EXPECT_EQ(s.unknownKeys().size(), 1u);
  s.markKnown({"base_frame"});
  EXPECT_TRUE(s.unknownKeys().empty());
}

// A misspelt odometry or SLAM key in a file is reported by name, not silently ignored.
TEST(ParameterSource, TheReadersFlagAMisspeltKey) {
  const YamlParameterSource s = yaml("resampling_budjet: 80\npartciles: 10\n");
  LaserOdometryConfig o;
  ScanPreprocessorConfig p;
  DpSlamConfig c;
  readOdometryParameters(s, o, p);
  readDpSlamParameters(s, c);
  EXPECT_EQ(o.resampling_budget, LaserOdometryConfig().resampling_budget);
  const std::vector<std::string> unknown = s.unknownKeys();
  ASSERT_EQ(unknown.size(), 2u);
  EXPECT_NE(unknown[0].find("did you mean 'resampling_budget'"), std::string::npos) << unknown[0];
  EXPECT_NE(unknown[1].find("did you mean 'particles'"), std::string::npos) << unknown[1];
}

// Every key of the shipped files is read by its node: none is reported.
TEST(ParameterSource, TheShippedFilesHoldNoUnknownKey) {
  const YamlParameterSource odometry = YamlParameterSource::load("config/laser_odometry.yaml");
  OdometryNodeSettings o;
  readOdometryNodeParameters(odometry, o);
  EXPECT_TRUE(odometry.unknownKeys().empty()) << odometry.unknownKeys().front();

  const YamlParameterSource slam = YamlParameterSource::load("config/dpslam.yaml");
  DpSlamNodeSettings c;
  readDpSlamNodeParameters(slam, c);
  EXPECT_TRUE(slam.unknownKeys().empty()) << slam.unknownKeys().front();
}

// The readers ask for exactly the registry's keys: none is read past it (and so undocumented).
TEST(ParameterSource, TheReadersReadExactlyTheRegistrysKeys) {
  const YamlParameterSource empty = yaml("{}");
  OdometryNodeSettings o;
  readOdometryNodeParameters(empty, o);
  std::set<std::string> odometry;
  for (const auto& p : odometryParameters()) odometry.insert(p.name);
  EXPECT_EQ(empty.knownKeys(), odometry);

  const YamlParameterSource empty_slam = yaml("{}");
  DpSlamNodeSettings c;
  readDpSlamNodeParameters(empty_slam, c);
  std::set<std::string> slam;
  for (const auto& p : dpslamParameters()) slam.insert(p.name);
  EXPECT_EQ(empty_slam.knownKeys(), slam);
}
