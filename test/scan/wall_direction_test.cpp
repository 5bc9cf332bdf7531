#include "laser_dpslam/scan/wall_direction.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

using namespace laser_dpslam;

namespace {
// A 6 m × 4 m rectangular room turned by `turn` rad, "scanned" in order from a point inside it: 683 beams over
// 240° (URG-04LX spacing), ray-cast on the four walls, Gaussian range noise of 1 cm + 1 % (seeded).
std::vector<Eigen::Vector2d> scanRoom(double turn, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  const Eigen::Vector2d o(-1.2, 0.7);  // scanner in the room's own frame, room = [-3, 3] x [-2, 2]
  std::vector<Eigen::Vector2d> points;
  for (int k = 0; k < 683; ++k) {
    const double a = -2.0 * M_PI / 3.0 + k * (4.0 * M_PI / 3.0) / 682.0;  // in the scanner's frame
    const Eigen::Vector2d d(std::cos(a - turn), std::sin(a - turn));         // in the room's frame
    double t = 1e9;
    if (d.x() != 0.0) t = std::min(t, ((d.x() > 0 ? 3.0 : -3.0) - o.x()) / d.x());
    if (d.y() != 0.0) t = std::min(t, ((d.y() > 0 ? 2.0 : -2.0) - o.y()) / d.y());
    const double r = t + (0.01 + 0.01 * t) * noise(rng);
    points.emplace_back(r * std::cos(a), r * std::sin(a));  // scanner frame: the walls run at +turn
  }
  return points;
}
}  // namespace

TEST(WallDirection, FindsTheWallsOfATurnedRoomModulo90Degrees) {
  for (double deg : {0.0, 4.0, -17.0, 30.0, 44.0, 60.0, 100.0}) {
    const WallDirection w = dominantWallDirection(scanRoom(deg * M_PI / 180.0, 1));
    // The walls run at deg in the scanner's frame; the answer is that modulo 90°, in (−45°, 45°].
    double expected = std::remainder(deg, 90.0);
    if (expected <= -45.0) expected += 90.0;
    const double got = w.angle * 180.0 / M_PI;
    // Exact without noise; one scan with this much noise: within 2° (0.1–1.4° here).
    EXPECT_NEAR(std::remainder(got - expected, 90.0), 0.0, 2.0) << deg << " deg: got " << got;
    EXPECT_GT(w.angle, -M_PI / 4);
    EXPECT_LE(w.angle, M_PI / 4);
    EXPECT_GT(w.strength, 0.6) << deg;
    EXPECT_GT(w.chords, 200) << deg;
  }
}

TEST(WallDirection, TheProjectionsSharpenACoarseAngleToATenthOfADegree) {
  // 20 noisy scans of the room at angles off the 0.01° search steps, refined from a start 2.5° off: the
  // error of the grid a map is then aligned with (a 1° error bends a 30 m corridor by 0.5 m).
  double worst = 0.0, squares = 0.0;
  for (int k = 0; k < 20; ++k) {
    const double deg = -40.0 + 4.237 * k;
    const double turn = deg * M_PI / 180.0;
    const double got = refineWallAngle(scanRoom(turn, 10 + k), turn + (k % 2 ? 2.5 : -2.5) * M_PI / 180.0);
    const double error = (got - turn) * 180.0 / M_PI;
    worst = std::max(worst, std::abs(error));
    squares += error * error;
  }
  // This room's noise (1 cm + 1 %) is more than a URG-04LX's: RMS 0.08°, worst 0.18° (the chords alone:
  // 0.1–1.4°).
  EXPECT_LT(std::sqrt(squares / 20.0), 0.1);
  EXPECT_LT(worst, 0.25);
  // Out of its ±3° window it cannot reach the walls: it stays at the window's edge.
  const double far = refineWallAngle(scanRoom(0.0, 1), 5.0 * M_PI / 180.0);
  EXPECT_NEAR(far * 180.0 / M_PI, 2.0, 0.011);
  // Nothing to refine: the coarse angle back; non-finite and far points are ignored.
  EXPECT_EQ(refineWallAngle({}, 0.3), 0.3);
  EXPECT_EQ(refineWallAngle({{1.0, 0.0}, {1e9, 0.0}, {NAN, 1.0}}, 0.3), 0.3);
}

TEST(WallDirection, NoDirectionOnACircleAndNothingWithoutChords) {
  std::vector<Eigen::Vector2d> circle;
  for (int k = 0; k < 683; ++k) {
    const double a = -M_PI + k * 2.0 * M_PI / 683.0;
    circle.emplace_back(2.0 * std::cos(a), 2.0 * std::sin(a));
  }
  const WallDirection c = dominantWallDirection(circle);
  EXPECT_GT(c.chords, 300);
  EXPECT_LT(c.strength, 0.1);
  const WallDirection none = dominantWallDirection({});
  EXPECT_EQ(none.chords, 0);
  EXPECT_EQ(none.strength, 0.0);
  EXPECT_EQ(none.angle, 0.0);
  // Points farther apart than max_chord (a sparse scan, or one point per surface) give no chord either.
  const WallDirection sparse = dominantWallDirection({{0.0, 0.0}, {1.0, 0.0}, {2.0, 0.0}});
  EXPECT_EQ(sparse.chords, 0);
}
