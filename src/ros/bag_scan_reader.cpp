#include "laser_dpslam/ros/bag_scan_reader.h"

#include <ros/serialization.h>

#include <boost/make_shared.hpp>

#include <cstring>
#include <stdexcept>
#include <vector>

namespace laser_dpslam {

namespace {

/// Walks a serialized ROS message, checking that each field fits in what is left before it is read.
/// ROS encodes lengths as little-endian uint32.
class RecordWalk {
 public:
  RecordWalk(const std::uint8_t* data, std::size_t size, std::string* why) : data_(data), size_(size), why_(why) {}

  /// Reads a uint32 length into *n; false when fewer than 4 bytes are left.
  bool length(std::uint64_t* n) {
    if (size_ - at_ < 4) return false;
    *n = std::uint64_t(data_[at_]) | (std::uint64_t(data_[at_ + 1]) << 8) | (std::uint64_t(data_[at_ + 2]) << 16) |
         (std::uint64_t(data_[at_ + 3]) << 24);
    at_ += 4;
    return true;
  }
  /// Skips `n` elements of `bytes` each; false when they do not fit.
  bool skip(std::uint64_t n, std::uint64_t bytes) {
    if (n * bytes > size_ - at_) return false;
    at_ += static_cast<std::size_t>(n * bytes);
    return true;
  }
  /// A length-prefixed array of `bytes`-sized elements (a string: 1); false with a message when it does not fit.
  bool array(std::uint64_t bytes, const char* name) {
    if (length(&n_) && skip(n_, bytes)) return true;
    return fail(std::string(name) + " length " + std::to_string(n_) + " does not fit");
  }
  /// std_msgs/Header: uint32 seq, time, string frame_id.
  bool header() { return (skip(1, 12) || fail("header cut short")) && array(1, "frame_id"); }
  /// True when every byte was used.
  bool finished() { return at_ == size_ || fail(std::to_string(size_ - at_) + " bytes left over after the message"); }
  std::size_t left() const { return size_ - at_; }
  /// Always false, saying why.
  bool fail(const std::string& what) {
    if (why_) *why_ = what + " (record of " + std::to_string(size_) + " bytes)";
    return false;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::string* why_;
  std::size_t at_ = 0;
  std::uint64_t n_ = 0;  ///< the last array length read (named in the messages)
};

}  // namespace

bool serializedLaserScanFits(const std::uint8_t* data, std::size_t size, std::string* why) {
  // sensor_msgs/LaserScan: header, 7 float32, float32[] ranges, float32[] intensities.
  RecordWalk r(data, size, why);
  if (!r.header()) return false;
  if (!r.skip(7, 4)) return r.fail("angle and range fields cut short");
  return r.array(4, "ranges") && r.array(4, "intensities") && r.finished();
}

bool serializedTfMessageFits(const std::uint8_t* data, std::size_t size, std::string* why) {
  // tf2_msgs/TFMessage: geometry_msgs/TransformStamped[] — each a header, string child_frame_id and
  // 7 float64 (translation, rotation).
  RecordWalk r(data, size, why);
  std::uint64_t count = 0;
  if (!r.length(&count)) return r.fail("transform count cut short");
  // Each transform takes at least 76 bytes: a count that cannot fit is corruption, caught before any
  // transform is read (and before a deserializer would allocate for it).
  if (count > r.left() / 76) return r.fail(std::to_string(count) + " transforms do not fit");
  for (std::uint64_t i = 0; i < count; ++i) {
    if (!r.header() || !r.array(1, "child_frame_id")) return false;
    if (!r.skip(7, 8)) return r.fail("transform cut short");
  }
  return r.finished();
}

bool serializedOdometryFits(const std::uint8_t* data, std::size_t size, std::string* why) {
  // nav_msgs/Odometry: header, string child_frame_id, pose (7 float64) with its float64[36] covariance,
  // twist (6 float64) with its float64[36] covariance.
  RecordWalk r(data, size, why);
  if (!r.header() || !r.array(1, "child_frame_id")) return false;
  if (!r.skip(7 + 36 + 6 + 36, 8)) return r.fail("pose and twist cut short");
  return r.finished();
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
