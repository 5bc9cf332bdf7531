#include "laser_dpslam/sim/vector_plan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>

#include "laser_dpslam/sim/scan_simulator.h"

namespace laser_dpslam {
namespace {

VectorPlan parse(const std::string& text) {
  std::istringstream in(text);
  return VectorPlan::parse(in, "test.txt");
}

TEST(VectorPlan, RaycastHitsRotatedWallsExactly) {
  // A square room 4 m wide turned by an angle off any lattice; from its centre every beam's range is
  // 2 / |cos(beam - wall normal)|, whatever the turn.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> turn(0.0, 2.0 * M_PI);
  for (int trial = 0; trial < 20; ++trial) {
    const double a = turn(rng);
    const Eigen::Vector2d c(3.217, -1.093);
    VectorPlan plan;
    std::vector<Eigen::Vector2d> corners;
    for (int k = 0; k < 4; ++k) {
      const double phi = a + M_PI / 4 + k * M_PI / 2;
      corners.push_back(c + std::sqrt(8.0) * Eigen::Vector2d(std::cos(phi), std::sin(phi)));
    }
    for (int k = 0; k < 4; ++k) plan.addWall(corners[k], corners[(k + 1) % 4]);
    for (int b = 0; b < 36; ++b) {
      const double beam = turn(rng);
      double rel = std::fmod(beam - a + 8 * M_PI, M_PI / 2);
      if (rel > M_PI / 4) rel -= M_PI / 2;
      double cos_incidence = 0.0;
      EXPECT_NEAR(plan.raycast(c, beam, 10.0, &cos_incidence), 2.0 / std::cos(rel), 1e-9);
      EXPECT_NEAR(cos_incidence, std::cos(rel), 1e-9);
      EXPECT_TRUE(std::isinf(plan.raycast(c, beam, 1.99)));
    }
  }
}

TEST(VectorPlan, CirclesAndPolygonsAreSolid) {
  const VectorPlan plan = parse("# a pillar and a table\ncircle 2 0 0.5\npolygon 0 3 1 3 1 4 0 4\n");
  EXPECT_NEAR(plan.raycast({0.0, 0.0}, 0.0, 5.6), 1.5, 1e-12);
  double cos_incidence = 0.0;
  EXPECT_NEAR(plan.raycast({2.0, -3.0}, M_PI / 2, 5.6, &cos_incidence), 2.5, 1e-12);
  EXPECT_NEAR(cos_incidence, 1.0, 1e-12);
  EXPECT_NEAR(plan.raycast({0.5, 0.0}, M_PI / 2, 5.6), 3.0, 1e-12);
  EXPECT_EQ(plan.raycast({2.1, 0.1}, 1.0, 5.6), 0.0);   // inside the pillar
  EXPECT_EQ(plan.raycast({0.5, 3.5}, 1.0, 5.6), 0.0);   // inside the table
  EXPECT_EQ(plan.clearance({0.5, 3.5}, 1.0), 0.0);
  EXPECT_NEAR(plan.clearance({2.0, 1.0}, 2.0), 0.5, 1e-12);
  EXPECT_NEAR(plan.clearance({0.5, 2.5}, 2.0), 0.5, 1e-12);
  EXPECT_EQ(plan.clearance({10.0, 10.0}, 2.0), 2.0);
  // near() keeps what a scan from there can hit.
  EXPECT_EQ(plan.near({0.0, 0.0}, 1.0).circles().size(), 0u);
  EXPECT_EQ(plan.near({0.0, 0.0}, 1.6).circles().size(), 1u);
  EXPECT_EQ(plan.near({0.0, 0.0}, 2.0).segments().size(), 0u);
}

TEST(VectorPlan, MalformedFilesNameTheLine) {
  const std::pair<const char*, const char*> cases[] = {
      {"wall 0 0 1 1\nwindow 1 2 3 4\n", "test.txt:2: unknown shape 'window'"},
      {"\n\nwall 0 0 1\n", "test.txt:3: odd number"},
      {"wall 0 0\n", "test.txt:1: a wall needs at least 2 points"},
      {"polygon 0 0 1 0\n", "test.txt:1: a polygon needs at least 3 points"},
      {"circle 0 0 -1\n", "test.txt:1: a circle's radius"},
      {"wall 0 0 1 x\n", "test.txt:1: 'x' is not a number"},
      {"wall 1 1 1 1\n", "test.txt:1: two consecutive points coincide"},
      {"# nothing\n", "test.txt: the plan holds no"},
  };
  for (const auto& [text, message] : cases) {
    try {
      parse(text);
      ADD_FAILURE() << "no exception for " << text;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(VectorPlan::load("/nonexistent/plan.txt"), std::runtime_error);
}

TEST(VectorPlan, ScanSimulatorSeesTheGeometry) {
  // A corridor 2 m wide at 30°: without noise, the beam across it reads 1 m on either side.
  const double a = M_PI / 6;
  const Eigen::Vector2d along(std::cos(a), std::sin(a)), across(-std::sin(a), std::cos(a));
  VectorPlan plan;
  plan.addWall(-20.0 * along + across, 20.0 * along + across);
  plan.addWall(-20.0 * along - across, 20.0 * along - across);
  ScanSimulatorConfig config;
  config.noise_min_stddev = config.noise_range_fraction = 0.0;
  config.dropout_probability = config.grazing_dropout_probability = 0.0;
  config.beams = 3;
  config.angle_min = -M_PI / 2;
  config.angle_max = M_PI / 2;
  ScanSimulator sim(plan, config, 1);
  const LaserScan scan = sim.simulate(Pose2D(0.0, 0.0, a), 0.0);
  ASSERT_EQ(scan.ranges.size(), 3u);
  EXPECT_NEAR(scan.ranges[0], 1.0, 1e-6);
  EXPECT_TRUE(std::isinf(scan.ranges[1]));  // along the corridor: nothing within 5.6 m
  EXPECT_NEAR(scan.ranges[2], 1.0, 1e-6);
}

}  // namespace
}  // namespace laser_dpslam
