"""tools/evaluate_relations on synthetic trajectories whose errors are known in closed form or computed here
independently (3x3 homogeneous SE(2) matrices; the tool uses quaternions)."""
import json
import math
import os
import shutil
import statistics
import subprocess
import tempfile
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
TOOL = os.path.join(HERE, '..', 'tools', 'evaluate_relations')
DATASETS = os.path.join(HERE, '..', '..', 'shared', 'datasets')
REQUIRED_KEYS = {'relations', 'used', 'trans_abs_mean', 'trans_abs_std', 'trans_sqr_mean', 'trans_sqr_std',
                 'rot_abs_mean_deg', 'rot_abs_std_deg', 'rot_sqr_mean_deg2', 'rot_sqr_std_deg2'}


def run(*args):
    p = subprocess.run(['/usr/bin/python3', TOOL] + list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       universal_newlines=True)
    return p.returncode, p.stdout, p.stderr


def se2(x, y, th):
    c, s = math.cos(th), math.sin(th)
    return np.array([[c, -s, x], [s, c, y], [0.0, 0.0, 1.0]])


def params(m):
    return m[0, 2], m[1, 2], math.atan2(m[1, 0], m[0, 0])


def write_tum(path, poses):
    with open(path, 'w') as f:
        f.write('# stamp x y z qx qy qz qw\n')
        for t, x, y, th in poses:
            f.write('%.9f %.12f %.12f 0 0 0 %.15f %.15f\n' % (t, x, y, math.sin(th / 2), math.cos(th / 2)))


def write_relations(path, rels):
    """rels: (t1, t2, dx, dy, yaw) or (t1, t2, dx, dy, dz, roll, pitch, yaw)."""
    with open(path, 'w') as f:
        for r in rels:
            if len(r) == 5:
                r = (r[0], r[1], r[2], r[3], 0.0, 0.0, 0.0, r[4])
            f.write(' '.join('%.15g' % v for v in r) + '\n')


def stats(values):
    """Expected (mean, std with n-1) computed with the statistics module."""
    return statistics.mean(values), statistics.stdev(values)


class EvaluateRelationsTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp()
        # A curved path sampled at 0.5 s: stamps 10.0 .. 29.5, heading through +-pi.
        self.poses = [(10.0 + 0.5 * k, 2.0 * math.cos(0.1 * k) + 0.05 * k, 1.5 * math.sin(0.13 * k),
                       math.atan2(math.sin(0.21 * k + 2.0), math.cos(0.21 * k + 2.0))) for k in range(40)]
        self.tum = self.path('t.tum')
        write_tum(self.tum, self.poses)

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def path(self, name):
        return os.path.join(self.dir, name)

    def true_delta(self, i, j):
        a, b = self.poses[i], self.poses[j]
        return params(np.linalg.inv(se2(*a[1:])) @ se2(*b[1:]))

    def evaluate(self, rels, *extra):
        write_relations(self.path('r.txt'), rels)
        code, out, err = run('--trajectory', self.tum, '--relations', self.path('r.txt'), *extra)
        self.assertEqual(code, 0, err)
        result = json.loads(out)
        self.assertTrue(REQUIRED_KEYS <= set(result), set(result))
        return result

    def pairs(self):
        return [(i, i + 1 + (i % 3)) for i in range(0, 36)]

    def test_exact_relations_give_zero(self):
        rels = [(self.poses[i][0], self.poses[j][0]) + self.true_delta(i, j) for i, j in self.pairs()]
        r = self.evaluate(rels)
        self.assertEqual((r['relations'], r['used'], r['clamped']), (36, 36, 0))
        for key in REQUIRED_KEYS - {'relations', 'used'}:
            self.assertLess(abs(r[key]), 1e-6, key)

    def test_translation_bias_gives_its_norm(self):
        # delta* = (R, t + b): E = delta * delta*^-1 = (I, -b) whatever the relation, so |t(E)| = |b| = 0.05.
        rels, expected = [], []
        for n, (i, j) in enumerate(self.pairs()):
            dx, dy, dth = self.true_delta(i, j)
            biased = n % 3 == 0
            rels.append((self.poses[i][0], self.poses[j][0], dx + 0.03 * biased, dy - 0.04 * biased, dth))
            expected.append(0.05 if biased else 0.0)
        r = self.evaluate(rels)
        mean, std = stats(expected)
        self.assertAlmostEqual(r['trans_abs_mean'], mean, places=9)
        self.assertAlmostEqual(r['trans_abs_std'], std, places=9)
        sqr_mean, sqr_std = stats([e * e for e in expected])
        self.assertAlmostEqual(r['trans_sqr_mean'], sqr_mean, places=9)
        self.assertAlmostEqual(r['trans_sqr_std'], sqr_std, places=9)
        self.assertLess(r['rot_abs_mean_deg'], 1e-6)

    def test_rotation_bias_gives_its_angle_and_the_chord(self):
        # delta* = (R R_phi, t): E = (R R_phi^-1 R^-1, t - R R_phi^-1 R^-1 t): angle |phi|, |t(E)| = 2|t| sin(phi/2).
        phi = math.radians(2.0)
        rels, et, er = [], [], []
        for n, (i, j) in enumerate(self.pairs()):
            dx, dy, dth = self.true_delta(i, j)
            sign = 1 if n % 2 else -1
            rels.append((self.poses[i][0], self.poses[j][0], dx, dy, dth + sign * phi))
            et.append(2.0 * math.hypot(dx, dy) * math.sin(phi / 2))
            er.append(2.0)
        r = self.evaluate(rels)
        self.assertAlmostEqual(r['rot_abs_mean_deg'], 2.0, places=7)
        self.assertLess(r['rot_abs_std_deg'], 1e-6)
        self.assertAlmostEqual(r['rot_sqr_mean_deg2'], 4.0, places=6)
        self.assertAlmostEqual(r['trans_abs_mean'], statistics.mean(et), places=9)
        self.assertAlmostEqual(r['trans_abs_std'], statistics.stdev(et), places=9)

    def test_error_is_estimate_times_inverse_truth(self):
        # General perturbation: compare with E = (T1^-1 T2) D^-1 from matrices, and check the test tells it apart
        # from the other order D^-1 (T1^-1 T2).
        rng = np.random.RandomState(3)
        rels, et, er, et_other = [], [], [], []
        for i, j in self.pairs():
            dx, dy, dth = self.true_delta(i, j)
            d = (dx + rng.normal(0, 0.1), dy + rng.normal(0, 0.1), dth + rng.normal(0, 0.1))
            rels.append((self.poses[i][0], self.poses[j][0]) + d)
            est = np.linalg.inv(se2(*self.poses[i][1:])) @ se2(*self.poses[j][1:])
            e = params(est @ np.linalg.inv(se2(*d)))
            et.append(math.hypot(e[0], e[1]))
            er.append(abs(math.degrees(e[2])))
            o = params(np.linalg.inv(se2(*d)) @ est)
            et_other.append(math.hypot(o[0], o[1]))
        r = self.evaluate(rels)
        self.assertAlmostEqual(r['trans_abs_mean'], statistics.mean(et), places=9)
        self.assertAlmostEqual(r['trans_abs_std'], statistics.stdev(et), places=9)
        self.assertAlmostEqual(r['rot_abs_mean_deg'], statistics.mean(er), places=7)
        self.assertAlmostEqual(r['rot_abs_std_deg'], statistics.stdev(er), places=7)
        self.assertGreater(abs(statistics.mean(et) - statistics.mean(et_other)), 1e-3)

    def test_interpolates_linearly_between_samples(self):
        # x = t, y = 0.5 t, theta = 0.3 t sampled at whole seconds; relations at fractional times are exact.
        poses = [(float(t), float(t), 0.5 * t, 0.3 * t) for t in range(8)]
        write_tum(self.tum, poses)
        rels = []
        for t1, t2 in ((0.25, 2.5), (1.1, 1.9), (3.75, 6.2), (0.0, 7.0)):
            d = params(np.linalg.inv(se2(t1, 0.5 * t1, 0.3 * t1)) @ se2(t2, 0.5 * t2, 0.3 * t2))
            rels.append((t1, t2) + d)
        r = self.evaluate(rels)
        self.assertLess(r['trans_abs_mean'], 1e-9)
        self.assertLess(r['rot_abs_mean_deg'], 1e-7)
        # Nearest-sample lookup (or interpolating angles the long way) would not give 0 at these stamps.
        self.assertGreater(abs(params(np.linalg.inv(se2(0.0, 0.0, 0.0)) @ se2(3.0, 1.5, 0.9))[0] - rels[0][2]), 0.1)

    def test_heading_is_interpolated_on_the_shortest_arc(self):
        # 3.0 rad -> -3.0 rad is a 0.283 rad turn through pi, not a 6 rad turn through 0.
        write_tum(self.tum, [(0.0, 0.0, 0.0, 3.0), (1.0, 0.0, 0.0, -3.0)])
        half = (2.0 * math.pi - 6.0) / 2.0
        r = self.evaluate([(0.0, 0.5, 0.0, 0.0, half), (0.5, 1.0, 0.0, 0.0, half)])
        self.assertLess(r['rot_abs_mean_deg'], 1e-7)

    def test_clamped_to_the_trajectory_ends(self):
        first, last = self.poses[0], self.poses[-1]
        d = self.true_delta(0, len(self.poses) - 1)
        r = self.evaluate([(first[0] - 5.0, last[0] + 5.0) + d, (first[0], last[0]) + d])
        self.assertEqual(r['used'], 2)
        self.assertEqual(r['clamped'], 1)
        self.assertLess(r['trans_abs_mean'], 1e-9)
        self.assertLess(r['rot_abs_mean_deg'], 1e-7)

    def test_max_dt_keeps_short_relations(self):
        # Exact relations over 0.5 s and 1.0 s, biased ones over 1.5 s: --max-dt 1.0 keeps the first two
        # kinds (|t2 - t1| <= S inclusive) and so reports zero error.
        rels = []
        for i, j in self.pairs():
            dx, dy, dth = self.true_delta(i, j)
            bias = 0.2 if j - i == 3 else 0.0
            rels.append((self.poses[i][0], self.poses[j][0], dx + bias, dy, dth))
        n_short = sum(1 for i, j in self.pairs() if j - i <= 2)
        r = self.evaluate(rels, '--max-dt', '1.0')
        self.assertEqual((r['relations'], r['used']), (36, n_short))
        self.assertLess(r['trans_abs_mean'], 1e-9)
        r_all = self.evaluate(rels)
        self.assertEqual(r_all['used'], 36)
        self.assertAlmostEqual(r_all['trans_abs_mean'], 0.2 * (36 - n_short) / 36.0, places=9)
        r_none = self.evaluate(rels, '--max-dt', '0.1')
        self.assertEqual(r_none['used'], 0)
        self.assertIsNone(r_none['trans_abs_mean'])

    def test_roll_and_pitch_of_a_relation_count(self):
        write_tum(self.tum, [(0.0, 0.0, 0.0, 0.0), (1.0, 1.0, 0.0, 0.0)])
        r = self.evaluate([(0.0, 1.0, 1.0, 0.0, 0.0, math.radians(3.0), math.radians(4.0), 0.0)])
        # Rx(3 deg) then Ry(4 deg): a single rotation of arccos((trace - 1) / 2).
        c3, s3, c4, s4 = math.cos(math.radians(3)), math.sin(math.radians(3)), math.cos(math.radians(4)), \
            math.sin(math.radians(4))
        ry = np.array([[c4, 0, s4], [0, 1, 0], [-s4, 0, c4]])
        rx = np.array([[1, 0, 0], [0, c3, -s3], [0, s3, c3]])
        angle = math.degrees(math.acos((np.trace(ry @ rx) - 1.0) / 2.0))
        self.assertAlmostEqual(r['rot_abs_mean_deg'], angle, places=6)
        self.assertIsNone(r['rot_abs_std_deg'])  # one relation: n - 1 = 0

    def expect_error(self, tum_text, rel_text, where):
        with open(self.path('bad.tum'), 'w') as f:
            f.write(tum_text)
        with open(self.path('bad.txt'), 'w') as f:
            f.write(rel_text)
        code, out, err = run('--trajectory', self.path('bad.tum'), '--relations', self.path('bad.txt'))
        self.assertNotEqual(code, 0)
        self.assertEqual(out, '')
        self.assertIn(where, err)

    def test_malformed_input_names_file_and_line(self):
        good_tum = '0 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n'
        good_rel = '0 1 1 0 0 0 0 0\n'
        self.expect_error(good_tum, '# t1 t2 ...\n0 1 1 0 0 0 0 0\n0 1 x 0 0 0 0 0\n', 'bad.txt:3')
        self.expect_error(good_tum, '0 1 1 0 0 0 0\n', 'bad.txt:1')
        self.expect_error(good_tum, '0 1 1 0 0 0 0 nan\n', 'bad.txt:1')
        self.expect_error('0 0 0 0 0 0 0 1\n1 1 0 0 0 0 1\n', good_rel, 'bad.tum:2')
        self.expect_error('0 0 0 0 0 0 0 1\n\n0 1 0 0 0 0 0 1\n', good_rel, 'bad.tum:3')  # stamp not increasing
        self.expect_error('0 0 0 0 0 0 0 0\n', good_rel, 'bad.tum:1')  # zero quaternion
        self.expect_error('', good_rel, 'bad.tum')
        self.expect_error(good_tum, '', 'bad.txt')

    def test_mit_csail_relations_with_its_odometry(self):
        """Optional: the benchmark relations against the CARMEN log's own odometry (needs shared/datasets)."""
        clf = os.path.join(DATASETS, 'mit-csail', 'mit-csail.clf')
        rel = os.path.join(DATASETS, 'mit-csail', 'mit-csail.relations')
        if not (os.path.exists(clf) and os.path.exists(rel)):
            raise unittest.SkipTest('shared/datasets/mit-csail not found')
        poses = []
        with open(clf) as f:
            for line in f:
                tok = line.split()
                if tok and tok[0] == 'FLASER':
                    n = int(tok[1])
                    poses.append((float(tok[n + 8]), float(tok[n + 5]), float(tok[n + 6]), float(tok[n + 7])))
        write_tum(self.tum, poses)
        code, out, err = run('--trajectory', self.tum, '--relations', rel)
        self.assertEqual(code, 0, err)
        r = json.loads(out)
        self.assertEqual((r['relations'], r['used'], r['clamped']), (1172, 1172, 0))
        # Independent SE(2) computation of the first relations (relation stamps are FLASER stamps +-1 ms).
        stamps = np.array([p[0] for p in poses])
        with open(rel) as f:
            rows = [list(map(float, line.split())) for line in f if line.strip()][:50]
        et = []
        for t1, t2, dx, dy, _dz, _r, _p, yaw in rows:
            def pose_at(t):
                k = int(np.clip(np.searchsorted(stamps, t) - 1, 0, len(stamps) - 2))
                a = min(max((t - stamps[k]) / (stamps[k + 1] - stamps[k]), 0.0), 1.0)
                p0, p1 = poses[k], poses[k + 1]
                dth = math.atan2(math.sin(p1[3] - p0[3]), math.cos(p1[3] - p0[3]))
                return se2(p0[1] + a * (p1[1] - p0[1]), p0[2] + a * (p1[2] - p0[2]), p0[3] + a * dth)
            e = params(np.linalg.inv(pose_at(t1)) @ pose_at(t2) @ np.linalg.inv(se2(dx, dy, yaw)))
            et.append(math.hypot(e[0], e[1]))
        with open(self.path('first50.txt'), 'w') as f:
            f.write(''.join(' '.join('%.17g' % v for v in row) + '\n' for row in rows))
        code, out, err = run('--trajectory', self.tum, '--relations', self.path('first50.txt'))
        self.assertAlmostEqual(json.loads(out)['trans_abs_mean'], statistics.mean(et), places=9)


if __name__ == '__main__':
    unittest.main()
