"""scripts/loop_closure_bound.py: ideal loop closures pull a drifting estimate of a twice-driven square back
to the truth, and leave an exact estimate exact."""
import importlib.util
import math
import os
import tempfile
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location('loop_closure_bound',
                                              os.path.join(HERE, '..', 'scripts', 'loop_closure_bound.py'))
lcb = importlib.util.module_from_spec(spec)
spec.loader.exec_module(lcb)


def square_laps(laps=2, side=10.0, step=0.1):
    """x, y, theta along a side x side square driven counter-clockwise `laps` times."""
    poses = []
    for _ in range(laps):
        for k in range(4):
            th = k * math.pi / 2
            x0, y0 = [(0, 0), (side, 0), (side, side), (0, side)][k]
            for i in range(int(round(side / step))):
                poses.append((x0 + i * step * math.cos(th), y0 + i * step * math.sin(th), th))
    poses.append((0.0, 0.0, 2 * math.pi * laps))
    return np.array(poses)


def write_tum(path, poses):
    with open(path, 'w') as f:
        for i, (x, y, th) in enumerate(poses):
            f.write('%.6f %.6f %.6f 0 0 0 %.9f %.9f\n' % (i * 0.1, x, y, math.sin(th / 2), math.cos(th / 2)))


def drifted(poses, yaw_bias):
    """Dead reckoning of the true steps with a heading error growing by yaw_bias per step."""
    out = [poses[0].copy()]
    for i in range(1, len(poses)):
        d = lcb.relative(poses[i - 1], poses[i])
        d[2] += yaw_bias
        x, y, th = out[-1]
        out.append(np.array([x + math.cos(th) * d[0] - math.sin(th) * d[1],
                             y + math.sin(th) * d[0] + math.cos(th) * d[1], th + d[2]]))
    return np.array(out)


class LoopClosureBoundTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp()
        self.truth = square_laps()
        self.ref = os.path.join(self.dir, 'truth.tum')
        write_tum(self.ref, self.truth)

    def test_closures_pull_a_drifting_estimate_back(self):
        est = os.path.join(self.dir, 'est.tum')
        write_tum(est, drifted(self.truth, 5e-4))  # 0.03 deg per 0.1 m: 23 deg over the 80 m
        out = lcb.bound(est, self.ref, min_separation=20.0)
        self.assertGreater(out['closures'], 10)
        self.assertGreater(out['ate_estimate_m'], 0.5)
        self.assertLess(out['ate_bound_m'], 0.05 * out['ate_estimate_m'])  # 0.68 -> 0.005 m when written

    def test_an_exact_estimate_stays_exact(self):
        out = lcb.bound(self.ref, self.ref)
        self.assertGreater(out['closures'], 10)
        self.assertLess(out['ate_estimate_m'], 1e-6)
        self.assertLess(out['ate_bound_m'], 0.01)  # only the closures' 1 cm noise

    def test_the_odometry_covariance_puts_the_correction_where_the_error_is(self):
        # All the drift in one stretch of lap 1 (2.3 deg over 2 m), which the match log marks as uncertain.
        bad = range(150, 170)
        est_poses = [self.truth[0].copy()]
        for i in range(1, len(self.truth)):
            d = lcb.relative(self.truth[i - 1], self.truth[i])
            d[2] += 2e-3 if i in bad else 0.0
            x, y, th = est_poses[-1]
            est_poses.append(np.array([x + math.cos(th) * d[0] - math.sin(th) * d[1],
                                       y + math.sin(th) * d[0] + math.cos(th) * d[1], th + d[2]]))
        est = os.path.join(self.dir, 'est.tum')
        write_tum(est, est_poses)
        log = os.path.join(self.dir, 'match.csv')
        with open(log, 'w') as f:
            f.write('stamp,ok,skip_reason,sxx,syy,stt\n')
            for i in range(len(est_poses)):
                f.write('%.6f,1,,1e-6,1e-6,%g\n' % (i * 0.1, 1e-4 if i in bad else 1e-8))
        uniform = lcb.bound(est, self.ref)
        weighted = lcb.bound(est, self.ref, match_log=log)
        self.assertGreater(weighted['closures'], 10)
        self.assertLess(weighted["ate_bound_m"], 0.5 * uniform["ate_bound_m"])  # 0.0029 vs 0.0111 m when written
        # A log of another run (stamps missing) is an error, not a silent fallback.
        with open(log, 'w') as f:
            f.write('stamp,sxx,syy,stt\n0.0,1e-6,1e-6,1e-8\n')
        with self.assertRaises(lcb.ET.InputError):
            lcb.bound(est, self.ref, match_log=log)

    def test_no_overlap_in_time_is_an_error(self):
        est = os.path.join(self.dir, 'late.tum')
        with open(est, 'w') as f:
            f.write('1000 0 0 0 0 0 0 1\n1001 1 0 0 0 0 0 1\n')
        self.assertEqual(lcb.main(['--estimate', est, '--reference', self.ref]), 1)


if __name__ == '__main__':
    unittest.main()
