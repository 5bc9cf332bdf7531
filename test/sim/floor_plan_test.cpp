#include "laser_dpslam/sim/floor_plan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace laser_dpslam {
namespace {

namespace fs = std::filesystem;

class FloorPlanFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (fs::temp_directory_path() / "floor_plan_test_XXXXXX").string();
    ASSERT_NE(mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (fs::path(dir_) / name).string(); }

  void writeFile(const std::string& name, const std::string& content) const {
    std::ofstream out(path(name), std::ios::binary);
    out << content;
  }

  std::string writeYaml(const std::string& name, const std::string& image, const std::string& extra = "",
                        const std::string& origin = "[-1.0, 2.0, 0.0]") const {
    writeFile(name, "image: " + image + "\nresolution: 0.5\norigin: " + origin +
                        "\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n" + extra);
    return path(name);
  }

  std::string dir_;
};

// A 4 x 3 image, row 0 = top:
//   0   254 254 254     <- top-left pixel occupied (black)
//   254 205 254 254     <- one unknown pixel
//   254 254 254 0       <- bottom-right pixel occupied
std::string pgmP5() {
  const unsigned char px[12] = {0, 254, 254, 254, 254, 205, 254, 254, 254, 254, 254, 0};
  return std::string("P5\n# a comment\n4 3\n255\n") + std::string(reinterpret_cast<const char*>(px), 12);
}

TEST_F(FloorPlanFiles, LoadsP5WithTopRowAtMaxY) {
  writeFile("map.pgm", pgmP5());
  const FloorPlan plan = FloorPlan::load(writeYaml("map.yaml", "map.pgm"));
  EXPECT_EQ(plan.width(), 4);
  EXPECT_EQ(plan.height(), 3);
  EXPECT_DOUBLE_EQ(plan.resolution(), 0.5);
  EXPECT_DOUBLE_EQ(plan.origin().x(), -1.0);
  EXPECT_DOUBLE_EQ(plan.origin().y(), 2.0);
  // Image top-left = cell (0, 2) = map x in [-1, -0.5), y in [3, 3.5).
  EXPECT_TRUE(plan.cellOccupied(0, 2));
  EXPECT_TRUE(plan.occupied(-0.75, 3.25));
  EXPECT_FALSE(plan.occupied(-0.75, 2.25));  // bottom-left is free
  // Image bottom-right = cell (3, 0) = x in [0.5, 1), y in [2, 2.5).
  EXPECT_TRUE(plan.cellOccupied(3, 0));
  EXPECT_TRUE(plan.occupied(0.75, 2.25));
  EXPECT_FALSE(plan.occupied(0.75, 3.25));
  // Unknown pixel: image row 1, column 1 = cell (1, 1).
  EXPECT_EQ(plan.cell(1, 1), FloorPlan::kUnknown);
  EXPECT_FALSE(plan.occupied(-0.25, 2.75));
  EXPECT_FALSE(plan.isFree(-0.25, 2.75));
  EXPECT_TRUE(plan.isFree(0.25, 2.75));
  // Outside the grid: not occupied, not free.
  EXPECT_FALSE(plan.occupied(-1.1, 3.25));
  EXPECT_FALSE(plan.occupied(-0.75, 3.6));
  EXPECT_FALSE(plan.isFree(5.0, 5.0));
  int occupied = 0;
  for (int iy = 0; iy < 3; ++iy)
    for (int ix = 0; ix < 4; ++ix) occupied += plan.cellOccupied(ix, iy);
  EXPECT_EQ(occupied, 2);
}

TEST_F(FloorPlanFiles, LoadsP2AsciiFromSubdirectoryAndNegate) {
  fs::create_directories(path("img"));
  // maxval 15: 0 → black, 15 → white. With negate, white (p = v/255 = 1) is occupied.
  writeFile("img/map.pgm", "P2\n3 2\n# comment in the header\n15\n0 15 15\n15 15 0\n");
  const FloorPlan plain = FloorPlan::load(writeYaml("plain.yaml", "img/map.pgm"));
  EXPECT_TRUE(plain.cellOccupied(0, 1));
  EXPECT_TRUE(plain.cellOccupied(2, 0));
  EXPECT_FALSE(plain.cellOccupied(1, 1));
  EXPECT_EQ(plain.cell(1, 1), FloorPlan::kFree);

  writeFile("neg.yaml", "image: img/map.pgm\nresolution: 0.1\norigin: [0, 0, 0]\nnegate: 1\n"
                        "occupied_thresh: 0.65\nfree_thresh: 0.196\n");
  const FloorPlan negated = FloorPlan::load(path("neg.yaml"));
  EXPECT_FALSE(negated.cellOccupied(0, 1));
  EXPECT_TRUE(negated.cellOccupied(1, 1));
  EXPECT_EQ(negated.cell(0, 1), FloorPlan::kFree);
}

TEST_F(FloorPlanFiles, ThresholdsFollowMapServer) {
  // p = (255 - v) / 255: v = 90 → p = 0.647 (unknown at 0.65); v = 89 → 0.651 (occupied); v = 205 → 0.196 (unknown).
  const unsigned char px[4] = {90, 89, 205, 206};
  writeFile("t.pgm", std::string("P5 4 1 255\n") + std::string(reinterpret_cast<const char*>(px), 4));
  const FloorPlan plan = FloorPlan::load(writeYaml("t.yaml", "t.pgm"));
  EXPECT_EQ(plan.cell(0, 0), FloorPlan::kUnknown);
  EXPECT_EQ(plan.cell(1, 0), FloorPlan::kOccupied);
  EXPECT_EQ(plan.cell(2, 0), FloorPlan::kUnknown);
  EXPECT_EQ(plan.cell(3, 0), FloorPlan::kFree);
}

TEST_F(FloorPlanFiles, SaveLoadRoundTrip) {
  std::vector<std::uint8_t> occ(6 * 4, 0);
  occ[0] = 1;           // (0, 0) bottom-left
  occ[3 * 6 + 5] = 1;   // (5, 3) top-right
  occ[2 * 6 + 1] = 1;   // (1, 2)
  const FloorPlan plan = FloorPlan::fromOccupancy(6, 4, 0.05, Eigen::Vector2d(1.5, -2.25), occ);
  plan.save(path("saved.yaml"));
  ASSERT_TRUE(fs::exists(path("saved.pgm")));
  const FloorPlan back = FloorPlan::load(path("saved.yaml"));
  ASSERT_EQ(back.width(), 6);
  ASSERT_EQ(back.height(), 4);
  EXPECT_NEAR(back.resolution(), 0.05, 1e-12);
  EXPECT_NEAR(back.origin().x(), 1.5, 1e-12);
  EXPECT_NEAR(back.origin().y(), -2.25, 1e-12);
  for (int iy = 0; iy < 4; ++iy)
    for (int ix = 0; ix < 6; ++ix) EXPECT_EQ(back.cellOccupied(ix, iy), occ[iy * 6 + ix] != 0) << ix << "," << iy;
  EXPECT_TRUE(back.occupied(1.5 + 0.01, -2.25 + 0.01));
}

void expectErrorMentioning(const std::string& yaml, const std::string& file, const std::string& what) {
  try {
    FloorPlan::load(yaml);
    ADD_FAILURE() << "no exception for " << yaml << " (expected: " << what << ")";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(file), std::string::npos) << msg;
    EXPECT_NE(msg.find(what), std::string::npos) << msg;
  }
}

TEST_F(FloorPlanFiles, MissingAndMalformedFilesGiveClearErrors) {
  expectErrorMentioning(path("nope.yaml"), "nope.yaml", "cannot open");

  writeFile("bad_syntax.yaml", "image: [unclosed\nresolution: 0.05\n");
  expectErrorMentioning(path("bad_syntax.yaml"), "bad_syntax.yaml", "malformed YAML");

  writeFile("no_res.yaml", "image: map.pgm\norigin: [0, 0, 0]\n");
  expectErrorMentioning(path("no_res.yaml"), "no_res.yaml", "resolution");

  writeFile("map.pgm", pgmP5());
  expectErrorMentioning(writeYaml("yaw.yaml", "map.pgm", "", "[0, 0, 0.5]"), "yaw.yaml", "yaw");
  expectErrorMentioning(writeYaml("short_origin.yaml", "map.pgm", "", "[0, 0]"), "short_origin.yaml", "origin");

  expectErrorMentioning(writeYaml("noimg.yaml", "missing.pgm"), "missing.pgm", "cannot open");

  writeFile("trunc.pgm", "P5\n4 3\n255\n\x01\x02\x03");
  expectErrorMentioning(writeYaml("trunc.yaml", "trunc.pgm"), "trunc.pgm", "truncated");

  writeFile("ppm.pgm", "P6\n1 1\n255\nabc");
  expectErrorMentioning(writeYaml("ppm.yaml", "ppm.pgm"), "ppm.pgm", "PGM");

  writeFile("wide.pgm", "P2\n1 1\n65535\n1000\n");
  expectErrorMentioning(writeYaml("wide.yaml", "wide.pgm"), "wide.pgm", "16-bit");

  writeFile("badval.pgm", "P2\n2 1\n255\n12 x\n");
  expectErrorMentioning(writeYaml("badval.yaml", "badval.pgm"), "badval.pgm", "pixel value");

  writeFile("badhdr.pgm", "P5\nfour 3\n255\n");
  expectErrorMentioning(writeYaml("badhdr.yaml", "badhdr.pgm"), "badhdr.pgm", "width");
}

TEST(FloorPlan, FromOccupancyChecksSizes) {
  EXPECT_THROW(FloorPlan::fromOccupancy(3, 3, 0.1, Eigen::Vector2d::Zero(), std::vector<std::uint8_t>(8)),
               std::invalid_argument);
  EXPECT_THROW(FloorPlan::fromOccupancy(3, 3, 0.0, Eigen::Vector2d::Zero(), std::vector<std::uint8_t>(9)),
               std::invalid_argument);
}

TEST(FloorPlan, RaycastHitsCellFacesExactly) {
  // 10 x 10 cells of 0.1 m from (0, 0); one occupied cell (7, 4) = [0.7, 0.8) x [0.4, 0.5).
  std::vector<std::uint8_t> occ(100, 0);
  occ[4 * 10 + 7] = 1;
  const FloorPlan plan = FloorPlan::fromOccupancy(10, 10, 0.1, Eigen::Vector2d::Zero(), occ);
  int axis = -2;
  EXPECT_NEAR(plan.raycast({0.23, 0.45}, 0.0, 5.0, &axis), 0.47, 1e-12);
  EXPECT_EQ(axis, 0);
  // From below, hitting the bottom face y = 0.4 at x = 0.75.
  const Eigen::Vector2d from(0.75 - 0.3 / std::tan(1.2), 0.1);
  EXPECT_NEAR(plan.raycast(from, 1.2, 5.0, &axis), 0.3 / std::sin(1.2), 1e-12);
  EXPECT_EQ(axis, 1);
  // Missing it, leaving the grid: +inf; too short: +inf.
  EXPECT_TRUE(std::isinf(plan.raycast({0.23, 0.45}, M_PI, 5.0)));
  EXPECT_TRUE(std::isinf(plan.raycast({0.23, 0.45}, 0.0, 0.46)));
  // From inside the occupied cell: 0.
  EXPECT_EQ(plan.raycast({0.75, 0.45}, 0.3, 5.0), 0.0);
  // From outside the grid, entering it: distance counted from the start point.
  EXPECT_NEAR(plan.raycast({-2.0, 0.45}, 0.0, 5.0), 2.7, 1e-12);
  EXPECT_NEAR(plan.raycast({1.5, 0.42}, M_PI, 5.0), 0.7, 1e-12);
}

TEST(FloorPlan, Clearance) {
  std::vector<std::uint8_t> occ(100, 0);
  occ[4 * 10 + 7] = 1;  // [0.7, 0.8) x [0.4, 0.5)
  const FloorPlan plan = FloorPlan::fromOccupancy(10, 10, 0.1, Eigen::Vector2d::Zero(), occ);
  EXPECT_NEAR(plan.clearance({0.5, 0.45}, 1.0), 0.2, 1e-12);
  EXPECT_NEAR(plan.clearance({0.9, 0.6}, 1.0), std::hypot(0.1, 0.1), 1e-12);
  EXPECT_NEAR(plan.clearance({0.1, 0.1}, 0.3), 0.3, 1e-12);
  EXPECT_NEAR(plan.clearance({0.75, 0.45}, 1.0), 0.0, 1e-12);
}

}  // namespace
}  // namespace laser_dpslam
