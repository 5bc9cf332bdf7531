"""tools/evaluate_trajectory on trajectories whose errors are known in closed form."""
import json
import math
import os
import shutil
import subprocess
import tempfile
import unittest

import numpy as np

TOOL = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'tools', 'evaluate_trajectory')
REQUIRED_KEYS = {'poses', 'ate_rmse_m', 'ate_max_m', 'rpe_trans_per_m', 'rpe_rot_deg_per_m', 'drift_percent'}


def write(path, poses, header=True):
    with open(path, 'w') as f:
        if header:
            f.write('# stamp x y z qx qy qz qw\n')
        for t, x, y, th in poses:
            f.write('%.6f %.12f %.12f 0 0 0 %.15f %.15f\n' % (t, x, y, math.sin(th / 2), math.cos(th / 2)))


def run(*args):
    p = subprocess.run(['/usr/bin/python3', TOOL] + list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       universal_newlines=True)
    return p.returncode, p.stdout, p.stderr


def square_loop():
    """A 10 m square (2.5 m sides) at 0.1 m steps, 0.1 s apart, heading along the path."""
    poses, t = [], 0.0
    for side in range(4):
        th = side * math.pi / 2
        ox, oy = [(0, 0), (2.5, 0), (2.5, 2.5), (0, 2.5)][side]
        for k in range(25):
            poses.append((t, ox + 0.1 * k * math.cos(th), oy + 0.1 * k * math.sin(th), th))
            t += 0.1
    return poses


def moved(poses, a, tx, ty):
    c, s = math.cos(a), math.sin(a)
    return [(t, c * x - s * y + tx, s * x + c * y + ty, th + a) for t, x, y, th in poses]


class EvaluateTrajectoryTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp()
        self.ref = square_loop()
        self.ref_path = os.path.join(self.dir, 'ref.tum')
        write(self.ref_path, self.ref)

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def evaluate(self, poses, *extra, **kw):
        path = os.path.join(self.dir, 'est.tum')
        write(path, poses)
        code, out, err = run('--estimate', path, '--reference', kw.get('ref', self.ref_path), *extra)
        self.assertEqual(code, 0, err)
        r = json.loads(out)
        self.assertTrue(REQUIRED_KEYS <= set(r), r)
        return r

    def test_identical_trajectories(self):
        r = self.evaluate(self.ref)
        self.assertEqual(r['poses'], 100)
        for k in ('ate_rmse_m', 'ate_max_m', 'rpe_trans_per_m', 'rpe_rot_deg_per_m', 'drift_percent'):
            self.assertAlmostEqual(r[k], 0.0, places=7, msg=k)
        self.assertAlmostEqual(r['distance_m'], 9.9, places=6)

    def test_rigidly_moved_copy(self):
        a, tx, ty = 0.7, 3.0, -1.0
        est = moved(self.ref, a, tx, ty)
        r = self.evaluate(est)  # se2 is the default
        self.assertEqual(r['poses'], 100)
        self.assertLess(r['ate_rmse_m'], 1e-6)
        self.assertLess(r['ate_max_m'], 1e-6)
        self.assertLess(r['ate_rot_rmse_deg'], 1e-5)
        self.assertLess(r['rpe_trans_per_m'], 1e-6)
        self.assertLess(r['rpe_rot_deg_per_m'], 1e-5)
        self.assertLess(r['drift_percent'], 1e-5)
        self.assertAlmostEqual(r['alignment']['theta_deg'], -math.degrees(a), places=5)
        # Without alignment: the known distances of the moved copy.
        r = self.evaluate(est, '--align', 'none')
        d = np.array([math.hypot(e[1] - g[1], e[2] - g[2]) for e, g in zip(est, self.ref)])
        self.assertAlmostEqual(r['ate_rmse_m'], float(np.sqrt(np.mean(d ** 2))), places=6)
        self.assertAlmostEqual(r['ate_max_m'], float(d.max()), places=6)
        self.assertLess(r['rpe_trans_per_m'], 1e-6)  # relative errors do not depend on the alignment
        self.assertLess(r['drift_percent'], 1e-5)

    def test_translated_copy_without_alignment(self):
        r = self.evaluate(moved(self.ref, 0.0, 0.3, 0.4), '--align', 'none')
        self.assertAlmostEqual(r['ate_rmse_m'], 0.5, places=6)
        self.assertAlmostEqual(r['ate_max_m'], 0.5, places=6)

    def test_constant_noise_magnitude_gives_its_rmse(self):
        # Every pose displaced by exactly 5 cm in a random direction: ATE RMSE and max are 5 cm unaligned;
        # the best alignment can only lower the RMSE a little (the offsets average almost to zero).
        rng = np.random.RandomState(3)
        phi = rng.uniform(-math.pi, math.pi, len(self.ref))
        est = [(t, x + 0.05 * math.cos(p), y + 0.05 * math.sin(p), th) for (t, x, y, th), p in zip(self.ref, phi)]
        r = self.evaluate(est, '--align', 'none')
        self.assertAlmostEqual(r['ate_rmse_m'], 0.05, places=7)
        self.assertAlmostEqual(r['ate_max_m'], 0.05, places=7)
        r = self.evaluate(est)
        self.assertLessEqual(r['ate_rmse_m'], 0.05 + 1e-9)
        self.assertGreater(r['ate_rmse_m'], 0.045)

    def test_alternating_offset_survives_alignment(self):
        # +-5 cm across the path, alternating, symmetric about the path: the best alignment is the identity.
        est = [(t, x - (0.05 if i % 2 else -0.05) * math.sin(th), y + (0.05 if i % 2 else -0.05) * math.cos(th), th)
               for i, (t, x, y, th) in enumerate(self.ref)]
        for align in ('none', 'se2'):
            r = self.evaluate(est, '--align', align)
            self.assertAlmostEqual(r['ate_rmse_m'], 0.05, places=3, msg=align)

    def test_scaled_straight_line(self):
        # Odometry over-estimating every step by 2 % on a 10 m straight line: drift 2 %, RPE 0.02 m per m.
        ref = [(0.1 * k, 0.1 * k, 0.0, 0.0) for k in range(101)]
        ref_path = os.path.join(self.dir, 'line.tum')
        write(ref_path, ref)
        r = self.evaluate([(t, 1.02 * x, y, th) for t, x, y, th in ref], ref=ref_path)
        self.assertAlmostEqual(r['drift_percent'], 2.0, places=6)
        self.assertAlmostEqual(r['final_error_m'], 0.2, places=6)
        self.assertAlmostEqual(r['distance_m'], 10.0, places=6)
        self.assertAlmostEqual(r['rpe_trans_per_m'], 0.02, places=6)
        self.assertAlmostEqual(r['rpe_rot_deg_per_m'], 0.0, places=7)
        # Aligned, the best fit of a 2 %-stretched line leaves an RMSE of 0.02 * std of the positions.
        xs = np.array([x for _, x, _, _ in ref])
        self.assertAlmostEqual(r['ate_rmse_m'], 0.02 * float(np.std(xs)), places=6)

    def test_scaled_loop_drift(self):
        est = [(t, 1.02 * x, 1.02 * y, th) for t, x, y, th in self.ref]
        r = self.evaluate(est)
        last = self.ref[-1]
        self.assertAlmostEqual(r['distance_m'], 9.9, places=6)
        self.assertAlmostEqual(r['drift_percent'], 100.0 * 0.02 * math.hypot(last[1], last[2]) / 9.9, places=5)

    def test_drift_is_measured_from_the_first_pose(self):
        # The estimate starts at (5, 5) facing +y instead of (0, 0) facing +x, otherwise exact: no drift.
        r = self.evaluate(moved(self.ref, math.pi / 2, 5.0, 5.0), '--align', 'none')
        self.assertGreater(r['ate_rmse_m'], 1.0)
        self.assertLess(r['drift_percent'], 1e-5)

    def test_heading_drift_per_metre(self):
        # Straight 10 m line, estimate heading drifting 2 deg per metre (positions exact).
        ref = [(0.1 * k, 0.1 * k, 0.0, 0.0) for k in range(101)]
        ref_path = os.path.join(self.dir, 'line.tum')
        write(ref_path, ref)
        r = self.evaluate([(t, x, y, math.radians(2.0) * x) for t, x, y, _ in ref], ref=ref_path)
        self.assertAlmostEqual(r['rpe_rot_deg_per_m'], 2.0, places=5)
        self.assertLess(r['ate_rmse_m'], 1e-6)

    def test_worst_segment_splits_a_stall_along_the_motion(self):
        # A straight 10 m run heading 0.3 rad; between 4 and 5 m the estimate advances half as far and moves
        # 0.2 m to the left (a corridor stall with a side step), then follows exactly, lagging from there on.
        a = 0.3
        ref = [(0.1 * k, 0.1 * k * math.cos(a), 0.1 * k * math.sin(a), a) for k in range(101)]
        ref_path = os.path.join(self.dir, 'line.tum')
        write(ref_path, ref)
        est, s, left = [], 0.0, 0.0
        for k in range(101):
            if k > 0:
                s += 0.05 if 40 < k <= 50 else 0.1
                left += 0.02 if 40 < k <= 50 else 0.0
            est.append((0.1 * k, s * math.cos(a) - left * math.sin(a), s * math.sin(a) + left * math.cos(a), a))
        w = self.evaluate(est, ref=ref_path)['rpe_worst']
        self.assertAlmostEqual(w['t_s'], 4.0, places=6)
        self.assertAlmostEqual(w['x'], 4.0 * math.cos(a), places=6)
        self.assertAlmostEqual(w['y'], 4.0 * math.sin(a), places=6)
        self.assertAlmostEqual(w['length_m'], 1.0, places=6)
        self.assertAlmostEqual(w['along_m'], -0.5, places=6)
        self.assertAlmostEqual(w['across_m'], 0.2, places=6)
        self.assertAlmostEqual(w['rot_deg'], 0.0, places=6)
        # No pair is worse when the run is exact, and a path shorter than --rpe-distance has none.
        self.assertAlmostEqual(self.evaluate(ref, ref=ref_path)['rpe_worst']['along_m'], 0.0, places=9)
        self.assertIsNone(self.evaluate(est, '--rpe-distance', '20', ref=ref_path)['rpe_worst'])

    def test_association_interpolates_and_drops(self):
        # Estimate at stamps between the reference's, some before and after its span.
        est = [(t + 0.05, x + 0.05 * math.cos(th), y + 0.05 * math.sin(th), th) for t, x, y, th in self.ref[:24]]
        est = [(-1.0, 0.0, 0.0, 0.0)] + est + [(100.0, 0.0, 0.0, 0.0)]
        path = os.path.join(self.dir, 'est.tum')
        write(path, est)
        code, out, err = run('--estimate', path, '--reference', self.ref_path)
        self.assertEqual(code, 0, err)
        r = json.loads(out)
        self.assertEqual(r['poses'], 24)
        self.assertEqual(r['dropped'], 2)
        self.assertIn('dropped', err)
        self.assertLess(r['ate_rmse_m'], 1e-6)

    def test_plot_files(self):
        plot = os.path.join(self.dir, 'plots', 'sub')
        rng = np.random.RandomState(1)
        est = [(t, x + rng.normal(0, 0.02), y + rng.normal(0, 0.02), th + rng.normal(0, 0.01))
               for t, x, y, th in self.ref]
        self.evaluate(est, '--plot', plot)
        for name in ('trajectories.png', 'error_over_time.png', 'error_histograms.png',
                     'step_error_histograms.png'):
            path = os.path.join(plot, name)
            self.assertTrue(os.path.exists(path), name)
            with open(path, 'rb') as f:
                self.assertEqual(f.read(8), b'\x89PNG\r\n\x1a\n')
            self.assertGreater(os.path.getsize(path), 1000)

    def check_malformed(self, text, where, what, as_reference=False):
        bad = os.path.join(self.dir, 'bad.tum')
        with open(bad, 'w') as f:
            f.write(text)
        if as_reference:
            code, out, err = run('--estimate', self.ref_path, '--reference', bad)
        else:
            code, out, err = run('--estimate', bad, '--reference', self.ref_path)
        self.assertEqual(code, 1, err)
        self.assertEqual(out, '')
        self.assertIn(where, err)
        self.assertIn(what, err)
        self.assertNotIn('Traceback', err)

    def test_malformed_input(self):
        good = '0 0 0 0 0 0 0 1\n'
        self.check_malformed(good + '0.1 0 0 0 0 0\n', 'bad.tum:2', '8 numbers')
        self.check_malformed('# header\n\n' + good + '0.1 0 x 0 0 0 0 1\n', 'bad.tum:4', 'not a number')
        self.check_malformed(good + '0.1 0 nan 0 0 0 0 1\n', 'bad.tum:2', 'not finite')
        self.check_malformed(good + '0.1 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 0 1\n', 'bad.tum:3', 'not after')
        self.check_malformed(good + '0.1 0 0 0 0 0 0 0\n', 'bad.tum:2', 'zero quaternion')
        self.check_malformed(good + '0.1 0 0 0 0 0 0 1 7\n', 'bad.tum:2', 'got 9', as_reference=True)
        self.check_malformed('# nothing\n', 'bad.tum', 'no poses')
        self.check_malformed('100 0 0 0 0 0 0 1\n101 0 0 0 0 0 0 1\n', 'bad.tum', 'time span')

    def test_missing_file(self):
        code, out, err = run('--estimate', os.path.join(self.dir, 'nope.tum'), '--reference', self.ref_path)
        self.assertEqual(code, 1)
        self.assertIn('nope.tum', err)
        self.assertNotIn('Traceback', err)


if __name__ == '__main__':
    unittest.main()
