#include "laser_dpslam/ros/bag_scan_reader.h"

#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <tf2_msgs/TFMessage.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

using namespace laser_dpslam;

namespace {

sensor_msgs::LaserScan urgScan(double stamp) {
  sensor_msgs::LaserScan s;
  s.header.stamp = ros::Time(stamp);
  s.header.frame_id = "laser";
  s.angle_min = -2.094f;
  s.angle_max = 2.094f;
  s.angle_increment = 4.188f / 682;
  s.range_min = 0.02f;
  s.range_max = 5.6f;
  s.ranges.assign(683, 1.5f);
  s.intensities.assign(683, 7.0f);
  return s;
}

std::vector<std::uint8_t> serialize(const sensor_msgs::LaserScan& s) {
  std::vector<std::uint8_t> b(ros::serialization::serializationLength(s));
  ros::serialization::OStream out(b.data(), static_cast<std::uint32_t>(b.size()));
  ros::serialization::serialize(out, s);
  return b;
}

/// Offset of the ranges length in a serialized scan with frame "laser": 12 + 4 + 5 + 28.
constexpr std::size_t kRangesLength = 49;

void putLength(std::uint8_t* at, std::uint32_t n) {
  for (int k = 0; k < 4; ++k) at[k] = static_cast<std::uint8_t>(n >> (8 * k));
}

}  // namespace

TEST(BagScanReader, AcceptsExactlyOneWellFormedTfMessage) {
  tf2_msgs::TFMessage tf;
  for (const char* child : {"laser", "imu"}) {
    geometry_msgs::TransformStamped t;
    t.header.frame_id = "base_link";
    t.child_frame_id = child;
    t.transform.rotation.w = 1.0;
    tf.transforms.push_back(t);
  }
  std::vector<std::uint8_t> b(ros::serialization::serializationLength(tf));
  ros::serialization::OStream out(b.data(), static_cast<std::uint32_t>(b.size()));
  ros::serialization::serialize(out, tf);
  std::string why;
  ASSERT_TRUE(serializedTfMessageFits(b.data(), b.size(), &why)) << why;
  for (std::size_t n = 0; n < b.size(); ++n) EXPECT_FALSE(serializedTfMessageFits(b.data(), n, &why)) << n;
  b.push_back(0);
  EXPECT_FALSE(serializedTfMessageFits(b.data(), b.size(), &why));
  EXPECT_NE(why.find("left over"), std::string::npos) << why;
  b.pop_back();
  // A corrupted transform count or string length is reported instead of being believed.
  putLength(&b[0], 20000000u);
  EXPECT_FALSE(serializedTfMessageFits(b.data(), b.size(), &why));
  EXPECT_NE(why.find("20000000 transforms do not fit"), std::string::npos) << why;
  putLength(&b[0], 2u);
  putLength(&b[16], 0xFFFFFFF0u);  // the first frame_id's length (after the count, seq and stamp)
  EXPECT_FALSE(serializedTfMessageFits(b.data(), b.size(), &why));
  EXPECT_NE(why.find("frame_id length"), std::string::npos) << why;
}

TEST(BagScanReader, AcceptsExactlyOneWellFormedOdometry) {
  nav_msgs::Odometry o;
  o.header.frame_id = "odom";
  o.child_frame_id = "base_footprint";
  o.pose.pose.orientation.w = 1.0;
  std::vector<std::uint8_t> b(ros::serialization::serializationLength(o));
  ros::serialization::OStream out(b.data(), static_cast<std::uint32_t>(b.size()));
  ros::serialization::serialize(out, o);
  std::string why;
  ASSERT_TRUE(serializedOdometryFits(b.data(), b.size(), &why)) << why;
  for (std::size_t n = 0; n < b.size(); ++n) EXPECT_FALSE(serializedOdometryFits(b.data(), n, &why)) << n;
  b.push_back(0);
  EXPECT_FALSE(serializedOdometryFits(b.data(), b.size(), &why));
  EXPECT_NE(why.find("left over"), std::string::npos) << why;
  b.pop_back();
  putLength(&b[20], 0xFFFFFFF0u);  // child_frame_id's length, after seq, stamp and "odom"
  EXPECT_FALSE(serializedOdometryFits(b.data(), b.size(), &why));
  EXPECT_NE(why.find("child_frame_id length"), std::string::npos) << why;
}

TEST(BagScanReader, AcceptsExactlyOneWellFormedScan) {
  std::vector<std::uint8_t> b = serialize(urgScan(1.0));
  std::string why;
  ASSERT_TRUE(serializedLaserScanFits(b.data(), b.size(), &why)) << why;
  ASSERT_EQ(b[kRangesLength], 683 % 256);  // the layout the corruptions below rely on
  // Cut anywhere: rejected.
  for (std::size_t n : {std::size_t(0), std::size_t(11), std::size_t(20), kRangesLength + 2, b.size() / 2, b.size() - 1}) {
    EXPECT_FALSE(serializedLaserScanFits(b.data(), n, &why)) << n;
  }
  // Trailing bytes: not one LaserScan either.
  b.push_back(0);
  EXPECT_FALSE(serializedLaserScanFits(b.data(), b.size(), &why));
  EXPECT_NE(why.find("left over"), std::string::npos) << why;
  b.pop_back();
  // A corrupted length is reported instead of being believed.
  putLength(&b[kRangesLength], 0x7FFFFFFFu);
  EXPECT_FALSE(serializedLaserScanFits(b.data(), b.size(), &why));
  EXPECT_NE(why.find("ranges length 2147483647"), std::string::npos) << why;
  b = serialize(urgScan(1.0));
  putLength(&b[12], 0xFFFFFFFFu);  // frame_id length
  EXPECT_FALSE(serializedLaserScanFits(b.data(), b.size(), &why));
  EXPECT_NE(why.find("frame_id"), std::string::npos) << why;
}

TEST(BagScanReader, ReadsScansFromABagAndRejectsACorruptedRecordQuickly) {
  const std::string path = ::testing::TempDir() + "/scan_reader_" + std::to_string(::getpid()) + ".bag";
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);  // uncompressed: the record bytes can be patched below
    tf2_msgs::TFMessage tf;
    bag.write("/tf_static", ros::Time(1.0), tf);
    for (int k = 0; k < 3; ++k) bag.write("/scan", ros::Time(1.0 + 0.1 * k), urgScan(1.0 + 0.1 * k));
  }
  {
    rosbag::Bag bag(path, rosbag::bagmode::Read);
    int scans = 0, others = 0;
    for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
      const sensor_msgs::LaserScan::Ptr s = readLaserScan(m);
      if (!s) {
        ++others;
        continue;
      }
      EXPECT_EQ(s->header.stamp, ros::Time(1.0 + 0.1 * scans));
      EXPECT_EQ(s->ranges, urgScan(0).ranges);
      EXPECT_EQ(s->intensities.size(), 683u);
      ++scans;
    }
    EXPECT_EQ(scans, 3);
    EXPECT_EQ(others, 1);
  }
  // Corrupt the second scan's ranges length in the file.
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::string frame("\x05\x00\x00\x00laser", 9);
  std::size_t at = bytes.find(frame);
  at = bytes.find(frame, at + 1);
  ASSERT_NE(at, std::string::npos);
  putLength(reinterpret_cast<std::uint8_t*>(&bytes[at + 9 + 28]), 0x7FFFFFFFu);
  std::ofstream(path, std::ios::binary) << bytes;
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  int read = 0;
  std::string error;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/scan"))) {
    try {
      readLaserScan(m);
      ++read;
    } catch (const std::runtime_error& e) {
      error = e.what();
      break;
    }
  }
  EXPECT_EQ(read, 1);
  EXPECT_NE(error.find("corrupted LaserScan record: ranges length 2147483647"), std::string::npos) << error;
  std::remove(path.c_str());
}
