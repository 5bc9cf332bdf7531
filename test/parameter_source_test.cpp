#include "laser_dpslam/parameter_source.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "laser_dpslam/dpslam_parameters.h"
#include "laser_dpslam/odometry_parameters.h"

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
  LaserOdometryConfig o;
  ScanPreprocessorConfig p;
  readOdometryParameters(odometry, o, p);
  odometry.markKnown(odometryNodeKeys());
  EXPECT_TRUE(odometry.unknownKeys().empty()) << odometry.unknownKeys().front();

  const YamlParameterSource slam = YamlParameterSource::load("config/dpslam.yaml");
  DpSlamConfig c;
  readDpSlamParameters(slam, c);
  slam.markKnown(dpslamNodeKeys());
  EXPECT_TRUE(slam.unknownKeys().empty()) << slam.unknownKeys().front();
}

// The shipped files document every parameter: each key a reader asks for is in its file (a key missing
// there would leave its default undocumented, and the defaults test could not see it).
TEST(ParameterSource, TheShippedFilesHoldEveryKeyTheReadersRead) {
  const YamlParameterSource empty = yaml("{}");
  LaserOdometryConfig o;
  ScanPreprocessorConfig p;
  readOdometryParameters(empty, o, p);
  const std::vector<std::string> odometry = YamlParameterSource::load("config/laser_odometry.yaml").keys();
  for (const std::string& k : empty.knownKeys()) {
    EXPECT_NE(std::find(odometry.begin(), odometry.end(), k), odometry.end()) << k << " missing in config/laser_odometry.yaml";
  }
  const YamlParameterSource empty_slam = yaml("{}");
  DpSlamConfig c;
  readDpSlamParameters(empty_slam, c);
  const std::vector<std::string> slam = YamlParameterSource::load("config/dpslam.yaml").keys();
  for (const std::string& k : empty_slam.knownKeys()) {
    EXPECT_NE(std::find(slam.begin(), slam.end(), k), slam.end()) << k << " missing in config/dpslam.yaml";
  }
}
