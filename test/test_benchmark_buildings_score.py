"""scripts/benchmark_buildings_score.py summary: the median, 90th percentile and worst of the benchmark's
rows, a failed run counted as the worst, and the verdict against each mode's targets."""
import os
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # nosetests under catkin does not add it
from test_demo_run import PKG  # noqa: E402

SCORE = os.path.join(PKG, "scripts", "benchmark_buildings_score.py")


def summary(mode, slam, rows):
    run = subprocess.run(["/usr/bin/python3", SCORE, "summary", mode, slam], input=rows, capture_output=True,
                         text=True)
    assert run.returncode == 0, run.stderr
    return run.stdout.splitlines()


class ScoreTest(unittest.TestCase):
    def test_statistics_and_targets(self):
        # drift 0.1 .. 1.0 % and 9.0 %: median 0.6, p90 1.0, worst 9.0; SLAM ATE 0.01 .. 0.10 m and 0.5 m.
        rows = "".join("seed%d ring laser 100.0 0.1 %.2f %.3f\n" % (k, 0.1 * k, 0.01 * k) for k in range(1, 11))
        rows += "seed11 hall laser 100.0 0.1 9.00 0.500\n"
        rows = rows.replace("seed1 ring", "seed1 hall")  # the hall's drifts are 0.1 and 9.0
        drift, ate, families = summary("laser", "1", rows)
        self.assertIn("hall 4.55 / 0.255, ring 0.60 / 0.060", families)
        self.assertIn("median   0.600  p90   1.000  worst   9.000  over 11 runs", drift)
        self.assertIn("targets: median <= 1, p90 <= 2", drift)
        self.assertIn("median   0.060", ate)
        self.assertIn("median > 0.05, worst <= 0.5", ate)
        wheel_ate = summary("wheels", "1", rows)[1]
        self.assertIn("median > 0.03, worst > 0.2", wheel_ate)

    def test_a_failed_run_is_the_worst(self):
        rows = "a ring laser 100.0 0.1 0.50 0.020\nb ring laser FAIL - - - (see x)\n"
        drift, ate = summary("laser", "1", rows)
        self.assertIn("worst     inf", drift)
        self.assertIn("(1 failed)", drift)
        self.assertIn("worst > 0.5", ate)

    def test_odometry_only_has_no_slam_line(self):
        self.assertEqual(len(summary("laser", "0", "a ring laser 100.0 0.1 0.50 -\n")), 1)


if __name__ == "__main__":
    unittest.main()
