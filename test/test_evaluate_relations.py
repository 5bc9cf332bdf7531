"""evaluate_relations on synthetic trajectories with known errors."""
import json
import math
import os
import subprocess
import tempfile
import unittest

TOOL = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools", "evaluate_relations")


def write_tum(path, poses):
    with open(path, "w") as f:
        for t, x, y, th in poses:
            f.write("%.6f %.6f %.6f 0 0 0 %.9f %.9f\n" % (t, x, y, math.sin(th / 2), math.cos(th / 2)))


def run(*args):
    p = subprocess.run(["/usr/bin/python3", TOOL] + list(args), capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


class EvaluateRelationsTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp()
        # Straight line at 1 m/s along x with a slow turn.
        self.poses = [(t * 0.5, t * 0.5, 0.1 * t, 0.02 * t) for t in range(40)]
        self.tum = os.path.join(self.dir, "t.tum")
        write_tum(self.tum, self.poses)

    def relations(self, bias_x=0.0, bias_yaw=0.0):
        path = os.path.join(self.dir, "r.txt")
        with open(path, "w") as f:
            for i in range(0, 38, 2):
                a, b = self.poses[i], self.poses[i + 1 + (i % 4 == 0) * 1]
                c, s = math.cos(a[3]), math.sin(a[3])
                dx, dy = c * (b[1] - a[1]) + s * (b[2] - a[2]), -s * (b[1] - a[1]) + c * (b[2] - a[2])
                f.write("%.6f %.6f %.9f %.9f 0 0 0 %.9f\n" % (a[0], b[0], dx + bias_x, dy, b[3] - a[3] + bias_yaw))
        return path

    def test_exact_relations_give_zero_error(self):
        code, out, _ = run("--trajectory", self.tum, "--relations", self.relations())
        self.assertEqual(code, 0)
        r = json.loads(out)
        self.assertEqual(r["relations"], 19)
        self.assertEqual(r["used"], 19)
        self.assertLess(r["trans_abs_mean"], 1e-6)
        self.assertLess(r["rot_abs_mean_deg"], 1e-5)

    def test_known_bias_is_reported(self):
        code, out, _ = run("--trajectory", self.tum, "--relations", self.relations(bias_x=0.05, bias_yaw=math.radians(1.0)))
        self.assertEqual(code, 0)
        r = json.loads(out)
        # error = est * gt^-1: a pure x bias of the relation of 0.05 m with a 1 deg rotation bias.
        self.assertAlmostEqual(r["rot_abs_mean_deg"], 1.0, places=4)
        self.assertAlmostEqual(r["trans_abs_mean"], 0.05, places=3)
        self.assertAlmostEqual(r["trans_sqr_mean"], r["trans_abs_mean"] ** 2, places=4)

    def test_max_dt_filters_relations(self):
        code, out, _ = run("--trajectory", self.tum, "--relations", self.relations(), "--max-dt", "0.6")
        r = json.loads(out)
        self.assertEqual(r["relations"], 19)
        self.assertEqual(r["used"], 9)  # the relations spanning one step (0.5 s), not two (1.0 s)

    def test_malformed_file_names_the_line(self):
        bad = os.path.join(self.dir, "bad.txt")
        with open(bad, "w") as f:
            f.write("1 2 0 0 0 0 0 0\n1 2 x 0 0 0 0 0\n")
        code, out, err = run("--trajectory", self.tum, "--relations", bad)
        self.assertNotEqual(code, 0)
        self.assertIn("bad.txt:2", err)
        self.assertEqual(out, "")


if __name__ == "__main__":
    unittest.main()
