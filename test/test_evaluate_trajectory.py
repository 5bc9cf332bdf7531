"""evaluate_trajectory on trajectories with known errors."""
import json
import math
import os
import subprocess
import tempfile
import unittest

TOOL = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools", "evaluate_trajectory")


def write(path, poses):
    with open(path, "w") as f:
        for t, x, y, th in poses:
            f.write("%.6f %.9f %.9f 0 0 0 %.12f %.12f\n" % (t, x, y, math.sin(th / 2), math.cos(th / 2)))


def run(*args):
    p = subprocess.run(["/usr/bin/python3", TOOL] + list(args), capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


class EvaluateTrajectoryTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp()
        # A 10 m square loop at 0.1 m steps.
        self.ref = []
        t = 0.0
        for side in range(4):
            for k in range(25):
                th = side * math.pi / 2
                ox, oy = [(0, 0), (2.5, 0), (2.5, 2.5), (0, 2.5)][side]
                self.ref.append((t, ox + 0.1 * k * math.cos(th), oy + 0.1 * k * math.sin(th), th))
                t += 0.1
        self.ref_path = os.path.join(self.dir, "ref.tum")
        write(self.ref_path, self.ref)

    def evaluate(self, poses, *extra):
        path = os.path.join(self.dir, "est.tum")
        write(path, poses)
        code, out, err = run("--estimate", path, "--reference", self.ref_path, *extra)
        self.assertEqual(code, 0, err)
        return json.loads(out)

    def test_rigidly_moved_copy(self):
        a, tx, ty = 0.7, 3.0, -1.0
        moved = [(t, math.cos(a) * x - math.sin(a) * y + tx, math.sin(a) * x + math.cos(a) * y + ty, th + a)
                 for t, x, y, th in self.ref]
        r = self.evaluate(moved)
        self.assertEqual(r["poses"], 100)
        self.assertLess(r["ate_rmse_m"], 1e-6)
        self.assertLess(r["rpe_trans_per_m"], 1e-6)
        self.assertLess(r["drift_percent"], 1e-6)
        r = self.evaluate([(t, x + 0.3, y, th) for t, x, y, th in self.ref], "--align", "none")
        self.assertAlmostEqual(r["ate_rmse_m"], 0.3, places=6)
        self.assertAlmostEqual(r["ate_max_m"], 0.3, places=6)

    def test_alternating_offset_gives_its_rmse(self):
        # +-5 cm across the path, alternating: the best alignment cannot remove it.
        est = [(t, x + (0.05 if i % 2 else -0.05) * -math.sin(th), y + (0.05 if i % 2 else -0.05) * math.cos(th), th)
               for i, (t, x, y, th) in enumerate(self.ref)]
        r = self.evaluate(est, "--align", "none")
        self.assertAlmostEqual(r["ate_rmse_m"], 0.05, places=6)

    def test_scaled_trajectory_drift(self):
        # Odometry that over-estimates every step by 2 %: the final error is 2 % of the final displacement.
        est = [(t, 1.02 * x, 1.02 * y, th) for t, x, y, th in self.ref]
        r = self.evaluate(est)
        last = self.ref[-1]
        expected = 100.0 * 0.02 * math.hypot(last[1], last[2]) / r["distance_m"]
        self.assertAlmostEqual(r["drift_percent"], expected, places=4)
        self.assertAlmostEqual(r["distance_m"], 9.9, places=6)

    def test_plot_files(self):
        plot = os.path.join(self.dir, "plots")
        self.evaluate(self.ref, "--plot", plot)
        for name in ("trajectories.png", "error_over_time.png", "error_histograms.png"):
            self.assertGreater(os.path.getsize(os.path.join(plot, name)), 1000)

    def test_malformed_input(self):
        bad = os.path.join(self.dir, "bad.tum")
        with open(bad, "w") as f:
            f.write("0 0 0 0 0 0 0 1\n0.1 0 0 0 0 0\n")
        code, out, err = run("--estimate", bad, "--reference", self.ref_path)
        self.assertNotEqual(code, 0)
        self.assertIn("bad.tum:2", err)
        self.assertEqual(out, "")


if __name__ == "__main__":
    unittest.main()
