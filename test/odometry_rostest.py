#!/usr/bin/env python3
"""Issue 5 (b, e) for the laser odometry: the demo bag is played through launch/bag.launch (slam:=false,
simulated time, rosbag play --clock). Checks that every scan gives one odom stamped with the scan's
time, that the TF chain odom -> base_link -> laser resolves at the scan stamps (and odom -> base_link
there equals the odom message), and that the final pose is within a tolerance of the ground truth."""
import math
import os
import threading
import time
import unittest

import rospy
import rostest
import tf2_ros
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan

PKG = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
BAG_SCANS = 981            # /scan messages in bags/demo.bag (98 s at 10 Hz)
FINAL_TOLERANCE_M = 0.25   # 1 % of the 24.4 m run; laser odometry ends ~0.08 m off
FINAL_TOLERANCE_DEG = 2.0


def yaw_of(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def relative(a, b):
    """Pose b (x, y, yaw) expressed in pose a's frame."""
    c, s = math.cos(a[2]), math.sin(a[2])
    dx, dy = b[0] - a[0], b[1] - a[1]
    d = b[2] - a[2]
    return (c * dx + s * dy, -s * dx + c * dy, math.atan2(math.sin(d), math.cos(d)))


def load_truth():
    truth = {}
    with open(os.path.join(PKG, "bags", "demo_ground_truth.tum")) as f:
        for line in f:
            v = [float(x) for x in line.split()]
            truth[round(v[0], 3)] = (v[1], v[2], 2.0 * math.atan2(v[6], v[7]))
    return truth


class OdometryRostest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("odometry_rostest")
        cls.lock = threading.Lock()
        cls.scans, cls.odoms = [], []
        cls.buffer = tf2_ros.Buffer(rospy.Duration(300.0))  # keeps the whole bag (98 s)
        cls.listener = tf2_ros.TransformListener(cls.buffer)
        rospy.Subscriber("scan", LaserScan, cls.on_scan, queue_size=100)
        rospy.Subscriber("odom", Odometry, cls.on_odom, queue_size=100)
        # Wall clock: the simulated clock only runs while the bag plays. Wait for the whole bag, or
        # until nothing new came for 5 s once it started.
        start = last_change = time.time()
        last_count = -1
        while not rospy.is_shutdown() and time.time() < start + 80.0:
            time.sleep(0.5)
            with cls.lock:
                n = len(cls.scans) + len(cls.odoms)
                done = len(cls.scans) >= BAG_SCANS and len(cls.odoms) >= len(cls.scans) - 2
            if done:
                break
            if n != last_count:
                last_count, last_change = n, time.time()
            elif n > 0 and time.time() > last_change + 5.0:
                break
        time.sleep(1.0)  # the last odom and TF messages

    @classmethod
    def on_scan(cls, msg):
        with cls.lock:
            cls.scans.append(msg.header.stamp)

    @classmethod
    def on_odom(cls, msg):
        with cls.lock:
            cls.odoms.append(msg)

    def test_1_one_odom_per_scan_stamped_with_the_scan_time(self):
        self.assertGreaterEqual(len(self.scans), BAG_SCANS - 5, "the bag was not played (scans: %d)" % len(self.scans))
        scan_stamps = set(self.scans)
        odom_stamps = [o.header.stamp for o in self.odoms]
        self.assertGreaterEqual(len(odom_stamps), len(self.scans) - 2, "odom missing for some scans")
        not_scan = [s.to_sec() for s in odom_stamps if s not in scan_stamps]
        self.assertEqual(not_scan, [], "odom stamps that are no scan's stamp (now() instead of the scan time?)")
        self.assertEqual(len(set(odom_stamps)), len(odom_stamps), "two odom messages with the same stamp")
        for o in self.odoms[:1]:
            self.assertEqual(o.header.frame_id, "odom")
            self.assertEqual(o.child_frame_id, "base_link")

    def test_2_tf_chain_resolves_at_scan_time(self):
        self.assertTrue(self.odoms)
        checked = 0
        for o in self.odoms[5::20]:
            stamp = o.header.stamp
            try:
                self.buffer.lookup_transform("odom", "laser", stamp, rospy.Duration(0.0))
                t = self.buffer.lookup_transform("odom", "base_link", stamp, rospy.Duration(0.0))
            except tf2_ros.TransformException as e:
                self.fail("odom -> base_link -> laser does not resolve at scan stamp %.3f: %s" % (stamp.to_sec(), e))
            # The TF at the scan's stamp is the odom message's pose: both carry the scan time.
            p = o.pose.pose
            self.assertAlmostEqual(t.transform.translation.x, p.position.x, places=4)
            self.assertAlmostEqual(t.transform.translation.y, p.position.y, places=4)
            self.assertAlmostEqual(yaw_of(t.transform.rotation), yaw_of(p.orientation), places=4)
            checked += 1
        self.assertGreater(checked, 20)

    def test_3_covariance_is_filled(self):
        c = self.odoms[-1].pose.covariance
        for i in (0, 7, 35):
            self.assertGreater(c[i], 0.0, "pose covariance [%d] not positive" % i)
            self.assertLess(c[i], 1e6)
        self.assertGreaterEqual(c[14], 1e6 - 1)  # z: unused axis

    def test_4_final_pose_against_ground_truth(self):
        self.assertGreater(len(self.odoms), 900)
        truth = load_truth()
        first, last = self.odoms[0], self.odoms[-1]
        t_first = truth[round(first.header.stamp.to_sec(), 3)]
        t_last = truth[round(last.header.stamp.to_sec(), 3)]
        expected = relative(t_first, t_last)

        def pose(o):
            p = o.pose.pose
            return (p.position.x, p.position.y, yaw_of(p.orientation))

        got = relative(pose(first), pose(last))
        err = math.hypot(got[0] - expected[0], got[1] - expected[1])
        derr = math.degrees(abs(math.atan2(math.sin(got[2] - expected[2]), math.cos(got[2] - expected[2]))))
        rospy.loginfo("odometry_rostest: final pose %.3f m / %.2f deg from the ground truth", err, derr)
        print("final pose error: %.3f m, %.2f deg (%d odom messages)" % (err, derr, len(self.odoms)))
        self.assertLess(err, FINAL_TOLERANCE_M, "final odom pose %.3f m from the ground truth" % err)
        self.assertLess(derr, FINAL_TOLERANCE_DEG, "final odom yaw %.2f deg from the ground truth" % derr)


if __name__ == "__main__":
    rostest.rosrun("laser_dpslam", "odometry_rostest", OdometryRostest)
