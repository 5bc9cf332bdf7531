"""robot.launch against the real drivers, urg_node and create_autonomy's create_driver, built from source by
scripts/build_drivers.sh: their executables exist under the names robot.launch starts, every parameter
robot.launch gives them is one they read, and every topic robot.launch remaps is one they publish or
subscribe. Without the driver sources the test reports itself skipped with the reason; when they fail to build
it fails."""
import os
import re
import sys
import unittest

import roslaunch.config

# catkin runs nosetests with -P (no path adjustment): the helper beside this file is found through its folder.
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from drivers_workspace import DriversUnavailable, drivers_devel  # noqa: E402

PKG = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
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
        cls.devel, cls.skip, cls.error = None, "", ""
        try:
            cls.devel = drivers_devel()
        except DriversUnavailable as e:
            cls.skip = str(e)
        except RuntimeError as e:
            cls.error = str(e)
        path = os.path.join(PKG, "launch", "robot.launch")
        cls.config = roslaunch.config.load_config_default([(path, ["rviz:=false"])], None, verbose=False)
        cls.nodes = {n.name: n for n in cls.config.nodes}

    def driver_dir(self, package):
        """The package's source folder in the drivers' workspace."""
        if self.error:
            self.fail(self.error)
        if self.devel is None:
            self.skipTest("robot drivers not available: " + self.skip)
        for root, dirs, files in os.walk(os.path.join(os.path.dirname(self.devel), "src")):
            if os.path.basename(root) == package and "package.xml" in files:
                return root
        self.fail("no source of %s in %s" % (package, os.path.dirname(self.devel)))

    def check_node(self, name):
        node = self.nodes[name]
        root = self.driver_dir(node.package)
        exe = os.path.join(self.devel, node.package, "lib", node.package, node.type)
        self.assertTrue(os.access(exe, os.X_OK),
                        "robot.launch starts %s/%s, which the driver does not build (%s)" % (node.package, node.type, exe))
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
