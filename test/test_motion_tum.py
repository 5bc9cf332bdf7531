"""dpslam_offline --motion-tum: the SLAM moved by a given trajectory (wheel odometry, or the simulator's
ground truth to measure the SLAM alone), and a clear error for a file it cannot use."""
import json
import os
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # nosetests under catkin does not add it
from test_demo_run import PKG  # noqa: E402

BAG = os.path.join(PKG, "bags", "demo.bag")
TRUTH = os.path.join(PKG, "bags", "demo_ground_truth.tum")


def offline(*extra):
    out = tempfile.mkdtemp()
    run = subprocess.run(["rosrun", "laser_dpslam", "dpslam_offline", "--bag", BAG, "--out", out, "--quiet"] + list(extra),
                         capture_output=True, text=True)
    return run, out


def ate(estimate):
    ev = subprocess.run(["rosrun", "laser_dpslam", "evaluate_trajectory", "--estimate", estimate, "--reference", TRUTH],
                        capture_output=True, text=True, check=True)
    return json.loads(ev.stdout)["ate_rmse_m"]


class MotionTumTest(unittest.TestCase):
    def test_slam_moved_by_the_truth_maps_the_demo(self):
        run, out = offline("--motion-tum", TRUTH)
        self.assertEqual(run.returncode, 0, run.stderr)
        # 0.0276 m when measured (2026-11-30; 0.0294 m with the laser odometry's motion)
        self.assertLess(ate(os.path.join(out, "trajectory.tum")), 0.04)

    def test_slam_moved_by_a_wrong_trajectory_goes_wrong(self):
        # The motion really comes from the file: the truth with every x doubled misleads the filter.
        with open(TRUTH) as f:
            src = f.read().splitlines()
        fd, bad = tempfile.mkstemp(suffix=".tum")
        with os.fdopen(fd, "w") as f:
            for line in src:
                v = line.split()
                if len(v) == 8 and not line.startswith("#"):
                    v[1] = repr(2.0 * float(v[1]))
                    line = " ".join(v)
                f.write(line + "\n")
        run, out = offline("--motion-tum", bad)
        self.assertEqual(run.returncode, 0, run.stderr)
        self.assertGreater(ate(os.path.join(out, "trajectory.tum")), 0.1)

    def test_scans_outside_the_file_are_not_given_to_the_slam(self):
        with open(TRUTH) as f:
            lines = [l for l in f.read().splitlines() if l and not l.startswith("#")]
        fd, half = tempfile.mkstemp(suffix=".tum")
        with os.fdopen(fd, "w") as f:
            f.write("\n".join(lines[: len(lines) // 2]) + "\n")
        run, out = offline("--motion-tum", half)
        self.assertEqual(run.returncode, 0, run.stderr)
        with open(os.path.join(out, "stats.json")) as f:
            stats = json.load(f)
        self.assertIn("slam_outside_motion_tum", json.dumps(stats))
        with open(os.path.join(out, "trajectory.tum")) as f:
            slam_poses = [l for l in f if l.strip() and not l.startswith("#")]
        self.assertLessEqual(len(slam_poses), len(lines) // 2 + 1)

    def test_unusable_files_are_refused_with_the_reason(self):
        fd, bad = tempfile.mkstemp(suffix=".tum")
        with os.fdopen(fd, "w") as f:
            f.write("1.0 0 0 0 0 0 0 1\n0.5 0 0 0 0 0 0 1\n")
        run, _ = offline("--motion-tum", bad)
        self.assertEqual(run.returncode, 2)
        self.assertIn("stamps must increase", run.stderr)
        run, _ = offline("--motion-tum", "/nonexistent/motion.tum")
        self.assertEqual(run.returncode, 2)
        self.assertIn("--motion-tum", run.stderr)
        run, _ = offline("--motion-tum", TRUTH, "--odometry-only")
        self.assertEqual(run.returncode, 2)


if __name__ == "__main__":
    unittest.main()
