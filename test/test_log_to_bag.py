"""log_to_bag on small synthetic logs of each format."""
import math
import os
import subprocess
import tempfile
import unittest

import rosbag

TOOL = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools", "log_to_bag")


def run(*args):
    p = subprocess.run(["/usr/bin/python3", TOOL] + list(args), capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


class LogToBagTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp()

    def path(self, name):
        return os.path.join(self.dir, name)

    def read(self, bag_path):
        with rosbag.Bag(bag_path) as bag:
            return [(topic, msg) for topic, msg, _ in bag.read_messages()]

    def test_carmen(self):
        with open(self.path("a.clf"), "w") as f:
            f.write("# comment\nODOM 0 0 0 0 0 0 1.0 host 1.0\n")
            f.write("FLASER 5 1.0 2.0 81.91 0.5 3.0 0 0 0 1.0 2.0 0.5 100.25 host 100.3\n")
            f.write("FLASER 5 1.5 2.0 2.0 0.5 3.0 0 0 0 1.1 2.0 0.5 100.5 host 100.6\n")
        code, _, err = run("--format", "carmen", self.path("a.clf"), self.path("a.bag"))
        self.assertEqual(code, 0, err)
        msgs = self.read(self.path("a.bag"))
        scans = [m for t, m in msgs if t == "/scan"]
        self.assertEqual(len(scans), 2)
        s = scans[0]
        self.assertAlmostEqual(s.header.stamp.to_sec(), 100.25, places=6)
        self.assertEqual(s.header.frame_id, "laser")
        self.assertAlmostEqual(s.angle_min, -math.pi / 2, places=5)
        self.assertAlmostEqual(s.angle_increment, math.pi / 4, places=5)
        self.assertEqual(list(s.ranges[:2]), [1.0, 2.0])
        self.assertTrue(math.isinf(s.ranges[2]) and s.ranges[2] > 0)  # no return -> +inf
        self.assertEqual(len([m for t, m in msgs if t == "/wheel_odom"]), 2)
        tf = [m for t, m in msgs if t == "/tf_static"]
        self.assertEqual(tf[0].transforms[0].child_frame_id, "laser")

    def test_mines_zero_is_no_return_and_stamps_are_microseconds(self):
        with open(self.path("m.dat"), "w") as f:
            for k in range(2):
                head = [str(1000000 * (k + 1))] + ["0"] * 23
                ranges = ["1000"] * 683
                ranges[0] = "0"
                f.write(" ".join(head + ranges) + "\n")
        code, _, err = run("--format", "mines", self.path("m.dat"), self.path("m.bag"))
        self.assertEqual(code, 0, err)
        scans = [m for t, m in self.read(self.path("m.bag")) if t == "/scan"]
        self.assertEqual(len(scans), 2)
        self.assertEqual(len(scans[0].ranges), 682)
        self.assertTrue(math.isinf(scans[0].ranges[0]))
        self.assertAlmostEqual(scans[0].ranges[1], 1.0)
        self.assertAlmostEqual(scans[1].header.stamp.to_sec(), 2.0)
        self.assertAlmostEqual(scans[0].angle_min, -math.radians(120), places=5)  # float32

    def test_dpslam_is_ten_hertz(self):
        with open(self.path("l.log"), "w") as f:
            for k in range(3):
                f.write("Odometry %d 0 0\nLaser 181 %s\n" % (k, " ".join(["1.5"] * 180 + ["8.19"])))
        code, _, err = run("--format", "dpslam", self.path("l.log"), self.path("l.bag"))
        self.assertEqual(code, 0, err)
        scans = [m for t, m in self.read(self.path("l.bag")) if t == "/scan"]
        self.assertEqual([round(s.header.stamp.to_sec(), 3) for s in scans], [0.0, 0.1, 0.2])
        self.assertTrue(math.isinf(scans[0].ranges[-1]))

    def test_malformed_line_gives_its_number_and_no_bag(self):
        with open(self.path("b.clf"), "w") as f:
            f.write("FLASER 3 1 2 3 0 0 0 0 0 0 5.0 h 5.0\nFLASER 3 1 2\n")
        code, _, err = run("--format", "carmen", self.path("b.clf"), self.path("b.bag"))
        self.assertNotEqual(code, 0)
        self.assertIn("b.clf:2", err)
        self.assertFalse(os.path.exists(self.path("b.bag")))
        self.assertFalse(os.path.exists(self.path("b.bag.tmp")))


if __name__ == "__main__":
    unittest.main()
