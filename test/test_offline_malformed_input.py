"""dpslam_offline on damaged bags (issue 6): a clear error on stderr, a non-zero exit, and none of the
outputs, so that nothing looks like the result of a complete run."""
import os
import re
import resource
import shutil
import subprocess
import tempfile
import unittest

PKG = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
DEMO = os.path.join(PKG, "bags", "demo.bag")
OUTPUTS = ["odometry.tum", "trajectory.tum", "map.pgm", "map.yaml", "map.png", "stats.json"]


class OfflineMalformedInputTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp()
        with open(DEMO, "rb") as f:
            self.demo = f.read()

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def write_bag(self, data):
        path = os.path.join(self.dir, "damaged.bag")
        with open(path, "wb") as f:
            f.write(data)
        return path

    def patched_bag(self, at, value):
        """The demo bag with the little-endian uint32 at byte `at` replaced by `value`."""
        data = bytearray(self.demo)
        data[at:at + 4] = value.to_bytes(4, "little")
        return self.write_bag(bytes(data))

    def run_offline(self, bag, extra=()):
        out = os.path.join(self.dir, "out")
        # A timeout: a corrupted array length used to make the deserializer allocate gigabytes for minutes.
        p = subprocess.run(["rosrun", "laser_dpslam", "dpslam_offline", "--bag", bag, "--out", out, "--quiet"]
                           + list(extra), capture_output=True, text=True, timeout=120)
        self.assertNotEqual(p.returncode, 0, p.stderr)
        self.assertNotIn("terminate called", p.stderr)  # a handled error, not an abort
        self.assertIn("dpslam_offline: ", p.stderr)
        self.assertIn(bag, p.stderr)
        left = sorted(os.listdir(out)) if os.path.isdir(out) else []
        self.assertEqual(left, [], "outputs of a failed run: %s" % left)
        return p.stderr

    def scan_ranges_length_offsets(self):
        """Offsets of the ranges length field of every scan (frame 'laser': length 5, then 7 float32)."""
        return [m.start() + 9 + 28 for m in re.finditer(re.escape(b"\x05\x00\x00\x00laser"), self.demo)
                if self.demo[m.start() + 37:m.start() + 41] == (683).to_bytes(4, "little")]

    def test_bag_truncated_to_half(self):
        err = self.run_offline(self.write_bag(self.demo[:len(self.demo) // 2]))
        self.assertIn("truncated", err)

    def test_corrupted_array_length_in_a_scan(self):
        offsets = self.scan_ranges_length_offsets()
        self.assertGreater(len(offsets), 100)  # the demo bag is uncompressed: its records can be patched
        err = self.run_offline(self.patched_bag(offsets[100], 0x7FFFFFFF))
        self.assertIn("corrupted LaserScan record: ranges length 2147483647", err)
        self.assertIn("scan message 101 of 981", err)

    def test_corrupted_record_header(self):
        # The 'op' field of a scan record's header (length 4: "op=" and the op code 0x02; then the 'time'
        # field, the data length and the scan: seq, stamp, frame 'laser' 41 bytes on) gets an impossible
        # length: rosbag cannot parse the record.
        field = b"\x04\x00\x00\x00op=\x02"
        starts = [m.start() for m in re.finditer(re.escape(field), self.demo)
                  if self.demo[m.start() + 41:m.start() + 50] == b"\x05\x00\x00\x00laser"]
        self.assertEqual(len(starts), 981)
        err = self.run_offline(self.patched_bag(starts[200], 0xFFFFFF00))
        self.assertIn("scan message 201 of 981", err)
        self.assertIn("damaged", err)

    def test_corrupted_transform_count_in_tf_static(self):
        # The demo's one /tf_static record (count, seq, stamp, then frame 'base_link' and child 'laser'):
        # its transform count becomes 20 million. The record is skipped with a warning naming it (no
        # gigabytes allocated for it); the run goes on with the laser at base_link, as for a bag without TF.
        key = b"\x09\x00\x00\x00base_link\x05\x00\x00\x00laser"
        starts = [m.start() for m in re.finditer(re.escape(key), self.demo)]
        self.assertEqual(len(starts), 1)
        at = starts[0] - 16
        self.assertEqual(self.demo[at:at + 4], (1).to_bytes(4, "little"))
        out = os.path.join(self.dir, "tf")
        p = subprocess.run(["rosrun", "laser_dpslam", "dpslam_offline", "--bag", self.patched_bag(at, 20000000), "--out", out,
                            "--quiet", "--odometry-only"], capture_output=True, text=True, timeout=120)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn("skipped 1 damaged TF record(s), the first /tf_static", p.stderr)
        self.assertIn("20000000 transforms do not fit", p.stderr)
        self.assertTrue(os.path.exists(os.path.join(out, "odometry.tum")))
        # Peak memory of every child so far (kB): deserializing that record used to take 2.7 GB.
        self.assertLess(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, 1 << 20)

    def test_wheel_odometry_topic_missing(self):
        # The demo bag has no wheel odometry: the error names the topic and the Odometry topics it has.
        err = self.run_offline(self.write_bag(self.demo), ["--wheel-odom", "/wheel_odom"])
        self.assertIn("--wheel-odom: no messages on /wheel_odom", err)
        self.assertIn("Odometry topics in the bag: /ground_truth", err)

    def test_the_intact_bag_still_runs(self):
        # The same helpers on the untouched bag: the failures above come from the damage, not the set-up.
        out = os.path.join(self.dir, "ok")
        p = subprocess.run(["rosrun", "laser_dpslam", "dpslam_offline", "--bag", self.write_bag(self.demo), "--out", out,
                            "--quiet", "--odometry-only"], capture_output=True, text=True, timeout=120)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertTrue(os.path.exists(os.path.join(out, "stats.json")))


if __name__ == "__main__":
    unittest.main()
