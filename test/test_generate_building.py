"""scripts/generate_building.py and simulate_scans on its plans: the same seed gives the same building;
the plan is a geometry plan simulate_scans reads; the laser path keeps its stops where something is in
view (within the laser's 240 degrees) while the wheel path also stops in blank stretches; --wheel-odometry
adds /wheel_odom without changing the scans."""
import filecmp
import importlib.util
import json
import math
import os
import subprocess
import sys
import tempfile
import unittest

import rosbag

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # nosetests under catkin does not add it
from test_demo_run import PKG  # noqa: E402

GENERATOR = os.path.join(PKG, "scripts", "generate_building.py")


def generate(seed, out, family=None):
    cmd = ["/usr/bin/python3", GENERATOR, "--seed", str(seed), "--out", out] + (["--family", family] if family else [])
    run = subprocess.run(cmd, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout)


def waypoints(path):
    return [l.split() for l in open(path) if l.strip() and not l.startswith("#")]


def turn_depth(path):
    """How far an out-and-back leg (the dead end) goes before it turns round (m), or None."""
    p = [tuple(map(float, w[:2])) for w in waypoints(path)]
    return next((math.dist(p[k - 1], p[k]) for k in range(1, len(p) - 1) if math.dist(p[k - 1], p[k + 1]) < 1e-5),
                None)


class GenerateBuildingTest(unittest.TestCase):
    def test_same_seed_same_building(self):
        a, b, c = (tempfile.mkdtemp() for _ in range(3))
        generate(5, a)
        generate(5, b)
        generate(6, c)
        for f in ("plan.txt", "plan.pgm", "plan.yaml", "path_laser.txt", "path_wheels.txt", "meta.json"):
            self.assertTrue(filecmp.cmp(os.path.join(a, f), os.path.join(b, f), shallow=False), f)
        self.assertFalse(filecmp.cmp(os.path.join(a, "plan.txt"), os.path.join(c, "plan.txt"), shallow=False))

    def test_blank_family_has_long_blank_stretches_and_wheel_stops_there(self):
        for seed in (4, 9, 14):
            out = tempfile.mkdtemp()
            meta = generate(seed, out, "blank")
            self.assertGreater(meta["longest_blank_m"], 0.5, meta)
            self.assertTrue(2 * 5.6 <= meta["blank_side_m"] <= 8 * 5.6, meta)
            self.assertGreaterEqual(meta["wheel_stops_in_corridors"], 1, meta)
            self.assertGreaterEqual(meta["route_m"], 80.0)
            laser, wheels = waypoints(os.path.join(out, "path_laser.txt")), waypoints(os.path.join(out, "path_wheels.txt"))
            self.assertGreater(len(wheels), len(laser))
            # The building is turned off the axes: not every wall is horizontal or vertical.
            walls = [list(map(float, l.split()[1:])) for l in open(os.path.join(out, "plan.txt")) if l.startswith("wall")]
            self.assertTrue(any(min(abs(w[2] - w[0]), abs(w[3] - w[1])) > 0.01 for w in walls))

    def test_in_view_only_within_the_field_of_view(self):
        spec = importlib.util.spec_from_file_location("generate_building", GENERATOR)
        gen = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(gen)
        # A dead end along +x, 2 m wide, its end wall at x = 0; the robot at x = 1.5 on the centre line.
        seg_a = gen.np.array([(0.0, -1.0), (0.0, -1.0), (0.0, 1.0)])
        seg_b = gen.np.array([(0.0, 1.0), (20.0, -1.0), (20.0, 1.0)])
        corners = gen.np.array([(0.0, -1.0), (0.0, 1.0)])
        p = gen.np.array([1.5, 0.0])
        self.assertTrue(gen.in_view(p, corners, seg_a, seg_b, 5.6))                  # any direction
        self.assertTrue(gen.in_view(p, corners, seg_a, seg_b, 5.6, math.pi))         # facing the end wall
        self.assertFalse(gen.in_view(p, corners, seg_a, seg_b, 5.6, 0.0))            # driving off: behind
        # The corner (0, 1) lies 146.3 deg off the x axis: 116.3 deg off a heading of 30 deg, 126.3 off 20.
        self.assertTrue(gen.in_view(p, corners, seg_a, seg_b, 5.6, math.radians(30)))
        self.assertFalse(gen.in_view(p, corners, seg_a, seg_b, 5.6, math.radians(20)))
        self.assertFalse(gen.in_view(p, corners, seg_a, seg_b, 1.0, math.pi))        # out of range

    def test_a_stop_needs_a_surface_facing_along_the_travel(self):
        spec = importlib.util.spec_from_file_location("generate_building", GENERATOR)
        gen = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(gen)
        np = gen.np
        # A corridor along +x, 2 m wide, closed at x = 0, open at x = 5 into a cross corridor whose far wall
        # runs along x = 7.5 (y from -4 to 4).
        walls = [((0.0, -1.0), (0.0, 1.0)), ((0.0, -1.0), (5.0, -1.0)), ((0.0, 1.0), (5.0, 1.0)),
                 ((7.5, -4.0), (7.5, 4.0))]
        seg_a, seg_b = np.array([w[0] for w in walls]), np.array([w[1] for w in walls])
        corners = np.array([(0.0, -1.0), (0.0, 1.0), (5.0, -1.0), (5.0, 1.0)])
        p = np.array([0.8, 0.0])
        # Driving off towards the opening: its corners are in range and in view, but edge-on; the far
        # wall is 6.7 m away. Nothing tells the start.
        self.assertTrue(gen.in_view(p, corners, seg_a, seg_b, 5.6, 0.0))
        self.assertFalse(gen.facing_in_view(p, 0.0, [], seg_a, seg_b, 5.6))
        self.assertTrue(gen.facing_in_view(p, math.pi, [], seg_a, seg_b, 5.6))         # the end wall ahead
        self.assertTrue(gen.facing_in_view(np.array([2.5, 0.0]), 0.0, [], seg_a, seg_b, 5.6))  # far wall at 5 m
        # The end wall is behind the laser's 240 degrees; a pillar in view counts.
        self.assertFalse(gen.facing_in_view(np.array([2.5, 0.0]), 0.0, [], seg_a[:3], seg_b[:3], 5.6))
        self.assertTrue(gen.facing_in_view(p, 0.0, [(3.0, 0.5, 0.1)], seg_a, seg_b, 5.6))
        # A wall behind another is not seen: a room's wall square to the corridor, behind its side wall.
        room = (np.array([(3.5, 1.0)]), np.array([(3.5, 3.0)]))
        q = np.array([2.5, 0.0])
        self.assertFalse(gen.facing_in_view(q, 0.0, [], np.vstack([seg_a[1:3], room[0]]), np.vstack([seg_b[1:3], room[1]]), 5.6))
        self.assertTrue(gen.facing_in_view(q, 0.0, [], np.vstack([seg_a[1:2], room[0]]), np.vstack([seg_b[1:2], room[1]]), 5.6))

    def test_laser_path_turns_round_in_a_dead_end_where_the_way_out_is_in_view(self):
        for seed, short in ((3, True), (8, True), (18, False)):  # dead ends of 13.0, 11.4 and 6.7 m
            out = tempfile.mkdtemp()
            meta = generate(seed, out, "deadend")
            laser, wheels = turn_depth(os.path.join(out, "path_laser.txt")), turn_depth(os.path.join(out, "path_wheels.txt"))
            self.assertIsNotNone(laser, meta)
            if short:  # the end wall is behind the robot as it starts back: the laser path turns before the end
                self.assertLess(laser, wheels - 1.0, meta)
                self.assertLess(laser, 5.6 + 1.0, meta)
            else:  # the way out is in view from near the end: a quarter metre short of where the wheels turn
                self.assertLessEqual(laser, wheels + 1e-4, meta)
                self.assertGreater(laser, wheels - 0.5, meta)

    def test_simulated_with_wheel_odometry(self):
        out = tempfile.mkdtemp()
        generate(2, out)  # a hall: pillars and furniture
        bags = {}
        for name, extra in (("plain", []), ("wheels", ["--wheel-odometry"])):
            run = subprocess.run(["rosrun", "laser_dpslam", "simulate_scans", "--floorplan", os.path.join(out, "plan.txt"),
                                  "--path", os.path.join(out, "path_wheels.txt"), "--duration", "30", "--seed", "2",
                                  "--out", os.path.join(out, name)] + extra, capture_output=True, text=True)
            self.assertEqual(run.returncode, 0, run.stderr)
            with rosbag.Bag(os.path.join(out, name, "sim.bag")) as bag:
                bags[name] = {t: [m for _, m, _ in bag.read_messages(topics=[t])] for t in ("/scan", "/wheel_odom")}
        self.assertEqual(len(bags["plain"]["/wheel_odom"]), 0)
        scans = {k: [repr(list(m.ranges)) for m in v["/scan"]] for k, v in bags.items()}  # repr: NaN == NaN
        self.assertEqual(scans["plain"], scans["wheels"])
        odom = bags["wheels"]["/wheel_odom"]
        self.assertGreater(len(odom), 500)  # 20 Hz over 30 s
        self.assertEqual((odom[0].header.frame_id, odom[0].child_frame_id), ("odom", "base_link"))
        self.assertEqual(odom[0].pose.pose.position.x, 0.0)
        self.assertGreater(max(m.twist.twist.linear.x for m in odom), 0.1)
        # Bad plan lines are reported with file and line.
        bad = os.path.join(out, "bad.txt")
        with open(bad, "w") as f:
            f.write("wall 0 0 5 0\nwall 0 1 five 1\n")
        run = subprocess.run(["rosrun", "laser_dpslam", "simulate_scans", "--floorplan", bad, "--path",
                              os.path.join(out, "path_laser.txt"), "--out", os.path.join(out, "bad")],
                             capture_output=True, text=True)
        self.assertEqual(run.returncode, 1)
        self.assertIn("bad.txt:2: 'five' is not a number", run.stderr)


if __name__ == "__main__":
    unittest.main()
