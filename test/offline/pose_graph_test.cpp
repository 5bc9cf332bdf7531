#include "laser_dpslam/offline/pose_graph.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

using namespace laser_dpslam;

namespace {

// A square loop of 4 × 10 poses, 1 m apart, turning 90° at each corner.
std::vector<Pose2D> squareLoop() {
  std::vector<Pose2D> p{Pose2D()};
  for (int i = 1; i < 40; ++i) p.push_back(p.back() * Pose2D(1.0, 0.0, i % 10 == 0 ? M_PI / 2 : 0.0));
  return p;
}

Eigen::Matrix3d information(double sxy, double st) {
  return Eigen::Vector3d(1 / (sxy * sxy), 1 / (sxy * sxy), 1 / (st * st)).asDiagonal();
}

double maxError(const std::vector<Pose2D>& a, const std::vector<Pose2D>& b) {
  double e = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) e = std::max(e, std::hypot(a[i].x - b[i].x, a[i].y - b[i].y));
  return e;
}

}  // namespace

TEST(PoseGraph, ErrorIsZeroForAnExactMeasurementAndWrapsTheAngle) {
  const Pose2D a(1.0, 2.0, 3.0), b(-0.5, 0.7, -3.0);
  EXPECT_LT(poseGraphError(a, b, between(a, b)).norm(), 1e-12);
  const Eigen::Vector3d e = poseGraphError(a, b, between(a, b) * Pose2D(0.0, 0.0, 0.1));
  EXPECT_NEAR(e.z(), -0.1, 1e-12);
}

TEST(PoseGraph, ConvergesToExactMeasurementsFromAPerturbedStart) {
  const std::vector<Pose2D> truth = squareLoop();
  std::vector<PoseGraphEdge> edges;
  for (int i = 1; i < 40; ++i) edges.push_back({i - 1, i, between(truth[i - 1], truth[i]), information(0.01, 0.005)});
  edges.push_back({39, 0, between(truth[39], truth[0]), information(0.01, 0.005)});
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0.0, 0.2);
  std::vector<Pose2D> poses = truth;
  for (std::size_t i = 1; i < poses.size(); ++i) poses[i] = Pose2D(truth[i].x + n(rng), truth[i].y + n(rng), truth[i].theta + 0.3 * n(rng));
  const PoseGraphResult r = optimizePoseGraph(poses, edges);
  EXPECT_TRUE(r.solved);
  EXPECT_TRUE(r.converged);
  EXPECT_LT(r.final_cost, 1e-6 * r.initial_cost);
  EXPECT_LT(maxError(poses, truth), 1e-4);
  EXPECT_EQ(poses[0].x, 0.0);  // the fixed node
}

TEST(PoseGraph, ALoopClosureSpreadsTheOdometryDriftOverTheLoop) {
  const std::vector<Pose2D> truth = squareLoop();
  // Odometry that turns 0.5° too little per step: the dead-reckoned loop misses its start by metres.
  std::vector<PoseGraphEdge> edges;
  std::vector<Pose2D> poses{truth[0]};
  for (int i = 1; i < 40; ++i) {
    const Pose2D z = between(truth[i - 1], truth[i]) * Pose2D(0.0, 0.0, -0.0087);
    edges.push_back({i - 1, i, z, information(0.01, 0.01)});
    poses.push_back(poses.back() * z);
  }
  const double before = maxError(poses, truth);
  edges.push_back({0, 39, between(truth[0], truth[39]), information(0.01, 0.01)});  // the closure
  const PoseGraphResult r = optimizePoseGraph(poses, edges);
  EXPECT_TRUE(r.solved);
  EXPECT_GT(before, 1.0);
  EXPECT_LT(maxError(poses, truth), 0.25 * before);
  EXPECT_LT(std::hypot(poses[39].x - truth[39].x, poses[39].y - truth[39].y), 0.05);
}

TEST(PoseGraph, HuberKeepsOneWrongClosureFromBendingTheGraph) {
  const std::vector<Pose2D> truth = squareLoop();
  std::vector<PoseGraphEdge> edges;
  for (int i = 1; i < 40; ++i) edges.push_back({i - 1, i, between(truth[i - 1], truth[i]), information(0.005, 0.002), false});
  for (const auto& c : {std::pair<int, int>{0, 39}, {10, 30}, {5, 35}, {15, 25}}) {
    edges.push_back({c.first, c.second, between(truth[c.first], truth[c.second]), information(0.02, 0.01)});
  }
  // A wrong loop closure (a corridor taken for its neighbour): half a metre off.
  edges.push_back({0, 20, between(truth[0], truth[20]) * Pose2D(0.5, 0.3, 0.0), information(0.02, 0.01)});
  std::vector<Pose2D> robust = truth, plain = truth;
  PoseGraphOptions off;
  off.huber_sigmas = 0.0;
  EXPECT_TRUE(optimizePoseGraph(robust, edges).converged);
  optimizePoseGraph(plain, edges, off);
  EXPECT_GT(maxError(plain, truth), 0.05);
  EXPECT_LT(maxError(robust, truth), 0.5 * maxError(plain, truth));
}

TEST(PoseGraph, BadEdgesAreRejectedAndLoneNodesStay) {
  std::vector<Pose2D> poses{Pose2D(), Pose2D(1, 0, 0), Pose2D(5, 5, 1)};
  std::vector<PoseGraphEdge> edges{{0, 3, Pose2D(), Eigen::Matrix3d::Identity()}};
  EXPECT_THROW(optimizePoseGraph(poses, edges), std::invalid_argument);
  edges = {{1, 1, Pose2D(), Eigen::Matrix3d::Identity()}};
  EXPECT_THROW(optimizePoseGraph(poses, edges), std::invalid_argument);
  edges = {{0, 1, Pose2D(std::nan(""), 0, 0), Eigen::Matrix3d::Identity()}};
  EXPECT_THROW(optimizePoseGraph(poses, edges), std::invalid_argument);
  edges = {{0, 1, Pose2D(2, 0, 0), Eigen::Matrix3d::Identity()}};
  const PoseGraphResult r = optimizePoseGraph(poses, edges);
  EXPECT_TRUE(r.solved);
  EXPECT_NEAR(poses[1].x, 2.0, 1e-6);
  EXPECT_EQ(poses[2].x, 5.0);  // no edge reaches it
  EXPECT_EQ(poses[2].theta, 1.0);
}
