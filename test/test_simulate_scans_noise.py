"""simulate_scans --range-noise / --range-noise-fraction: the range noise of the simulated URG-04LX can be
set (sigma = max(M, F * range)), so that a user can match their sensor and so that the effect of range noise
on the SLAM can be measured (doc/benchmarks.md). Compared beam by beam with a --no-noise run of the same
path and seed."""
import math
import os
import subprocess
import sys
import tempfile
import unittest

import rosbag

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # nosetests under catkin does not add it
from test_demo_run import PKG  # noqa: E402


def simulate(*extra):
    out = tempfile.mkdtemp()
    run = subprocess.run(["rosrun", "laser_dpslam", "simulate_scans", "--floorplan",
                          os.path.join(PKG, "plans", "office.yaml"), "--path", "loop", "--duration", "2",
                          "--seed", "3", "--out", out] + list(extra), capture_output=True, text=True)
    return run, out


def ranges(out):
    with rosbag.Bag(os.path.join(out, "sim.bag")) as bag:
        return [list(m.ranges) for _, m, _ in bag.read_messages(topics=["/scan"])]


def differences(a, b):
    """Range differences of the beams finite in both runs."""
    d = []
    for sa, sb in zip(a, b):
        d += [x - y for x, y in zip(sa, sb) if math.isfinite(x) and math.isfinite(y)]
    return d


class SimulateScansNoiseTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        run, out = simulate("--no-noise")
        assert run.returncode == 0, run.stderr
        cls.exact = ranges(out)

    def test_zero_noise_gives_the_exact_ranges(self):
        run, out = simulate("--range-noise", "0", "--range-noise-fraction", "0", "--dropout", "0")
        self.assertEqual(run.returncode, 0, run.stderr)
        noisy = ranges(out)
        self.assertEqual(len(noisy), len(self.exact))
        self.assertGreater(len(noisy), 10)
        # Grazing-incidence dropouts (NaN) stay on; every beam both runs return is the same.
        d = differences(noisy, self.exact)
        self.assertGreater(len(d), 5000)
        self.assertEqual(max(abs(x) for x in d), 0.0)

    def test_constant_noise_has_the_requested_standard_deviation(self):
        run, out = simulate("--range-noise", "0.05", "--range-noise-fraction", "0", "--dropout", "0")
        self.assertEqual(run.returncode, 0, run.stderr)
        d = differences(ranges(out), self.exact)
        self.assertGreater(len(d), 5000)
        mean = sum(d) / len(d)
        std = math.sqrt(sum((x - mean) ** 2 for x in d) / len(d))
        self.assertLess(abs(mean), 0.005)
        self.assertGreater(std, 0.045)
        self.assertLess(std, 0.055)

    def test_proportional_noise_grows_with_range(self):
        run, out = simulate("--range-noise", "0", "--range-noise-fraction", "0.02", "--dropout", "0")
        self.assertEqual(run.returncode, 0, run.stderr)
        near, far = [], []
        for sa, sb in zip(ranges(out), self.exact):
            for x, y in zip(sa, sb):
                if math.isfinite(x) and math.isfinite(y):
                    (near if y < 1.5 else far if y > 3.0 else []).append((x - y) / (0.02 * y))
        self.assertGreater(len(near), 500)
        self.assertGreater(len(far), 500)
        for z in (near, far):  # normalised by 2 % of the range: unit variance at every range
            self.assertAlmostEqual(math.sqrt(sum(v * v for v in z) / len(z)), 1.0, delta=0.1)

    def test_negative_noise_is_refused(self):
        for flag in ("--range-noise", "--range-noise-fraction"):
            run, _ = simulate(flag, "-0.01")
            self.assertNotEqual(run.returncode, 0)
            self.assertIn(flag + " must be >= 0", run.stderr)


if __name__ == "__main__":
    unittest.main()
