"""robot.launch against the real drivers, urg_node and create_autonomy's create_driver, built from source by
scripts/build_drivers.sh (scripts/test.sh puts that workspace on the package path): their executables exist
under the names robot.launch starts, every parameter robot.launch gives them is one they read, and every topic
robot.launch remaps is one they publish or subscribe. Without the drivers the test reports itself skipped
with the reason."""
import os
import re
import unittest

import roslaunch.config
import roslib.packages
import rospkg

PKG = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
# What scripts/test.sh found when it tried to build the drivers (empty: built).
SKIP_REASON = os.environ.get("LASER_DPSLAM_DRIVERS_SKIP", "")

# The parameters a ROS 1 C++ node reads: nh.param<T>("name", ...), nh.param("name", ...), getParam("name", ...);
# and the dynamic_reconfigure ones, read from the parameter server at start-up: gen.add("name", ...).
PARAM_CALL = re.compile(r'(?:\bparam\s*(?:<[^>]*>)?|getParam)\s*\(\s*"([^"]+)"')
CFG_ADD = re.compile(r'gen\.add\(\s*"([^"]+)"')
# Topics: advertise<T>("name", ...), subscribe("name", ...).
TOPIC_CALL = re.compile(r'(?:advertise\s*<[^>]*>|subscribe(?:\s*<[^>]*>)?)\s*\(\s*"([^"]+)"')


def sources(package_dir, pattern):
    found = []
    for root, _, files in os.walk(package_dir):
        found += [os.path.join(root, f) for f in files if re.search(pattern, f)]
    return found


def matches(files, regex):
    names = set()
    for path in files:
        with open(path, encoding="utf-8", errors="replace") as f:
            names.update(regex.findall(f.read()))
    return names


class RobotDriversTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.rospack = rospkg.RosPack()
        path = os.path.join(PKG, "launch", "robot.launch")
        cls.config = roslaunch.config.load_config_default([(path, ["rviz:=false"])], None, verbose=False)
        cls.nodes = {n.name: n for n in cls.config.nodes}

    def driver_dir(self, package):
        try:
            return self.rospack.get_path(package)
        except rospkg.ResourceNotFound:
            self.skipTest("driver package %s not found (%s)"
                          % (package, SKIP_REASON or "scripts/build_drivers.sh not run: scripts/test.sh builds them"))

    def check_node(self, name):
        node = self.nodes[name]
        root = self.driver_dir(node.package)
        self.assertTrue(roslib.packages.find_node(node.package, node.type, rospack=self.rospack),
                        "robot.launch starts %s/%s, which the driver does not build" % (node.package, node.type))
        code = sources(root, r"\.(cpp|h|hpp)$")
        read = matches(code, PARAM_CALL) | matches(sources(root, r"\.cfg$"), CFG_ADD)
        given = {k.split("/")[-1] for k in self.config.params if k.startswith("/%s/" % name)}
        self.assertTrue(given, "robot.launch gives %s no parameter" % name)
        self.assertEqual(given - read, set(), "parameters %s does not read (it reads %s)" % (name, sorted(read)))
        topics = matches(code, TOPIC_CALL)
        for source, _ in node.remap_args:
            self.assertIn(source, topics, "robot.launch remaps %s of %s, which it never uses" % (source, name))
        return read, topics

    def test_urg_node(self):
        read, topics = self.check_node("urg_node")
        self.assertIn("scan", topics)
        for key in ("serial_port", "frame_id", "angle_min", "angle_max", "publish_intensity"):
            self.assertIn(key, read)

    def test_create_driver(self):
        read, topics = self.check_node("create_driver")
        # The wheel odometry (remapped to wheel_odom) and the velocity command a teleop node sends.
        self.assertIn("odom", topics)
        self.assertIn("cmd_vel", topics)
        for key in ("dev", "robot_model", "base_frame", "odom_frame", "publish_tf"):
            self.assertIn(key, read)


if __name__ == "__main__":
    unittest.main()
