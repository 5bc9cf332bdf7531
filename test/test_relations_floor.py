"""scripts/relations_floor.py: its matchers recover a known motion between two synthetic scans, and on a bag
whose relations are off by a known amount it reports that amount as the floor."""
import importlib.util
import io
import json
import math
import os
import shutil
import tempfile
import unittest
from contextlib import redirect_stdout

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location('relations_floor', os.path.join(HERE, '..', 'scripts', 'relations_floor.py'))
rf = importlib.util.module_from_spec(spec)
spec.loader.exec_module(rf)


def room_scan(pose, rng, n=361):
    """Ranges of a 180-degree scanner at pose in a 6 x 4 m room with a 0.5 m pillar, cast exactly, plus
    5 mm noise; returned as points in the scanner frame."""
    segs = [((0, 0), (6, 0)), ((6, 0), (6, 4)), ((6, 4), (0, 4)), ((0, 4), (0, 0)),
            ((3, 2), (3.5, 2)), ((3.5, 2), (3.5, 2.5)), ((3.5, 2.5), (3, 2.5)), ((3, 2.5), (3, 2))]
    pts = []
    for a in np.linspace(-math.pi / 2, math.pi / 2, n):
        d = np.array([math.cos(pose[2] + a), math.sin(pose[2] + a)])
        best = np.inf
        for p, q in segs:
            p, q = np.array(p, float), np.array(q, float)
            m = np.array([d, p - q]).T
            if abs(np.linalg.det(m)) < 1e-12:
                continue
            t, u = np.linalg.solve(m, p - pose[:2])
            if t > 0 and 0 <= u <= 1:
                best = min(best, t)
        r = best + rng.normal(0, 0.005)
        pts.append([r * math.cos(a), r * math.sin(a)])
    return np.array(pts)


class Matchers(unittest.TestCase):
    def test_recover_known_motion(self):
        rng = np.random.default_rng(3)
        p1, p2 = np.array([1.5, 1.0, 0.2]), np.array([1.85, 1.12, 0.28])
        s1, s2 = room_scan(p1, rng), room_scan(p2, rng)
        truth = rf.vec(np.linalg.inv(rf.se2(p1)) @ rf.se2(p2))
        start = truth + np.array([0.05, -0.04, math.radians(2)])
        for line in (True, False):
            est = rf.align(s1, s2, start, point_to_line=line, scale=0.03 if line else 0.05)
            t, r = rf.error(est, truth)
            self.assertLess(t, 0.005, 'point_to_line=%s' % line)
            self.assertLess(r, 0.1, 'point_to_line=%s' % line)


class FloorOnABag(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp()

    def tearDown(self):
        shutil.rmtree(self.dir)

    def test_relations_off_by_3cm_give_a_3cm_floor(self):
        import rosbag
        import rospy
        from sensor_msgs.msg import LaserScan
        rng = np.random.default_rng(5)
        poses = [np.array([1.5 + 0.2 * k, 1.0 + 0.05 * k, 0.1 * k]) for k in range(4)]
        bag_path = os.path.join(self.dir, 'b.bag')
        with rosbag.Bag(bag_path, 'w') as bag:
            for k, p in enumerate(poses):
                pts = room_scan(p, rng)
                msg = LaserScan()
                msg.header.stamp = rospy.Time.from_sec(100.0 + k)
                msg.angle_min, msg.angle_max = -math.pi / 2, math.pi / 2
                msg.angle_increment = math.pi / 360
                msg.range_min, msg.range_max = 0.02, 30.0
                msg.ranges = list(np.hypot(pts[:, 0], pts[:, 1]))
                msg.ranges[7] = float('nan')  # REP-117 values are dropped, not matched
                bag.write('/scan', msg, msg.header.stamp)
        rel_path = os.path.join(self.dir, 'r.txt')
        with open(rel_path, 'w') as f:
            for k in range(3):
                d = rf.vec(np.linalg.inv(rf.se2(poses[k])) @ rf.se2(poses[k + 1]))
                f.write('%.6f %.6f %.6f %.6f 0 0 0 %.6f\n' % (100.0 + k, 101.0 + k, d[0] + 0.03, d[1], d[2]))
            f.write('100.0 150.0 0 0 0 0 0 0\n')  # no scan at 150 s
        tum_path = os.path.join(self.dir, 't.tum')  # the true poses as the estimate
        with open(tum_path, 'w') as f:
            for k, p in enumerate(poses):
                f.write('%.6f %.9f %.9f 0 0 0 %.12f %.12f\n' % (100.0 + k, p[0], p[1], math.sin(p[2] / 2), math.cos(p[2] / 2)))
        out = io.StringIO()
        with redirect_stdout(out):
            self.assertEqual(rf.main(['--bag', bag_path, '--relations', rel_path, '--trajectory', tum_path]), 0)
        res = json.loads(out.getvalue())
        self.assertEqual(res['relations_used'], 3)
        self.assertEqual(res['relations_without_scans'], 1)
        for k in ('fwd', 'rev', 'p2p'):
            self.assertAlmostEqual(res[k]['trans_abs_mean'], 0.03, delta=0.005, msg=k)
        self.assertLess(res['fwd_vs_p2p']['trans_abs_mean'], 0.005)
        self.assertAlmostEqual(res['estimate']['trans_abs_mean'], 0.03, delta=1e-4)  # the relations' offset
        self.assertLess(res['estimate_vs_matchers']['trans_abs_mean'], 0.005)


if __name__ == '__main__':
    unittest.main()
