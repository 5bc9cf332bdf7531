#include "laser_dpslam/ros/msg_conversion.h"

#include <gtest/gtest.h>
#include <tf2/LinearMath/Quaternion.h>

#include <Eigen/LU>

#include <cmath>
#include <limits>

using namespace laser_dpslam;

namespace {
geometry_msgs::Transform transform(double x, double y, double z, double roll, double pitch, double yaw) {
  tf2::Quaternion q;
  q.setRPY(roll, pitch, yaw);
  geometry_msgs::Transform t;
  t.translation.x = x;
  t.translation.y = y;
  t.translation.z = z;
  t.rotation.x = q.x();
  t.rotation.y = q.y();
  t.rotation.z = q.z();
  t.rotation.w = q.w();
  return t;
}
}  // namespace

TEST(MsgConversion, ScanFieldsSurviveBothWaysIncludingRep117Values) {
  LaserScan s;
  s.stamp = 1700000000.25;
  s.frame_id = "laser";
  s.angle_min = -2.0862;
  s.angle_max = 2.0923;
  s.angle_increment = 0.00613;
  s.time_increment = 1e-4;
  s.scan_time = 0.1;
  s.range_min = 0.02;
  s.range_max = 5.6;
  s.ranges = {1.0f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
              -std::numeric_limits<float>::infinity(), 5.5f};
  s.intensities = {1.0f, 2.0f};
  const sensor_msgs::LaserScan msg = toMsg(s);
  EXPECT_EQ(msg.header.frame_id, "laser");
  EXPECT_EQ(msg.header.stamp.sec, 1700000000u);
  EXPECT_EQ(msg.header.stamp.nsec, 250000000u);
  const LaserScan back = fromMsg(msg);
  EXPECT_DOUBLE_EQ(back.stamp, s.stamp);
  EXPECT_EQ(back.frame_id, s.frame_id);
  EXPECT_FLOAT_EQ(back.angle_min, s.angle_min);  // the message holds float32
  EXPECT_FLOAT_EQ(back.angle_max, s.angle_max);
  EXPECT_FLOAT_EQ(back.angle_increment, s.angle_increment);
  EXPECT_FLOAT_EQ(back.scan_time, s.scan_time);
  EXPECT_FLOAT_EQ(back.range_max, s.range_max);
  ASSERT_EQ(back.ranges.size(), 5u);
  EXPECT_EQ(back.ranges[0], 1.0f);
  EXPECT_TRUE(std::isnan(back.ranges[1]));
  EXPECT_TRUE(std::isinf(back.ranges[2]) && back.ranges[2] > 0);
  EXPECT_TRUE(std::isinf(back.ranges[3]) && back.ranges[3] < 0);
  EXPECT_EQ(back.intensities, s.intensities);
}

TEST(MsgConversion, PlanarPosesRoundTripThroughPoseAndTransform) {
  for (const Pose2D& p : {Pose2D(1.0, -2.0, 0.3), Pose2D(0.0, 0.0, M_PI - 1e-3), Pose2D(-5.0, 4.0, -2.5)}) {
    const Pose2D a = poseFromMsg(toPoseMsg(p));
    const Pose2D b = poseFromMsg(toTransformMsg(p));
    for (const Pose2D& q : {a, b}) {
      EXPECT_NEAR(q.x, p.x, 1e-12);
      EXPECT_NEAR(q.y, p.y, 1e-12);
      EXPECT_NEAR(q.theta, p.theta, 1e-9);
    }
  }
  // A zero quaternion (an unset message) reads as no rotation rather than NaN.
  geometry_msgs::Pose zero;
  zero.position.x = 2.0;
  const Pose2D z = poseFromMsg(zero);
  EXPECT_EQ(z.x, 2.0);
  EXPECT_EQ(z.theta, 0.0);
}

TEST(MsgConversion, AnUpsideDownLaserIsDetectedAndItsMountMirrorsTheScan) {
  bool upside_down = true;
  poseFromMsg(transform(0.1, 0.0, 0.2, 0.0, 0.0, 0.5), &upside_down);
  EXPECT_FALSE(upside_down);
  const Pose2D flipped = poseFromMsg(transform(0.1, 0.0, 0.2, M_PI, 0.0, 0.5), &upside_down);
  EXPECT_TRUE(upside_down);
  EXPECT_NEAR(flipped.theta, 0.5, 1e-9);  // the x axis still points at yaw 0.5

  // Upright mount: a point 1 m ahead of the laser is 1 m along the yaw, offset by the translation.
  const LaserMount upright = mountFromTransform(transform(0.1, 0.2, 0.3, 0.0, 0.0, M_PI / 2));
  const Eigen::Vector2d ahead = upright.apply(Eigen::Vector2d(1.0, 0.0));
  EXPECT_NEAR(ahead.x(), 0.1, 1e-9);
  EXPECT_NEAR(ahead.y(), 1.2, 1e-9);
  // Upside down (roll pi): the laser's left is the robot's right.
  const LaserMount mirrored = mountFromTransform(transform(0.0, 0.0, 0.3, M_PI, 0.0, 0.0));
  const Eigen::Vector2d left = mirrored.apply(Eigen::Vector2d(0.0, 1.0));
  EXPECT_NEAR(left.x(), 0.0, 1e-9);
  EXPECT_NEAR(left.y(), -1.0, 1e-9);
  EXPECT_NEAR(mirrored.A.determinant(), -1.0, 1e-9);
}

TEST(MsgConversion, ALeadingSlashIsStrippedFromFrameIds) {
  EXPECT_EQ(cleanFrameId("/laser"), "laser");
  EXPECT_EQ(cleanFrameId("laser"), "laser");
  EXPECT_EQ(cleanFrameId("/robot/laser"), "robot/laser");
  EXPECT_EQ(cleanFrameId(""), "");
}

// A ROS 6×6 covariance holds the planar 3×3 in rows and columns x, y, yaw (0, 1, 5); the others are kept.
TEST(MsgConversion, PlanarCovarianceGoesToXYAndYaw) {
  Eigen::Matrix3d cov;
  cov << 1, 2, 3, 2, 4, 5, 3, 5, 6;
  boost::array<double, 36> msg;
  msg.fill(-1.0);
  setPlanarCovariance(cov, &msg);
  EXPECT_EQ(msg[0], 1.0);
  EXPECT_EQ(msg[1], 2.0);
  EXPECT_EQ(msg[5], 3.0);
  EXPECT_EQ(msg[30], 3.0);
  EXPECT_EQ(msg[35], 6.0);
  EXPECT_EQ(msg[2], -1.0);   // x–z untouched
  EXPECT_EQ(msg[14], -1.0);  // z–z untouched
  EXPECT_EQ(planarCovarianceFromMsg(msg), cov);
}
