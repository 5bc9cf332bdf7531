#!/usr/bin/env python3
"""robot.launch with its real drivers (urg_node, create_driver) against emulated devices.

emulate_robot puts a Hokuyo URG-04LX (SCIP 2.0) and an iRobot Create (Open Interface) on pseudo-terminals;
robot.launch runs unchanged but for the two ports and rviz:=false, in a roslaunch of its own on this test's
master, with the drivers' workspace (scripts/build_drivers.sh) overlaid on the package's. The test drives
the robot with cmd_vel through the office plan (steering from the emulator's true pose) and checks what a
user relies on: /scan from urg_node reaching both nodes, TF map -> odom -> base_link -> laser, /map over
the driven area, the SLAM pose against the truth (ATE), save_map, and create_driver's wheel_odom staying
off TF. Without the driver sources the test writes a JUnit result marked skipped, with the reason."""
import math
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import unittest

from drivers_workspace import DriversUnavailable, drivers_devel

PKG = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
# Waypoints in the office plan (m): out of the west corridor's room N1 and east along the corridor.
WAYPOINTS = [(3.5, 6.0), (3.5, 8.6), (3.5, 6.0), (8.0, 6.0), (12.0, 6.0)]
START = (2.0, 6.0, 0.0)
ATE_LIMIT = 0.05  # m


def results_path():
    for a in sys.argv:
        if a.startswith("--gtest_output=xml:"):
            return a[len("--gtest_output=xml:"):]
    return None


def report_skipped(reason):
    """A JUnit result with the test marked skipped (rosunit has no notion of skipping)."""
    from xml.sax.saxutils import quoteattr
    print("robot_drivers_rostest: SKIPPED: " + reason, flush=True)
    path = results_path()
    if path:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w") as f:
            f.write('<?xml version="1.0" encoding="utf-8"?>\n'
                    '<testsuite name="robot_drivers" tests="1" errors="0" failures="0" skipped="1">\n'
                    '  <testcase classname="robot_drivers_rostest.RobotDrivers" name="test_robot_drivers">\n'
                    '    <skipped message=%s/>\n  </testcase>\n</testsuite>\n' % quoteattr(reason))
    sys.exit(0)


def overlay_env(drivers):
    """This environment with the drivers' workspace under the package's (ROS_MASTER_URI kept)."""
    devel = next(p for p in os.environ.get("CMAKE_PREFIX_PATH", "").split(":")
                 if os.path.isfile(os.path.join(p, "setup.bash")) and os.path.isdir(os.path.join(p, "lib", "laser_dpslam")))
    script = 'source "%s/setup.bash" && source "%s/setup.bash" --extend && env -0' % (drivers, devel)
    out = subprocess.run(["bash", "-c", script], stdout=subprocess.PIPE, check=True, env=os.environ).stdout
    env = dict(kv.split("=", 1) for kv in out.decode().split("\0") if "=" in kv)
    env["ROS_MASTER_URI"] = os.environ["ROS_MASTER_URI"]
    return env, devel


def yaw(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def read_truth(path):
    rows = []
    with open(path) as f:
        for line in f:
            v = line.split()
            if len(v) == 8:
                rows.append((float(v[0]), float(v[1]), float(v[2]), 2.0 * math.atan2(float(v[6]), float(v[7]))))
    return rows


def interpolate(truth, t):
    import bisect
    i = bisect.bisect_left([r[0] for r in truth], t)
    if i <= 0 or i >= len(truth):
        return None
    a, b = truth[i - 1], truth[i]
    f = (t - a[0]) / max(b[0] - a[0], 1e-9)
    return (a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2]))


def align(est, ref):
    """Rigid 2D alignment (rotation + translation, no scale) of est onto ref: (c, s, tx, ty), RMSE."""
    n = len(est)
    ex, ey = sum(p[0] for p in est) / n, sum(p[1] for p in est) / n
    rx, ry = sum(p[0] for p in ref) / n, sum(p[1] for p in ref) / n
    sxx = sum((e[0] - ex) * (r[0] - rx) + (e[1] - ey) * (r[1] - ry) for e, r in zip(est, ref))
    sxy = sum((e[0] - ex) * (r[1] - ry) - (e[1] - ey) * (r[0] - rx) for e, r in zip(est, ref))
    th = math.atan2(sxy, sxx)
    c, s = math.cos(th), math.sin(th)
    tx, ty = rx - (c * ex - s * ey), ry - (s * ex + c * ey)
    err = [math.hypot(c * e[0] - s * e[1] + tx - r[0], s * e[0] + c * e[1] + ty - r[1]) for e, r in zip(est, ref)]
    return (c, s, tx, ty), math.sqrt(sum(x * x for x in err) / n)


def wrap(a):
    return math.atan2(math.sin(a), math.cos(a))


class RobotDrivers(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        import rospy
        import tf2_ros
        from geometry_msgs.msg import PoseWithCovarianceStamped, Twist
        from nav_msgs.msg import OccupancyGrid, Odometry
        from sensor_msgs.msg import LaserScan
        from tf2_msgs.msg import TFMessage
        env, devel = overlay_env(DRIVERS)
        cls.tmp = tempfile.mkdtemp(prefix="laser_dpslam_robot_")
        cls.urg, cls.create = os.path.join(cls.tmp, "urg"), os.path.join(cls.tmp, "create")
        cls.truth_path = os.path.join(cls.tmp, "truth.tum")
        cls.emulator = subprocess.Popen(
            [os.path.join(devel, "lib", "laser_dpslam", "emulate_robot"), "--floorplan",
             os.path.join(PKG, "plans", "office.yaml"), "--laser-port", cls.urg, "--create-port", cls.create,
             "--truth", cls.truth_path, "--x", str(START[0]), "--y", str(START[1]), "--theta", str(START[2]),
             "--seed", "1"], stdout=open(os.path.join(cls.tmp, "emulator.log"), "w"), stderr=subprocess.STDOUT)
        deadline = time.time() + 20.0
        while not (os.path.exists(cls.urg) and os.path.exists(cls.create)) and time.time() < deadline:
            time.sleep(0.1)
        # The user's command line, with the emulator's ports.
        cls.launch = subprocess.Popen(
            ["roslaunch", "laser_dpslam", "robot.launch", "serial_port:=" + cls.urg, "create_port:=" + cls.create,
             "rviz:=false"], env=env, start_new_session=True,
            stdout=open(os.path.join(cls.tmp, "roslaunch.log"), "w"), stderr=subprocess.STDOUT)
        rospy.init_node("robot_drivers_rostest")
        cls.scans, cls.odoms, cls.wheel, cls.poses, cls.maps = [], [], [], [], []
        cls.tf_publishers = {}  # (parent, child) -> set of caller ids
        cls.buffer = tf2_ros.Buffer(rospy.Duration(600))
        cls.listener = tf2_ros.TransformListener(cls.buffer)
        rospy.Subscriber("scan", LaserScan, lambda m: cls.scans.append(m))
        rospy.Subscriber("odom", Odometry, lambda m: cls.odoms.append(m.header.stamp))
        rospy.Subscriber("wheel_odom", Odometry, lambda m: cls.wheel.append(m))
        rospy.Subscriber("pose", PoseWithCovarianceStamped, lambda m: cls.poses.append(m))
        rospy.Subscriber("map", OccupancyGrid, lambda m: cls.maps.append(m))
        rospy.Subscriber("tf", TFMessage, cls.on_tf)
        cls.cmd = rospy.Publisher("cmd_vel", Twist, queue_size=1)
        deadline = time.time() + 90.0
        while time.time() < deadline and not (len(cls.scans) > 20 and len(cls.wheel) > 5 and len(cls.poses) > 5):
            time.sleep(0.5)
        cls.truth_file = open(cls.truth_path)
        cls.pose = START
        cls.drive_start = time.time()
        cls.arrived = cls.drive(Twist)
        cls.drive_time = time.time() - cls.drive_start
        time.sleep(3.0)  # the last scans through both nodes
        cls.truth = read_truth(cls.truth_path)
        cls.logs = ""
        for name in ("emulator.log", "roslaunch.log"):
            with open(os.path.join(cls.tmp, name), errors="replace") as f:
                cls.logs += "\n--- %s (tail) ---\n%s" % (name, "".join(f.readlines()[-15:]))

    @classmethod
    def on_tf(cls, msg):
        caller = msg._connection_header.get("callerid", "?")
        for t in msg.transforms:
            cls.tf_publishers.setdefault((t.header.frame_id.lstrip("/"), t.child_frame_id.lstrip("/")), set()).add(caller)

    @classmethod
    def true_pose(cls):
        for line in cls.truth_file.readlines():
            v = line.split()
            if len(v) == 8:
                cls.pose = (float(v[1]), float(v[2]), 2.0 * math.atan2(float(v[6]), float(v[7])))
        return cls.pose

    @classmethod
    def drive(cls, Twist):
        """Stop, turn towards the next waypoint, drive to it; steered from the emulator's true pose."""
        import rospy
        rate = rospy.Rate(20)
        arrived = 0
        for wx, wy in WAYPOINTS:
            turning, deadline = True, time.time() + 60.0
            while not rospy.is_shutdown() and time.time() < deadline:
                x, y, th = cls.true_pose()
                dist = math.hypot(wx - x, wy - y)
                err = wrap(math.atan2(wy - y, wx - x) - th)
                if dist < 0.08:
                    arrived += 1
                    break
                cmd = Twist()
                turning = turning and abs(err) > 0.05
                if turning:
                    cmd.angular.z = max(-0.6, min(0.6, 2.0 * err))
                else:
                    cmd.linear.x = min(0.3, 0.8 * dist + 0.05)
                    cmd.angular.z = max(-0.5, min(0.5, 2.0 * err))
                cls.cmd.publish(cmd)
                rate.sleep()
            cls.cmd.publish(Twist())
            time.sleep(0.5)
        return arrived

    @classmethod
    def tearDownClass(cls):
        try:
            os.killpg(cls.launch.pid, signal.SIGINT)
            cls.launch.wait(30)
        except (subprocess.TimeoutExpired, ProcessLookupError):
            os.killpg(cls.launch.pid, signal.SIGKILL)
        cls.emulator.terminate()
        cls.emulator.wait(10)
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def ate(self):
        pairs = [(p.pose.pose.position, interpolate(self.truth, p.header.stamp.to_sec())) for p in self.poses]
        pairs = [(e, r) for e, r in pairs if r is not None]
        est = [(e.x, e.y) for e, _ in pairs]
        ref = [r for _, r in pairs]
        transform, rmse = align(est, ref)
        return transform, rmse, len(pairs)

    def test_a_drove_the_path(self):
        self.assertEqual(self.arrived, len(WAYPOINTS),
                         "reached %d of %d waypoints%s" % (self.arrived, len(WAYPOINTS), self.logs))
        self.assertGreater(len(self.truth), 1000)

    def test_b_scans_from_urg_node_reach_both_nodes(self):
        import rosgraph
        scans = self.scans
        self.assertGreater(len(scans), 8.0 * self.drive_time,
                           "%d scans in %.0f s%s" % (len(scans), self.drive_time, self.logs))
        s = scans[-1]
        self.assertEqual(s.header.frame_id, "laser")
        self.assertEqual(len(s.ranges), 682)  # steps 44..725 of the URG-04LX
        self.assertAlmostEqual(s.angle_min, -2.0862, places=3)
        self.assertAlmostEqual(s.angle_max, 2.0923, places=3)
        self.assertEqual(len(s.intensities), 0)  # the URG-04LX has none: urg_node's probe is refused
        stamps = [m.header.stamp.to_sec() for m in scans]
        self.assertTrue(all(b > a for a, b in zip(stamps, stamps[1:])), "scan stamps not increasing")
        self.assertLess(abs(stamps[-1] - time.time()), 5.0, "scan stamps not in wall-clock time")
        _, subscribers, _ = rosgraph.Master("/robot_drivers_rostest").getSystemState()
        readers = dict(subscribers).get("/scan", [])
        self.assertIn("/laser_odometry_node", readers)
        self.assertIn("/dpslam_node", readers)
        # One odometry per scan (stamped with it) and SLAM poses from most of them.
        self.assertGreater(len(self.odoms), 0.9 * len(scans))
        self.assertGreater(len(self.poses), 0.5 * len(scans))
        self.assertLessEqual(set(self.odoms), set(m.header.stamp for m in scans))

    def test_c_tf_chain(self):
        import rospy
        import tf2_ros
        checked = 0
        for m in self.scans[20:-20:25]:
            for parent, child in (("map", "odom"), ("odom", "base_link"), ("base_link", "laser"), ("map", "laser")):
                try:
                    self.buffer.lookup_transform(parent, child, m.header.stamp, rospy.Duration(0.0))
                except tf2_ros.TransformException as e:
                    self.fail("%s -> %s at %.3f: %s" % (parent, child, m.header.stamp.to_sec(), e))
            checked += 1
        self.assertGreater(checked, 10)

    def test_d_ate_against_the_emulator(self):
        _, rmse, n = self.ate()
        NUMBERS["ate"] = rmse
        NUMBERS["poses"] = n
        self.assertGreater(n, 300)
        self.assertLessEqual(rmse, ATE_LIMIT, "SLAM ATE %.4f m over %d poses" % (rmse, n))

    def test_e_map_covers_the_driven_area(self):
        self.assertTrue(self.maps, "no /map")
        m = self.maps[-1]
        (c, s, tx, ty), _, _ = self.ate()
        info = m.info
        NUMBERS["map"] = "%dx%d cells at %.3f m" % (info.width, info.height, info.resolution)
        free = covered = 0
        for t, x, y, _ in self.truth[::50]:
            # truth -> map frame: the inverse of the alignment of the estimate onto the truth
            dx, dy = x - tx, y - ty
            mx, my = c * dx + s * dy, -s * dx + c * dy
            i = int((mx - info.origin.position.x) / info.resolution)
            j = int((my - info.origin.position.y) / info.resolution)
            if 0 <= i < info.width and 0 <= j < info.height:
                covered += 1
                v = m.data[j * info.width + i]
                free += 1 if 0 <= v < 50 else 0
        n = len(self.truth[::50])
        NUMBERS["path_free"] = "%d of %d" % (free, n)
        self.assertEqual(covered, n, "the map does not span the driven path")
        self.assertGreaterEqual(free, 0.9 * n, "only %d of %d path samples free in the map" % (free, n))
        self.assertGreater(sum(1 for v in m.data if v > 65), 300)

    def test_f_save_map(self):
        import rospy
        from laser_dpslam.srv import SaveMap
        rospy.wait_for_service("save_map", 10)
        base = os.path.join(self.tmp, "office")
        res = rospy.ServiceProxy("save_map", SaveMap)(base)
        self.assertTrue(res.success, res.message)
        with open(base + ".pgm", "rb") as f:
            self.assertEqual(f.read(2), b"P5")
        self.assertTrue(os.path.getsize(base + ".yaml") > 0)

    def test_g_wheel_odometry_stays_off_tf(self):
        self.assertGreater(len(self.wheel), 5.0 * self.drive_time, "%d wheel_odom" % len(self.wheel))
        w = self.wheel[-1]
        self.assertEqual(w.header.frame_id, "odom")
        travelled = math.hypot(w.pose.pose.position.x, w.pose.pose.position.y)
        self.assertGreater(travelled, 5.0, "wheel odometry ends %.2f m from its start" % travelled)
        NUMBERS["wheel_odom"] = len(self.wheel)
        self.assertEqual(self.tf_publishers.get(("odom", "base_link")), {"/laser_odometry_node"})
        for frames, callers in self.tf_publishers.items():
            self.assertNotIn("/create_driver", callers, "create_driver publishes %s -> %s" % frames)


NUMBERS = {}
DRIVERS = None

if __name__ == "__main__":
    try:
        DRIVERS = drivers_devel()
    except DriversUnavailable as e:
        report_skipped(str(e))
    import rostest
    try:
        rostest.rosrun("laser_dpslam", "robot_drivers", RobotDrivers)
    finally:
        summary = "scans %d, SLAM poses %s, ATE %s m, map %s, path cells free %s, wheel_odom %s\n" % (
            len(RobotDrivers.__dict__.get("scans", [])), NUMBERS.get("poses"),
            "%.4f" % NUMBERS["ate"] if "ate" in NUMBERS else None, NUMBERS.get("map"),
            NUMBERS.get("path_free"), NUMBERS.get("wheel_odom"))
        print("robot_drivers_rostest: " + summary, flush=True)
        path = results_path()
        if path:
            with open(os.path.join(os.path.dirname(path), "robot_drivers_summary.txt"), "w") as f:
                f.write(summary)
