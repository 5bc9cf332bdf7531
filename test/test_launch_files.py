"""Validates the launch files without running them (the robot drivers are not installed here):
arguments parse, YAML parameter files load, node names, remaps and frames are as documented."""
import os
import unittest

import roslaunch.config
import rospkg

PKG = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


def load(name, *args):
    os.environ.setdefault("ROS_PACKAGE_PATH", os.path.dirname(PKG))
    path = os.path.join(PKG, "launch", name)
    return roslaunch.config.load_config_default([(path, list(args))] if args else [path], None, verbose=False)


def nodes(config):
    return {n.name: n for n in config.nodes}


class LaunchFilesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        try:
            rospkg.RosPack().get_path("laser_dpslam")
        except rospkg.ResourceNotFound:
            raise unittest.SkipTest("laser_dpslam is not on ROS_PACKAGE_PATH")

    def test_slam_launch_loads_both_yaml_files(self):
        c = load("slam.launch")
        self.assertEqual(set(nodes(c)), {"laser_odometry_node", "dpslam_node"})
        self.assertEqual(c.params["/laser_odometry_node/resampling"].value, "saliency")
        self.assertEqual(c.params["/laser_odometry_node/base_frame"].value, "base_link")
        self.assertIn("/dpslam_node/particles", c.params)
        self.assertEqual(c.params["/dpslam_node/map_frame"].value, "map")

    def test_slam_launch_arguments(self):
        c = load("slam.launch", "base_frame:=base_footprint", "scan_topic:=front_scan", "slam:=false")
        n = nodes(c)
        self.assertEqual(set(n), {"laser_odometry_node"})
        self.assertIn(["scan", "front_scan"], [list(r) for r in n["laser_odometry_node"].remap_args])
        self.assertEqual(c.params["/laser_odometry_node/base_frame"].value, "base_footprint")

    def test_robot_launch_turns_the_create_odometry_tf_off(self):
        c = load("robot.launch", "rviz:=false")
        n = nodes(c)
        for name in ("urg_node", "create_driver", "laser_mount_tf", "laser_odometry_node", "dpslam_node"):
            self.assertIn(name, n)
        self.assertNotIn("rviz", n)
        self.assertIs(c.params["/create_driver/publish_tf"].value, False)
        self.assertEqual(c.params["/urg_node/frame_id"].value, "laser")
        self.assertEqual(n["laser_mount_tf"].args.split()[-2:], ["base_link", "laser"])

    def test_robot_launch_upside_down_laser_rolls_by_pi(self):
        c = load("robot.launch", "rviz:=false", "upside_down:=true", "base_frame:=base_footprint")
        args = nodes(c)["laser_mount_tf"].args.split()
        self.assertAlmostEqual(float(args[5]), 3.14159265, places=6)
        self.assertEqual(args[-2], "base_footprint")

    def test_bag_launch_uses_sim_time_and_plays_the_demo(self):
        c = load("bag.launch")
        self.assertIs(c.params["/use_sim_time"].value, True)
        player = nodes(c)["player"]
        self.assertIn("--clock", player.args)
        self.assertTrue(player.args.rstrip().endswith("bags/demo.bag"))
        self.assertNotIn("laser_mount_tf", nodes(c))
        c = load("bag.launch", "publish_laser_tf:=true", "laser_x:=0.2", "bag:=/tmp/x.bag")
        self.assertIn("laser_mount_tf", nodes(c))
        self.assertIn("/tmp/x.bag", nodes(c)["player"].args)


if __name__ == "__main__":
    unittest.main()
