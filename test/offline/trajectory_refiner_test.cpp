#include "laser_dpslam/offline/trajectory_refiner.h"

#include <gtest/gtest.h>

#include <cmath>

#include "laser_dpslam/scan/scan_preprocessor.h"
#include "laser_dpslam/sim/scan_simulator.h"
#include "laser_dpslam/sim/sim_path.h"
#include "test_rooms.h"

using namespace laser_dpslam;

namespace {

// Two laps around the furnished room, URG-04LX-like scans at 10 Hz, the true path.
struct Laps {
  std::vector<StampedPose> truth;
  TrajectoryRefiner refiner;
};

const Laps& laps() {
  static const Laps run = [] {
    Laps r;
    const FloorPlan room = test::furnishedRoom();
    const std::vector<Eigen::Vector2d> loop{{1.5, 2.5}, {3.2, 3.0}, {6.5, 2.0}, {7.0, 5.0}, {4.5, 5.0}, {1.5, 3.5}, {1.5, 2.5}};
    ScanSimulator sim(room, ScanSimulatorConfig(), 5);
    for (const auto& tp : samplePath(repeatLoop(loop, 2), 10.0, PathConfig())) {
      const PreprocessedScan scan = preprocessScan(sim.simulate(tp.pose, 10.0 + tp.stamp), ScanPreprocessorConfig());
      r.truth.push_back({scan.stamp, tp.pose});
      r.refiner.addScan(scan.stamp, tp.pose, scan.points, r.truth.size() == 1);
    }
    return r;
  }();
  return run;
}

double maxError(const std::vector<StampedPose>& a, const std::vector<StampedPose>& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, std::hypot(a[i].pose.x - b[i].pose.x, a[i].pose.y - b[i].pose.y));
  return m;
}

double rmsError(const std::vector<StampedPose>& a, const std::vector<StampedPose>& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += std::pow(a[i].pose.x - b[i].pose.x, 2) + std::pow(a[i].pose.y - b[i].pose.y, 2);
  return std::sqrt(s / a.size());
}

}  // namespace

TEST(TrajectoryRefiner, KeepsAKeyframeEveryKeyframeDistance) {
  const Laps& run = laps();
  const auto& kf = run.refiner.keyframes();
  ASSERT_GT(kf.size(), 50u);
  for (std::size_t i = 1; i < kf.size(); ++i) {
    const Pose2D d = between(kf[i - 1].odometry, kf[i].odometry);
    EXPECT_TRUE(std::hypot(d.x, d.y) >= 0.2 || std::abs(d.theta) >= 0.1) << i;
    EXPECT_FALSE(kf[i].points.empty());
  }
}

TEST(TrajectoryRefiner, TakesABendOfTheFirstLapOutAndLeavesAConsistentPathAlone) {
  const Laps& run = laps();
  // The first lap's path bent by up to 6 cm and 1° (about the map's origin: up to 18 cm) over 10 s (a
  // filter's late correction), the
  // second lap true: the matches between the laps and along the bend say where it belongs.
  std::vector<StampedPose> bent = run.truth;
  const double t0 = run.truth.front().stamp + 20.0;
  for (auto& p : bent) {
    const double u = (p.stamp - t0) / 10.0;
    if (u <= 0.0 || u >= 1.0) continue;
    const double w = 0.5 - 0.5 * std::cos(2.0 * M_PI * u);
    p.pose = Pose2D(0.0, 0.06 * w, 0.0175 * w) * p.pose;
  }
  RefinerStats stats;
  const std::vector<StampedPose> refined = run.refiner.refine(bent, &stats);
  ASSERT_EQ(refined.size(), bent.size());
  const double before = rmsError(bent, run.truth), after = rmsError(refined, run.truth);
  std::printf("[ Refiner  ] bent path RMS %.4f m -> %.4f m, max %.4f -> %.4f m; %d keyframes, %d matches (%d rejected), max shift %.3f m\n",
              before, after, maxError(bent, run.truth), maxError(refined, run.truth), stats.keyframes, stats.match_edges, stats.rejected_matches, stats.max_shift_m);
  EXPECT_GT(stats.match_edges, 3 * stats.keyframes);
  // The path's own edges hold its shape at every scale (they must: on real data the filter's path is the
  // better one, MIT CSAIL), so the matches take out part of the bend: 11 % of the RMS, 11 % of the peak.
  EXPECT_LT(after, 0.93 * before);
  EXPECT_LT(maxError(refined, run.truth), 0.93 * maxError(bent, run.truth));

  RefinerStats same;
  const std::vector<StampedPose> kept = run.refiner.refine(run.truth, &same);
  EXPECT_LT(rmsError(kept, run.truth), 0.005);
  EXPECT_LT(same.max_shift_m, 0.015);
  // Deterministic.
  const std::vector<StampedPose> again = run.refiner.refine(bent);
  for (std::size_t i = 0; i < again.size(); ++i) ASSERT_EQ(again[i].pose.x, refined[i].pose.x);
}

TEST(TrajectoryRefiner, APathItCannotRefineComesBackUnchanged) {
  TrajectoryRefiner r;
  const std::vector<StampedPose> path{{1.0, Pose2D(0, 0, 0)}, {2.0, Pose2D(1, 0, 0)}};
  EXPECT_EQ(r.refine(path)[1].pose.x, 1.0);  // no keyframe at all
  r.addScan(1.0, Pose2D(), {}, true);        // no points: not a keyframe
  EXPECT_TRUE(r.keyframes().empty());
  r.addScan(1.5, Pose2D(0.5, 0, 0), {{1.0, 0.0}, {1.0, 0.5}}, false);
  r.addScan(1.6, Pose2D(0.55, 0, 0), {{1.0, 0.0}, {1.0, 0.5}}, false);  // 5 cm: not a keyframe
  r.addScan(1.7, Pose2D(0.55, 0, 0), {{1.0, 0.0}, {1.0, 0.5}}, true);   // after a reset: one
  EXPECT_EQ(r.keyframes().size(), 2u);
  RefinerStats s;
  const std::vector<StampedPose> out = r.refine({{5.0, Pose2D(1, 2, 3)}, {6.0, Pose2D(2, 2, 3)}}, &s);
  EXPECT_EQ(s.keyframes, 0);  // none within the path's time span
  EXPECT_EQ(out[0].pose.y, 2.0);
  r.clear();
  EXPECT_TRUE(r.keyframes().empty());
}
