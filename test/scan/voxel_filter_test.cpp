#include "laser_dpslam/scan/voxel_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace laser_dpslam;

using V = Eigen::Vector2d;

TEST(VoxelFilter, OneCentroidPerOccupiedVoxelInFirstSeenOrder) {
  const std::vector<V> out = voxelFilter({V(0.07, 0.01), V(0.01, 0.01), V(0.03, 0.03), V(0.09, 0.04)}, 0.05);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NEAR(out[0].x(), 0.08, 1e-12);  // (0.07, 0.01) and (0.09, 0.04), seen first
  EXPECT_NEAR(out[0].y(), 0.025, 1e-12);
  EXPECT_NEAR(out[1].x(), 0.02, 1e-12);
  EXPECT_NEAR(out[1].y(), 0.02, 1e-12);
}

// Voxels are floor(x / size): points either side of zero are in different voxels (no double-width voxel at 0).
TEST(VoxelFilter, VoxelsOnBothSidesOfZeroAreDistinct) {
  EXPECT_EQ(voxelFilter({V(-0.01, 0.0), V(0.01, 0.0)}, 0.05).size(), 2u);
  EXPECT_EQ(voxelFilter({V(0.0, -0.01), V(0.0, 0.01)}, 0.05).size(), 2u);
  EXPECT_EQ(voxelFilter({V(-0.01, -0.01), V(-0.04, -0.04)}, 0.05).size(), 1u);
  // Far from the origin the key still separates rows and columns.
  EXPECT_EQ(voxelFilter({V(1000.0, -3.0), V(-3.0, 1000.0), V(1000.0, 1000.0)}, 0.05).size(), 3u);
}

TEST(VoxelFilter, NonFinitePointsAreDroppedAndANonPositiveSizeKeepsTheInput) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const std::vector<V> out = voxelFilter({V(nan, 0.0), V(0.0, inf), V(0.2, 0.2)}, 0.05);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0], V(0.2, 0.2));
  const std::vector<V> in{V(0.01, 0.01), V(0.02, 0.02)};
  EXPECT_EQ(voxelFilter(in, 0.0), in);
  EXPECT_EQ(voxelFilter(in, -1.0), in);
  EXPECT_TRUE(voxelFilter({}, 0.05).empty());
}

// A dense cluster is thinned to the voxel count, so it cannot outweigh sparse structure.
TEST(VoxelFilter, ADenseClusterShrinksToItsVoxels) {
  std::vector<V> pts;
  for (int i = 0; i < 1000; ++i) pts.emplace_back(0.001 * (i % 100), 0.001 * (i / 100));  // 0.1 x 0.01 m
  pts.emplace_back(3.0, 3.0);
  const std::vector<V> out = voxelFilter(pts, 0.05);
  EXPECT_EQ(out.size(), 3u);  // two voxels along x for the cluster, one for the lone point
  EXPECT_EQ(out.back(), V(3.0, 3.0));
}
