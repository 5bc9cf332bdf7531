#!/usr/bin/env python3
"""Issue 5 (f): without the static base_link -> laser TF, laser_odometry_node logs an error naming both
frames and publishes nothing; once the TF appears it recovers without a restart."""
import math
import unittest

import rospy
import rostest
import tf2_ros
from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Log
from sensor_msgs.msg import LaserScan


def room_scan(stamp):
    """A stationary URG-04LX-like scan inside a 4 m x 3 m room with a box."""
    m = LaserScan()
    m.header.stamp = stamp
    m.header.frame_id = "/laser"  # leading slash, as old drivers and bags have it
    m.angle_min, m.angle_max = -2.0944, 2.0944
    n = 683
    m.angle_increment = (m.angle_max - m.angle_min) / (n - 1)
    m.range_min, m.range_max = 0.02, 5.6
    for i in range(n):
        a = m.angle_min + i * m.angle_increment
        c, s = math.cos(a), math.sin(a)
        r = min(2.2 / c if c > 1e-6 else 1e9, 1.8 / -c if c < -1e-6 else 1e9,
                1.4 / s if s > 1e-6 else 1e9, 1.6 / -s if s < -1e-6 else 1e9)
        if 0.3 < a < 0.6:
            r = min(r, 1.0)  # a box
        m.ranges.append(r)
    return m


class MissingTfTest(unittest.TestCase):
    def test_error_names_the_frames_and_the_node_recovers(self):
        rospy.init_node("missing_tf_rostest")
        logs, odoms = [], []
        rospy.Subscriber("/rosout_agg", Log, lambda m: logs.append(m))
        rospy.Subscriber("/rosout", Log, lambda m: logs.append(m))
        rospy.Subscriber("odom", Odometry, lambda m: odoms.append(m))
        pub = rospy.Publisher("scan", LaserScan, queue_size=10)
        rate = rospy.Rate(10)
        end = rospy.Time.now() + rospy.Duration(6.0)
        while rospy.Time.now() < end and not rospy.is_shutdown():
            pub.publish(room_scan(rospy.Time.now()))
            rate.sleep()
        errors = [l.msg for l in logs if l.level >= Log.ERROR and l.name.endswith("laser_odometry_node")]
        self.assertTrue(any("base_link" in e and "laser" in e for e in errors),
                        "no error naming base_link and laser: %s" % errors[:3])
        self.assertEqual(odoms, [], "odometry published without the laser's TF")

        broadcaster = tf2_ros.StaticTransformBroadcaster()
        t = TransformStamped()
        t.header.stamp = rospy.Time.now()
        t.header.frame_id = "base_link"
        t.child_frame_id = "laser"
        t.transform.translation.x = 0.1
        t.transform.rotation.w = 1.0
        broadcaster.sendTransform(t)
        end = rospy.Time.now() + rospy.Duration(8.0)
        while rospy.Time.now() < end and len(odoms) < 20 and not rospy.is_shutdown():
            pub.publish(room_scan(rospy.Time.now()))
            rate.sleep()
        self.assertGreaterEqual(len(odoms), 20, "the node did not recover once the TF appeared")
        last = odoms[-1].pose.pose.position
        self.assertLess(math.hypot(last.x, last.y), 0.05)  # the scans are stationary


if __name__ == "__main__":
    rostest.rosrun("laser_dpslam", "missing_tf_rostest", MissingTfTest)
