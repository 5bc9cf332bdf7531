#!/usr/bin/env python3
"""Listener of scripts/benchmark_lag.sh: how far the SLAM's map -> odom lags the scan time, under sim time.

    lag_listener.py --out DIR [--map-frame map] [--odom-frame odom]

Until shut down (SIGINT), records
  - every map -> odom transform on /tf: lag = ROS time when it arrives (the /clock of rosbag play) - its stamp;
  - the SLAM's live pose (`pose`) and its last output path (`trajectory`);
  - dpslam_node's /diagnostics: the last status, and how many came at each level;
then writes to DIR: lag.csv (stamp, lag), pose.tum, trajectory.tum and summary.json (lag median / p95 / max
in s, transforms counted, the last diagnostics' key/values, the count of statuses per level).
"""
import argparse
import json
import math
import os

import rospy
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PoseWithCovarianceStamped
from nav_msgs.msg import Path
from tf2_msgs.msg import TFMessage


def yaw_quaternion(q):
    """The TUM quaternion (qx qy qz qw) of the yaw of q, as the evaluation reads only the yaw."""
    yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
    return (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))


def tum_line(stamp, pose):
    qx, qy, qz, qw = yaw_quaternion(pose.orientation)
    return "%.6f %.6f %.6f 0 %.9f %.9f %.9f %.9f\n" % (stamp, pose.position.x, pose.position.y, qx, qy, qz, qw)


def percentile(sorted_values, p):
    """Nearest rank (as run_statistics.cpp): the ceil(p n)-th smallest."""
    if not sorted_values:
        return None
    k = max(1, int(math.ceil(p * len(sorted_values))))
    return sorted_values[k - 1]


def median(sorted_values):
    n = len(sorted_values)
    if n == 0:
        return None
    return sorted_values[n // 2] if n % 2 else 0.5 * (sorted_values[n // 2 - 1] + sorted_values[n // 2])


class Listener:
    def __init__(self, map_frame, odom_frame):
        self.map_frame, self.odom_frame = map_frame, odom_frame
        self.lags = []  # (stamp, lag)
        self.poses = []  # (stamp, pose)
        self.path = None
        self.diagnostics = None
        self.levels = {}  # diagnostic level (0 OK, 1 WARN, 2 ERROR) -> statuses received
        rospy.Subscriber("/tf", TFMessage, self.on_tf, queue_size=200)
        rospy.Subscriber("pose", PoseWithCovarianceStamped, self.on_pose, queue_size=200)
        rospy.Subscriber("trajectory", Path, self.on_path, queue_size=2)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=20)

    def on_tf(self, msg):
        now = rospy.get_rostime().to_sec()
        for t in msg.transforms:
            if t.header.frame_id.lstrip("/") == self.map_frame and t.child_frame_id.lstrip("/") == self.odom_frame:
                stamp = t.header.stamp.to_sec()
                self.lags.append((stamp, now - stamp))

    def on_pose(self, msg):
        self.poses.append((msg.header.stamp.to_sec(), msg.pose.pose))

    def on_path(self, msg):
        self.path = msg

    def on_diagnostics(self, msg):
        for s in msg.status:
            if "dpslam_node" in s.name:
                self.diagnostics = {"name": s.name, "level": int(s.level), "message": s.message,
                                    "values": {kv.key: kv.value for kv in s.values}}
                self.levels[int(s.level)] = self.levels.get(int(s.level), 0) + 1

    def write(self, out):
        os.makedirs(out, exist_ok=True)
        with open(os.path.join(out, "lag.csv"), "w") as f:
            f.write("stamp,lag\n")
            for stamp, lag in self.lags:
                f.write("%.6f,%.6f\n" % (stamp, lag))
        with open(os.path.join(out, "pose.tum"), "w") as f:
            for stamp, pose in self.poses:
                f.write(tum_line(stamp, pose))
        with open(os.path.join(out, "trajectory.tum"), "w") as f:
            for ps in (self.path.poses if self.path else []):
                f.write(tum_line(ps.header.stamp.to_sec(), ps.pose))
        lags = sorted(lag for _, lag in self.lags)
        summary = {
            "transforms": len(lags),
            "lag_median_s": median(lags),
            "lag_p95_s": percentile(lags, 0.95),
            "lag_max_s": lags[-1] if lags else None,
            "poses": len(self.poses),
            "trajectory_poses": len(self.path.poses) if self.path else 0,
            "diagnostics": self.diagnostics,
            "diagnostics_levels": self.levels,
        }
        with open(os.path.join(out, "summary.json"), "w") as f:
            json.dump(summary, f, indent=1)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", required=True)
    parser.add_argument("--map-frame", default="map")
    parser.add_argument("--odom-frame", default="odom")
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node("lag_listener")
    listener = Listener(args.map_frame, args.odom_frame)
    rospy.spin()
    listener.write(args.out)


if __name__ == "__main__":
    main()
