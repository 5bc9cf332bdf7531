"""Every launch file parses with every flag combination (roslaunch's own loader, no nodes started, so the
robot drivers need not be installed); every YAML parameter reaches its node; arguments are passed through
from robot.launch / bag.launch to slam.launch; the nodes of this package exist as executables."""
import itertools
import os
import unittest

import roslaunch.config
import roslib.packages
import rospkg
import yaml

PKG = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
FLAGS = {
    "slam.launch": ["slam", "wheel_odometry"],
    "bag.launch": ["slam", "rviz", "publish_laser_tf", "exit_at_end"],
    "robot.launch": ["slam", "rviz", "create", "upside_down", "wheel_odometry"],
    "sim_robot.launch": ["slam", "rviz"],
}


def load(name, *args):
    path = os.path.join(PKG, "launch", name)
    return roslaunch.config.load_config_default([(path, list(args))] if args else [path], None, verbose=False)


def nodes(config):
    return {n.name: n for n in config.nodes}


def remaps(node):
    return dict(tuple(r) for r in node.remap_args)


def yaml_keys(name):
    with open(os.path.join(PKG, "config", name)) as f:
        return list(yaml.safe_load(f).keys())


class LaunchArgsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        try:
            rospkg.RosPack().get_path("laser_dpslam")
        except rospkg.ResourceNotFound:
            raise unittest.SkipTest("laser_dpslam is not on ROS_PACKAGE_PATH")

    def test_every_flag_combination_parses(self):
        for name, flags in FLAGS.items():
            for values in itertools.product(["true", "false"], repeat=len(flags)):
                args = ["%s:=%s" % (f, v) for f, v in zip(flags, values)]
                with self.subTest(launch=name, args=args):
                    c = load(name, *args)
                    n = nodes(c)
                    self.assertIn("laser_odometry_node", n)
                    self.assertEqual("dpslam_node" in n, "slam:=true" in args)
                    if "rviz:=true" in args:
                        self.assertIn("rviz", n)

    def test_every_yaml_parameter_reaches_its_node(self):
        c = load("slam.launch")
        for node, config in (("laser_odometry_node", "laser_odometry.yaml"), ("dpslam_node", "dpslam.yaml")):
            for key in yaml_keys(config):
                self.assertIn("/%s/%s" % (node, key), c.params, "%s: %s not loaded" % (node, key))

    def test_nodes_of_this_package_are_built(self):
        for node in nodes(load("slam.launch")).values():
            self.assertEqual(node.package, "laser_dpslam")
            self.assertTrue(roslib.packages.find_node("laser_dpslam", node.type), "%s not built" % node.type)

    def test_executables_of_installed_packages_exist(self):
        # Packages that are absent (urg_node, create_driver, maybe rviz) are the user's to install; but a package
        # that is there without its executable fails only at run time, e.g. Debian's tf2_ros without
        # tf2-tools, which ships static_transform_publisher.
        rospack = rospkg.RosPack()
        for name, flags in FLAGS.items():
            for node in load(name, *["%s:=true" % f for f in flags]).nodes:
                try:
                    rospack.get_path(node.package)
                except rospkg.ResourceNotFound:
                    continue
                with self.subTest(launch=name, node=node.name):
                    self.assertTrue(roslib.packages.find_node(node.package, node.type, rospack=rospack),
                                    "%s: no executable %s/%s (for tf2_ros: apt-get install tf2-tools)"
                                    % (name, node.package, node.type))

    def test_robot_launch_passes_frames_and_topic_through(self):
        c = load("robot.launch", "base_frame:=base_footprint", "odom_frame:=odom2", "map_frame:=world",
                 "scan_topic:=base_scan", "laser_frame:=hokuyo")
        n = nodes(c)
        p = c.params
        self.assertEqual(p["/laser_odometry_node/base_frame"].value, "base_footprint")
        self.assertEqual(p["/laser_odometry_node/odom_frame"].value, "odom2")
        self.assertEqual(p["/dpslam_node/odom_frame"].value, "odom2")
        self.assertEqual(p["/dpslam_node/map_frame"].value, "world")
        self.assertEqual(p["/create_driver/base_frame"].value, "base_footprint")
        self.assertEqual(p["/create_driver/odom_frame"].value, "odom2")
        self.assertEqual(p["/urg_node/frame_id"].value, "hokuyo")
        self.assertEqual(remaps(n["urg_node"]).get("scan"), "base_scan")
        self.assertEqual(remaps(n["laser_odometry_node"]).get("scan"), "base_scan")
        self.assertEqual(remaps(n["dpslam_node"]).get("scan"), "base_scan")
        self.assertEqual(n["laser_mount_tf"].args.split()[-2:], ["base_footprint", "hokuyo"])
        self.assertIn("-f world", n["rviz"].args)

    def test_robot_launch_keeps_wheel_odometry_out_of_the_way(self):
        n = nodes(load("robot.launch"))
        self.assertEqual(remaps(n["create_driver"]).get("odom"), "wheel_odom")
        # create_autonomy's current package, node and parameter names (ca_driver was its old name).
        self.assertEqual((n["create_driver"].package, n["create_driver"].type), ("create_driver", "create_driver"))
        p = load("robot.launch", "create_port:=/dev/ttyUSB7").params
        self.assertEqual(p["/create_driver/dev"].value, "/dev/ttyUSB7")
        self.assertEqual(p["/create_driver/robot_model"].value, "CREATE_1")
        self.assertEqual(p["/create_driver/odom_frame"].value, "odom")
        self.assertEqual(p["/urg_node/serial_port"].value, "/dev/ttyACM0")
        self.assertEqual(len(n["laser_mount_tf"].args.split()), 8)  # x y z yaw pitch roll parent child

    def test_wheel_odometry_reaches_both_nodes(self):
        def use(*args):
            p = load("robot.launch", *args).params
            odometry, slam = p["/laser_odometry_node/use_wheel_odometry"].value, p["/dpslam_node/use_wheel_odometry"].value
            self.assertEqual(odometry, slam)  # the SLAM bounds its noise by the wheels only when they are fused
            return odometry
        self.assertFalse(use())  # the YAML's default: laser only
        self.assertTrue(use("wheel_odometry:=true"))
        self.assertFalse(use("wheel_odometry:=true", "create:=false"))  # no base driver, no wheels
        self.assertEqual(remaps(nodes(load("robot.launch"))["laser_odometry_node"]).get("wheel_odom"), "wheel_odom")
        n = nodes(load("slam.launch", "wheel_odometry:=true", "wheel_odom_topic:=odom_wheels"))
        self.assertEqual(remaps(n["laser_odometry_node"]).get("wheel_odom"), "odom_wheels")

    def test_sim_robot_launch_points_the_drivers_at_the_emulator(self):
        c = load("sim_robot.launch", "rviz:=false")
        n, p = nodes(c), c.params
        args = n["emulate_robot"].args.split()
        self.assertEqual(p["/urg_node/serial_port"].value, args[args.index("--laser-port") + 1])
        self.assertEqual(p["/create_driver/dev"].value, args[args.index("--create-port") + 1])
        self.assertTrue(os.path.isfile(args[args.index("--floorplan") + 1]))
        self.assertNotIn("rviz", n)

    def test_urg_field_of_view_arguments(self):
        c = load("robot.launch", "angle_min:=-1.5", "angle_max:=1.5", "serial_port:=/dev/ttyUSB1")
        self.assertAlmostEqual(c.params["/urg_node/angle_min"].value, -1.5)
        self.assertAlmostEqual(c.params["/urg_node/angle_max"].value, 1.5)
        self.assertEqual(c.params["/urg_node/serial_port"].value, "/dev/ttyUSB1")

    def test_rviz_fixed_frame_follows_slam(self):
        self.assertIn("-f map", nodes(load("bag.launch", "rviz:=true"))["rviz"].args)
        self.assertIn("-f odom", nodes(load("bag.launch", "rviz:=true", "slam:=false"))["rviz"].args)
        self.assertIn("-f odom", nodes(load("robot.launch", "slam:=false"))["rviz"].args)
        self.assertIn("-f base_link", nodes(load("bag.launch", "rviz:=true", "fixed_frame:=base_link"))["rviz"].args)

    def test_bag_launch_player(self):
        n = nodes(load("bag.launch"))
        self.assertFalse(n["player"].required)  # the map stays up for save_map and rviz after the bag
        self.assertIn("--rate=1.0", n["player"].args)
        n = nodes(load("bag.launch", "exit_at_end:=true", "rate:=3", "scan_topic:=base_scan"))
        self.assertTrue(n["player"].required)
        self.assertIn("--rate=3", n["player"].args)
        self.assertEqual(remaps(n["laser_odometry_node"]).get("scan"), "base_scan")

    def test_bag_launch_laser_tf_for_bags_without_one(self):
        n = nodes(load("bag.launch", "publish_laser_tf:=true", "laser_x:=0.2", "laser_yaw:=3.14159",
                       "base_frame:=base_footprint"))
        args = n["laser_mount_tf"].args.split()
        self.assertEqual(args[0], "0.2")
        self.assertEqual(args[3], "3.14159")
        self.assertEqual(args[-2:], ["base_footprint", "laser"])
        self.assertEqual(n["laser_mount_tf"].package, "tf2_ros")


if __name__ == "__main__":
    unittest.main()
