#include "laser_dpslam/common/parameter_registry.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "laser_dpslam/common/parameter_docs.h"
#include "laser_dpslam/odometry/odometry_parameters.h"
#include "laser_dpslam/slam/dpslam_parameters.h"

using namespace laser_dpslam;

namespace {
YamlParameterSource yaml(const std::string& text) { return YamlParameterSource(YAML::Load(text)); }

std::string join(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& l : lines) out += l + "\n";
  return out;
}

template <class S>
std::size_t userKeys(const std::vector<Parameter<S>>& registry) {
  std::size_t n = 0;
  for (const Parameter<S>& p : registry) n += p.advanced() ? 0 : 1;
  return n;
}

// Names unique, every field documented, every default inside its own range.
template <class S>
void expectWellFormed(const std::vector<Parameter<S>>& registry) {
  std::set<std::string> names;
  for (const Parameter<S>& p : registry) {
    EXPECT_TRUE(names.insert(p.name).second) << "duplicate " << p.name;
    EXPECT_FALSE(std::string(p.topic).empty()) << p.name;
    EXPECT_FALSE(std::string(p.unit).empty()) << p.name;
    EXPECT_FALSE(std::string(p.description).empty()) << p.name;
    S settings;
    // Reading the default back through a source must pass the range check.
    const std::string text = p.name + std::string(": ") + parameterValueText(p, settings);
    EXPECT_NO_THROW(readParameter(yaml(text), p, settings)) << text;
    EXPECT_EQ(parameterValueText(p, settings), parameterValueText(p, S())) << text;
  }
}
}  // namespace

TEST(ParameterRegistry, RangesAreTestedAndWrittenAsIntervals) {
  EXPECT_TRUE(above(0).contains(0.1));
  EXPECT_FALSE(above(0).contains(0.0));
  EXPECT_TRUE(atLeast(0).contains(0.0));
  EXPECT_FALSE(atLeast(3).contains(2.0));
  EXPECT_TRUE(below(0).contains(-1.0));
  EXPECT_FALSE(below(0).contains(0.0));
  EXPECT_FALSE(atMost(1).contains(1.5));
  EXPECT_TRUE(leftOpenInterval(0, 1).contains(1.0));
  EXPECT_FALSE(leftOpenInterval(0, 1).contains(0.0));
  EXPECT_FALSE(closedInterval(0, 1).contains(std::nan("")));
  EXPECT_TRUE(anyValue().contains(-1e300));
  EXPECT_EQ(above(0).text(), "> 0");
  EXPECT_EQ(atLeast(3).text(), ">= 3");
  EXPECT_EQ(below(0).text(), "< 0");
  EXPECT_EQ(atMost(1).text(), "<= 1");
  EXPECT_EQ(closedInterval(0, 1).text(), "[0, 1]");
  EXPECT_EQ(leftOpenInterval(0, 0.5).text(), "(0, 0.5]");
  EXPECT_EQ(anyValue().text(), "any");
}

TEST(ParameterRegistry, NumbersAreWrittenAsShortAsTheyReadBack) {
  EXPECT_EQ(formatParameterNumber(0.25), "0.25");
  EXPECT_EQ(formatParameterNumber(0.17), "0.17");
  EXPECT_EQ(formatParameterNumber(1.0), "1.0");
  EXPECT_EQ(formatParameterNumber(-1.15), "-1.15");
  EXPECT_EQ(formatParameterNumber(0.001), "0.001");
  EXPECT_EQ(formatParameterNumber(-std::numeric_limits<double>::infinity()), "-.inf");
  EXPECT_EQ(std::stod(formatParameterNumber(0.1 + 0.2)), 0.1 + 0.2);
}

TEST(ParameterRegistry, OutOfRangeValuesNameTheKeyTheValueAndTheRange) {
  auto odometryError = [](const std::string& text) {
    try {
      OdometryNodeSettings o;
      readOdometryNodeParameters(yaml(text), o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(odometryError("de_CR: 1.5"), "parameter 'de_CR' = 1.5 is outside its range [0, 1]");
  EXPECT_EQ(odometryError("de_population: 3"), "parameter 'de_population' = 3 is outside its range >= 4");
  EXPECT_EQ(odometryError("window_xy: 0"), "parameter 'window_xy' = 0.0 is outside its range > 0");
  EXPECT_EQ(odometryError("ndt_cell_sizes: []"), "parameter 'ndt_cell_sizes' must not be empty");
  EXPECT_EQ(odometryError("resampling: random"),
            "parameter 'resampling' = 'random': must be one of none, every_kth, uniform, saliency");
  EXPECT_NE(odometryError("angle_min: 1.0\nangle_max: 0.5").find("'angle_min' = 1.0 must be < 'angle_max' = 0.5"),
            std::string::npos);
  EXPECT_EQ(odometryError("de_population: 4"), "no error");

  auto slamError = [](const std::string& text) {
    try {
      DpSlamNodeSettings d;
      readDpSlamNodeParameters(yaml(text), d);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(slamError("beam_log_floor: 0.5"), "parameter 'beam_log_floor' = 0.5 is outside its range < 0");
  EXPECT_EQ(slamError("seed: -1"), "parameter 'seed' = -1 is outside its range >= 0");
  EXPECT_NE(slamError("trace_max_range: 0.01").find("must exceed 'map_resolution'"), std::string::npos);
  EXPECT_EQ(slamError("map_frame: 3"), "no error");  // YAML reads 3 as a string
  EXPECT_NE(slamError("particles: many").find("'particles' must be an integer"), std::string::npos);
}

TEST(ParameterRegistry, TheNodesOwnKeysAreReadIntoTheirSettings) {
  OdometryNodeSettings o;
  readOdometryNodeParameters(yaml("base_frame: base_footprint\npublish_tf: false\ntransform_timeout: 0.5"), o);
  EXPECT_EQ(o.base_frame, "base_footprint");
  EXPECT_FALSE(o.publish_tf);
  EXPECT_EQ(o.transform_timeout, 0.5);
  DpSlamNodeSettings d;
  readDpSlamNodeParameters(yaml("map_frame: world\nmax_range: 4.5\nmap_update_interval: 1\nparticles: 12"), d);
  EXPECT_EQ(d.map_frame, "world");
  EXPECT_EQ(d.preprocessing.max_range, 4.5);
  EXPECT_EQ(d.map_update_interval, 1.0);
  EXPECT_EQ(d.slam.particles, 12);
}

TEST(ParameterRegistry, EveryEntryIsWellFormed) {
  expectWellFormed(odometryParameters());
  expectWellFormed(dpslamParameters());
}

// The shipped files hold exactly the user-facing keys, each at its default; few enough to read.
TEST(ParameterRegistry, TheShippedFilesHoldTheUserFacingKeysAtTheirDefaults) {
  const auto odometry = checkShippedParameters(odometryParameters(), YamlParameterSource::load("config/laser_odometry.yaml"));
  EXPECT_TRUE(odometry.empty()) << "config/laser_odometry.yaml:\n" << join(odometry);
  const auto slam = checkShippedParameters(dpslamParameters(), YamlParameterSource::load("config/dpslam.yaml"));
  EXPECT_TRUE(slam.empty()) << "config/dpslam.yaml:\n" << join(slam);
  EXPECT_LE(userKeys(odometryParameters()) + userKeys(dpslamParameters()), 35u);
}

TEST(ParameterRegistry, TheShippedFileCheckSeesAMissingAWrongAnAdvancedAndAnUnknownKey) {
  const auto problems = checkShippedParameters(
      dpslamParameters(), yaml("particles: 31\nbeam_sigma: 0.13\nparticels: 30\nmap_frame: map\n"));
  const std::string all = join(problems);
  EXPECT_NE(all.find("particles: 31 but the default is 30"), std::string::npos) << all;
  EXPECT_NE(all.find("beam_sigma: advanced"), std::string::npos) << all;
  EXPECT_NE(all.find("particels: not a parameter"), std::string::npos) << all;
  EXPECT_NE(all.find("oversampling: missing"), std::string::npos) << all;
  EXPECT_EQ(all.find("map_frame"), std::string::npos) << all;
}

// doc/parameters.md is generated: regenerate it with `rosrun laser_dpslam parameter_docs --out doc/parameters.md`.
TEST(ParameterRegistry, TheCommittedDocIsTheGeneratedOne) {
  std::ifstream in("doc/parameters.md");
  ASSERT_TRUE(in);
  std::stringstream committed;
  committed << in.rdbuf();
  EXPECT_EQ(committed.str(), parametersMarkdown())
      << "doc/parameters.md is stale: rosrun laser_dpslam parameter_docs --out doc/parameters.md";
}

namespace {
std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// "0.3 m" -> "0.3", "[1.0, 0.5] m" -> "[1.0, 0.5]", "0 m: the scan's" -> "0".
std::string leadingValue(const std::string& text) {
  if (!text.empty() && text[0] == '[') return text.substr(0, text.find(']') + 1);
  return text.substr(0, text.find_first_of(" :"));
}

bool sameValue(const std::string& a, const std::string& b) {
  char *end_a = nullptr, *end_b = nullptr;
  const double x = std::strtod(a.c_str(), &end_a), y = std::strtod(b.c_str(), &end_b);
  if (*end_a == '\0' && *end_b == '\0' && !a.empty() && !b.empty()) return x == y;
  return a == b;
}
}  // namespace

// README's "Parameters that matter" lists exactly the user-facing keys, each under its node and with its default.
TEST(ParameterRegistry, TheReadmeTableAgreesWithTheRegistries) {
  const std::string readme = readFile("README.md");
  const std::size_t begin = readme.find("## Parameters that matter");
  ASSERT_NE(begin, std::string::npos);
  const std::string section = readme.substr(begin, readme.find("\n## ", begin + 1) - begin);
  std::map<std::string, ParameterInfo> odometry, slam;
  for (const ParameterInfo& p : describeParameters(odometryParameters())) odometry[p.name] = p;
  for (const ParameterInfo& p : describeParameters(dpslamParameters())) slam[p.name] = p;

  std::set<std::string> listed;
  const std::regex row(R"(\| (odometry|SLAM|both) \| ([^|]*) \|)");
  const std::regex entry(R"(`([a-z_]+)` \(([^)]*)\))");
  for (std::sregex_iterator r(section.begin(), section.end(), row), end; r != end; ++r) {
    const std::string node = (*r)[1], keys = (*r)[2];
    for (std::sregex_iterator e(keys.begin(), keys.end(), entry); e != end; ++e) {
      const std::string key = (*e)[1], value = leadingValue((*e)[2]);
      listed.insert(key);
      std::vector<const std::map<std::string, ParameterInfo>*> registries;
      if (node != "SLAM") registries.push_back(&odometry);
      if (node != "odometry") registries.push_back(&slam);
      for (const auto* registry : registries) {
        const auto it = registry->find(key);
        ASSERT_NE(it, registry->end()) << key << " (" << node << ") is not a parameter of that node";
        EXPECT_FALSE(it->second.advanced) << key << " is advanced";
        EXPECT_TRUE(sameValue(value, it->second.default_value)) << key << ": README " << value << ", code "
                                                                 << it->second.default_value;
      }
    }
  }
  for (const auto* registry : {&odometry, &slam}) {
    for (const auto& [name, info] : *registry) {
      if (!info.advanced) {
        EXPECT_TRUE(listed.count(name)) << name << " is user-facing but not in the README's table";
      }
    }
  }
}
