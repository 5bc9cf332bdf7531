#include "laser_dpslam/ros/bag_scan_reader.h"

#include <ros/serialization.h>

#include <boost/make_shared.hpp>

#include <cstring>
#include <stdexcept>
#include <vector>

namespace laser_dpslam {

namespace {

/// Reads a little-endian uint32 length at `at`, advancing it; false when fewer than 4 bytes are left.
bool readLength(const std::uint8_t* data, std::size_t size, std::size_t* at, std::uint64_t* n) {
  if (size - *at < 4) return false;
  *n = std::uint64_t(data[*at]) | (std::uint64_t(data[*at + 1]) << 8) | (std::uint64_t(data[*at + 2]) << 16) |
       (std::uint64_t(data[*at + 3]) << 24);
  *at += 4;
  return true;
}

/// Skips `n` elements of `bytes` each; false when they do not fit.
bool skip(std::size_t size, std::size_t* at, std::uint64_t n, std::uint64_t bytes) {
  if (n * bytes > size - *at) return false;
  *at += static_cast<std::size_t>(n * bytes);
  return true;
}

}  // namespace

bool serializedLaserScanFits(const std::uint8_t* data, std::size_t size, std::string* why) {
  // sensor_msgs/LaserScan: header (uint32 seq, time, string frame_id), 7 float32, float32[] ranges,
  // float32[] intensities; lengths are uint32, little endian.
  std::size_t at = 0;
  std::uint64_t n = 0;
  auto fail = [&](const std::string& what) {
    if (why) *why = what + " (record of " + std::to_string(size) + " bytes)";
    return false;
  };
  if (!skip(size, &at, 1, 12)) return fail("header cut short");
  if (!readLength(data, size, &at, &n) || !skip(size, &at, n, 1)) return fail("frame_id length " + std::to_string(n) + " does not fit");
  if (!skip(size, &at, 7, 4)) return fail("angle and range fields cut short");
  if (!readLength(data, size, &at, &n) || !skip(size, &at, n, 4)) return fail("ranges length " + std::to_string(n) + " does not fit");
  if (!readLength(data, size, &at, &n) || !skip(size, &at, n, 4)) return fail("intensities length " + std::to_string(n) + " does not fit");
  if (at != size) return fail(std::to_string(size - at) + " bytes left over after the message");
  return true;
}

bool serializedTfMessageFits(const std::uint8_t* data, std::size_t size, std::string* why) {
  // tf2_msgs/TFMessage: geometry_msgs/TransformStamped[] — each a header (uint32 seq, time, string
  // frame_id), string child_frame_id and 7 float64 (translation, rotation).
  std::size_t at = 0;
  std::uint64_t count = 0, n = 0;
  auto fail = [&](const std::string& what) {
    if (why) *why = what + " (record of " + std::to_string(size) + " bytes)";
    return false;
  };
  if (!readLength(data, size, &at, &count)) return fail("transform count cut short");
  // Each transform takes at least 76 bytes: a count that cannot fit is corruption, caught before any
  // transform is read (and before a deserializer would allocate for it).
  if (count > (size - at) / 76) return fail(std::to_string(count) + " transforms do not fit");
  for (std::uint64_t i = 0; i < count; ++i) {
    if (!skip(size, &at, 1, 12)) return fail("header cut short");
    if (!readLength(data, size, &at, &n) || !skip(size, &at, n, 1)) return fail("frame_id length " + std::to_string(n) + " does not fit");
    if (!readLength(data, size, &at, &n) || !skip(size, &at, n, 1)) return fail("child_frame_id length " + std::to_string(n) + " does not fit");
    if (!skip(size, &at, 7, 8)) return fail("transform cut short");
  }
  if (at != size) return fail(std::to_string(size - at) + " bytes left over after the message");
  return true;
}

bool serializedOdometryFits(const std::uint8_t* data, std::size_t size, std::string* why) {
  // nav_msgs/Odometry: header (uint32 seq, time, string frame_id), string child_frame_id, pose (7 float64)
  // with its float64[36] covariance, twist (6 float64) with its float64[36] covariance.
  std::size_t at = 0;
  std::uint64_t n = 0;
  auto fail = [&](const std::string& what) {
    if (why) *why = what + " (record of " + std::to_string(size) + " bytes)";
    return false;
  };
  if (!skip(size, &at, 1, 12)) return fail("header cut short");
  if (!readLength(data, size, &at, &n) || !skip(size, &at, n, 1)) return fail("frame_id length " + std::to_string(n) + " does not fit");
  if (!readLength(data, size, &at, &n) || !skip(size, &at, n, 1)) return fail("child_frame_id length " + std::to_string(n) + " does not fit");
  if (!skip(size, &at, 7 + 36 + 6 + 36, 8)) return fail("pose and twist cut short");
  if (at != size) return fail(std::to_string(size - at) + " bytes left over after the message");
  return true;
}

namespace {

/// Reads, checks (`fits`) and deserializes one record of type M; `name` goes into the error message.
template <class M>
boost::shared_ptr<M> readChecked(const rosbag::MessageInstance& m, const char* name,
                                 bool (*fits)(const std::uint8_t*, std::size_t, std::string*)) {
  if (!m.isType<M>()) return nullptr;
  const std::uint32_t size = m.size();
  // Far above any real scan (a million beams with intensities is 8 MB) or TF message: larger is corruption.
  constexpr std::uint32_t kMaxBytes = 64u << 20;
  if (size > kMaxBytes) throw std::runtime_error(std::string("corrupted ") + name + " record: " + std::to_string(size) + " bytes");
  std::vector<std::uint8_t> buffer(size);
  ros::serialization::OStream out(buffer.data(), size);
  m.write(out);
  std::string why;
  if (!fits(buffer.data(), buffer.size(), &why)) throw std::runtime_error(std::string("corrupted ") + name + " record: " + why);
  auto msg = boost::make_shared<M>();
  ros::serialization::IStream in(buffer.data(), size);
  ros::serialization::deserialize(in, *msg);
  return msg;
}

}  // namespace

sensor_msgs::LaserScan::Ptr readLaserScan(const rosbag::MessageInstance& m) {
  return readChecked<sensor_msgs::LaserScan>(m, "LaserScan", serializedLaserScanFits);
}

tf2_msgs::TFMessage::Ptr readTfMessage(const rosbag::MessageInstance& m) {
  return readChecked<tf2_msgs::TFMessage>(m, "TFMessage", serializedTfMessageFits);
}

nav_msgs::Odometry::Ptr readOdometry(const rosbag::MessageInstance& m) {
  return readChecked<nav_msgs::Odometry>(m, "Odometry", serializedOdometryFits);
}

}  // namespace laser_dpslam
