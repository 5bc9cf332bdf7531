// lookupTransformWall must end after its wall-clock timeout even when simulated time stands still (a bag
// that stopped publishing /clock), and must return a transform that is there.
#include "laser_dpslam/ros/tf_wait.h"

#include <gtest/gtest.h>
#include <ros/time.h>
#include <tf2/exceptions.h>
#include <tf2_ros/buffer.h>

#include <chrono>

namespace laser_dpslam {
namespace {

class TfWaitTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ros::Time::init();
    ros::Time::setNow(ros::Time(1000.0));  // simulated time, frozen for the whole test
  }
};

TEST_F(TfWaitTest, MissingTransformThrowsAfterTheWallTimeoutUnderFrozenSimTime) {
  tf2_ros::Buffer buffer;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_THROW(lookupTransformWall(buffer, "odom", "base_link", ros::Time(1000.0), 0.1), tf2::TransformException);
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GE(waited, 0.09);
  EXPECT_LT(waited, 5.0);  // the ROS-time wait of tf2 would never return here
}

TEST_F(TfWaitTest, AvailableTransformIsReturnedAtItsStamp) {
  tf2_ros::Buffer buffer;
  geometry_msgs::TransformStamped a, b;
  a.header.frame_id = b.header.frame_id = "odom";
  a.child_frame_id = b.child_frame_id = "base_link";
  a.header.stamp = ros::Time(999.0);
  b.header.stamp = ros::Time(1001.0);
  a.transform.rotation.w = b.transform.rotation.w = 1.0;
  b.transform.translation.x = 2.0;
  buffer.setTransform(a, "test");
  buffer.setTransform(b, "test");
  const auto t = lookupTransformWall(buffer, "odom", "base_link", ros::Time(1000.0), 0.1);
  EXPECT_NEAR(t.transform.translation.x, 1.0, 1e-9);  // interpolated at the asked stamp
  EXPECT_THROW(lookupTransformWall(buffer, "odom", "base_link", ros::Time(1002.0), 0.05),
               tf2::TransformException);  // extrapolation into the future is not answered
}

}  // namespace
}  // namespace laser_dpslam
