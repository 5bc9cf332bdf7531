#include "laser_dpslam/ros/bag_tf.h"

#include <rosbag/view.h>
#include <tf2/LinearMath/Transform.h>
#include <tf2_msgs/TFMessage.h>

#include <map>
#include <set>

#include "laser_dpslam/ros/bag_scan_reader.h"
#include "laser_dpslam/ros/msg_conversion.h"

namespace laser_dpslam {

namespace {
tf2::Transform toTf(const geometry_msgs::Transform& t) {
  return tf2::Transform(tf2::Quaternion(t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w).normalized(),
                        tf2::Vector3(t.translation.x, t.translation.y, t.translation.z));
}
}  // namespace

bool findBagTransform(rosbag::Bag& bag, const std::string& parent, const std::string& child,
                      geometry_msgs::Transform* out, std::string* error) {
  const std::string p = cleanFrameId(parent), c = cleanFrameId(child);
  // child frame → (parent frame, transform parent→child); first occurrence wins (static mounts).
  std::map<std::string, std::pair<std::string, geometry_msgs::Transform>> edges;
  std::set<std::string> frames;
  rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{"/tf_static", "/tf", "tf_static", "tf"}));
  int damaged = 0;
  std::string damage;
  for (const rosbag::MessageInstance& m : view) {
    // Checked before deserializing (a corrupted array length would make the deserializer allocate and
    // fill gigabytes); a damaged record is skipped: the others may still hold the transform.
    tf2_msgs::TFMessage::Ptr msg;
    try {
      msg = readTfMessage(m);
    } catch (const std::exception& e) {
      if (damaged++ == 0) damage = m.getTopic() + " at " + std::to_string(m.getTime().toSec()) + " s: " + e.what();
      continue;
    }
    if (!msg) continue;
    for (const auto& t : msg->transforms) {
      const std::string tp = cleanFrameId(t.header.frame_id), tc = cleanFrameId(t.child_frame_id);
      frames.insert(tp);
      frames.insert(tc);
      if (!edges.count(tc)) edges[tc] = {tp, t.transform};
    }
  }
  tf2::Transform acc;
  acc.setIdentity();
  std::string frame = c;
  for (int depth = 0; depth < 32 && frame != p; ++depth) {
    auto it = edges.find(frame);
    if (it == edges.end()) break;
    acc = toTf(it->second.second) * acc;
    frame = it->second.first;
  }
  if (frame != p) {
    if (error) {
      std::string seen;
      for (const auto& f : frames) seen += (seen.empty() ? "" : ", ") + f;
      *error = "no transform " + p + " -> " + c + " in the bag's /tf_static or /tf (frames seen: " +
               (seen.empty() ? "none" : seen) + ")";
      if (damaged > 0) *error += "; skipped " + std::to_string(damaged) + " damaged TF record(s), the first " + damage;
    }
    return false;
  }
  out->translation.x = acc.getOrigin().x();
  out->translation.y = acc.getOrigin().y();
  out->translation.z = acc.getOrigin().z();
  const tf2::Quaternion q = acc.getRotation();
  out->rotation.x = q.x();
  out->rotation.y = q.y();
  out->rotation.z = q.z();
  out->rotation.w = q.w();
  return true;
}

}  // namespace laser_dpslam
