"""tools/log_to_bag on small synthetic logs of each format, malformed logs, and (optionally) the real logs in
shared/datasets."""
import math
import os
import shutil
import subprocess
import tempfile
import unittest

import rosbag

HERE = os.path.dirname(os.path.abspath(__file__))
TOOL = os.path.join(HERE, '..', 'tools', 'log_to_bag')
DATASETS = os.path.join(HERE, '..', '..', 'shared', 'datasets')
INF = float('inf')


def run(*args):
    p = subprocess.run(['/usr/bin/python3', TOOL] + list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       universal_newlines=True)
    return p.returncode, p.stdout, p.stderr


def yaw(q):
    return 2.0 * math.atan2(q.z, q.w)


def mines_line(stamp_us, left, right, ranges_mm, trailing='7777'):
    head = [str(stamp_us), '14710', str(left), str(right)] + ['0'] * 20
    return ' '.join(head + [str(r) for r in ranges_mm] + [trailing]) + '\n'


class LogToBagTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp()

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def path(self, name):
        return os.path.join(self.dir, name)

    def write(self, name, text):
        with open(self.path(name), 'w') as f:
            f.write(text)
        return self.path(name)

    def convert(self, fmt, text, *extra):
        src = self.write('in.' + fmt, text)
        code, out, err = run('--format', fmt, src, self.path('out.bag'), *extra)
        self.assertEqual(code, 0, err)
        self.assertFalse(os.path.exists(self.path('out.bag.tmp')))
        msgs = {'/scan': [], '/tf_static': [], '/wheel_odom': []}
        with rosbag.Bag(self.path('out.bag')) as bag:
            for topic, msg, t in bag.read_messages():
                self.assertIn(topic, msgs)
                stamp = msg.transforms[0].header.stamp if topic == '/tf_static' else msg.header.stamp
                # Record time = header stamp, except that a stamp of 0 is recorded at 1 ns (ros::TIME_MIN).
                self.assertEqual(t.to_nsec(), max(stamp.to_nsec(), 1))
                msgs[topic].append(msg)
        self.assertEqual(len(msgs['/tf_static']), 1)
        tf = msgs['/tf_static'][0].transforms
        self.assertEqual(len(tf), 1)
        self.assertEqual((tf[0].header.frame_id, tf[0].child_frame_id), ('base_link', 'laser'))
        r, p = tf[0].transform.rotation, tf[0].transform.translation
        self.assertEqual((p.x, p.y, p.z, r.x, r.y, r.z, r.w), (0, 0, 0, 0, 0, 0, 1))
        self.assertEqual(tf[0].header.stamp, msgs['/scan'][0].header.stamp)
        for k, s in enumerate(msgs['/scan']):
            self.assertEqual(s.header.frame_id, 'laser')
            self.assertEqual(s.header.seq, k)
        for o in msgs['/wheel_odom']:
            self.assertEqual((o.header.frame_id, o.child_frame_id), ('odom', 'base_link'))
        return msgs

    def assertRanges(self, ranges, expected):
        """+inf exactly, finite values to float32 precision."""
        self.assertEqual(len(ranges), len(expected))
        for r, e in zip(ranges, expected):
            if math.isinf(e):
                self.assertEqual(r, e)
            else:
                self.assertAlmostEqual(r, e, places=5)

    def assertAngles(self, scan, fov_deg, n):
        fov = math.radians(fov_deg)
        self.assertEqual(len(scan.ranges), n)
        self.assertAlmostEqual(scan.angle_min, -fov / 2, places=6)  # float32 fields
        self.assertAlmostEqual(scan.angle_max, fov / 2, places=6)
        self.assertAlmostEqual(scan.angle_increment, fov / (n - 1), places=7)

    # ---- CARMEN ----------------------------------------------------------------------------------------
    CARMEN = ('# message formats defined: ...\n'
              'PARAM robot_front_laser_max 81.9 host 0.1\n'
              'ODOM 0 0 0 0 0 0 1.0 host 1.0\n'
              'FLASER 5 1.00 2.00 81.91 0.50 81.90 0 0 0 10.0 -2.0 0.5 1134864629.895182 b21 0.086295\n'
              '\n'
              'FLASER 5 1.50 90.00 2.00 0.50 3.00 0 0 0 10.1 -2.0 -3.1 1134864630.105179 b21 0.273363\n')

    def test_carmen(self):
        m = self.convert('carmen', self.CARMEN)
        scans = m['/scan']
        self.assertEqual(len(scans), 2)
        # Exact stamps from the decimal ipc_timestamp (not via a double).
        self.assertEqual((scans[0].header.stamp.secs, scans[0].header.stamp.nsecs), (1134864629, 895182000))
        self.assertEqual((scans[1].header.stamp.secs, scans[1].header.stamp.nsecs), (1134864630, 105179000))
        self.assertAngles(scans[0], 180.0, 5)
        self.assertRanges(scans[0].ranges, [1.0, 2.0, INF, 0.5, 81.9])  # 81.91 = no return -> +inf
        self.assertRanges(scans[1].ranges, [1.5, INF, 2.0, 0.5, 3.0])  # above it too
        self.assertAlmostEqual(scans[0].range_max, 81.91, places=4)
        self.assertEqual(scans[0].range_min, 0.0)
        odom = m['/wheel_odom']
        self.assertEqual(len(odom), 2)  # from the FLASER lines; the ODOM line is not a scan
        self.assertEqual(odom[0].header.stamp, scans[0].header.stamp)
        self.assertAlmostEqual(odom[0].pose.pose.position.x, 10.0)
        self.assertAlmostEqual(odom[0].pose.pose.position.y, -2.0)
        self.assertAlmostEqual(yaw(odom[0].pose.pose.orientation), 0.5)
        self.assertAlmostEqual(yaw(odom[1].pose.pose.orientation), -3.1)

    def test_fov_and_max_range_options(self):
        m = self.convert('carmen', self.CARMEN, '--fov-deg', '100', '--max-range', '2.0')
        s = m['/scan'][0]
        self.assertAngles(s, 100.0, 5)
        self.assertRanges(s.ranges, [1.0, INF, INF, 0.5, INF])
        self.assertAlmostEqual(s.range_max, 2.0, places=6)

    # ---- Mines -----------------------------------------------------------------------------------------
    def test_mines(self):
        ranges = [1000 + k for k in range(682)]
        ranges[0] = 0
        ranges[681] = 5580
        text = (mines_line(212387282, 29221, 25178, ranges) +
                mines_line(212484734, 29221 + 2000, 25178 + 2000, ranges) +    # both wheels one turn
                mines_line(212584734, 29221 + 1000, 25178 + 3000, ranges))     # turn in place to the left
        m = self.convert('mines', text)
        scans = m['/scan']
        self.assertEqual(len(scans), 3)
        self.assertEqual((scans[0].header.stamp.secs, scans[0].header.stamp.nsecs), (212, 387282000))
        self.assertEqual((scans[1].header.stamp.secs, scans[1].header.stamp.nsecs), (212, 484734000))
        s = scans[0]
        self.assertAngles(s, 240.0, 682)  # the 707th token (7777) is dropped
        self.assertEqual(s.ranges[0], INF)  # 0 = no return
        self.assertAlmostEqual(s.ranges[1], 1.001, places=6)
        self.assertAlmostEqual(s.ranges[681], 5.58, places=6)
        self.assertNotIn(7.777, [round(r, 3) for r in s.ranges])
        self.assertAlmostEqual(s.range_min, 0.02, places=6)
        self.assertAlmostEqual(s.range_max, 5.6, places=6)
        self.assertAlmostEqual(s.scan_time, 0.1, places=6)
        # Wheel odometry: 77 mm wheels, 2000 ticks a turn, half axle 165 mm (BreezySLAM's MinesRover).
        odom = m['/wheel_odom']
        self.assertEqual(len(odom), 3)
        p0, p1, p2 = [o.pose.pose for o in odom]
        self.assertEqual((p0.position.x, p0.position.y, yaw(p0.orientation)), (0.0, 0.0, 0.0))
        self.assertAlmostEqual(p1.position.x, 2 * math.pi * 0.077, places=9)
        self.assertAlmostEqual(p1.position.y, 0.0, places=9)
        self.assertAlmostEqual(p2.position.x, 2 * math.pi * 0.077, places=9)
        self.assertAlmostEqual(yaw(p2.orientation), (2 * math.pi * 0.077) / (2 * 0.165), places=6)

    def test_mines_max_range_option(self):
        ranges = [1000] * 682
        ranges[5] = 4500
        s = self.convert('mines', mines_line(1000000, 0, 0, ranges), '--max-range', '4.0')['/scan'][0]
        self.assertEqual(s.ranges[5], INF)
        self.assertAlmostEqual(s.ranges[4], 1.0)
        self.assertAlmostEqual(s.range_max, 4.0, places=6)

    # ---- DP-SLAM ---------------------------------------------------------------------------------------
    def dpslam_text(self):
        lines = []
        for k in range(3):
            ranges = ['%.6f' % (1.0 + 0.01 * i) for i in range(181)]
            ranges[0], ranges[1], ranges[2] = '8.190000', '8.191000', '8.180000'
            lines.append('Odometry %.3f %.3f %.3f \n' % (k * 0.1, 0.0, 0.05 * k))
            lines.append('Laser 181 %s \n' % ' '.join(ranges))
        return ''.join(lines)

    def test_dpslam(self):
        m = self.convert('dpslam', self.dpslam_text())
        scans = m['/scan']
        # No time in these logs: 10 Hz from 0 (the default --start-time).
        self.assertEqual([(s.header.stamp.secs, s.header.stamp.nsecs) for s in scans],
                         [(0, 0), (0, 100000000), (0, 200000000)])
        s = scans[0]
        self.assertAngles(s, 180.0, 181)
        self.assertEqual(s.ranges[0], INF)
        self.assertEqual(s.ranges[1], INF)
        self.assertAlmostEqual(s.ranges[2], 8.18, places=5)
        self.assertAlmostEqual(s.ranges[180], 2.8, places=5)
        self.assertAlmostEqual(s.range_max, 8.19, places=5)
        odom = m['/wheel_odom']
        self.assertEqual([o.header.stamp for o in odom], [s.header.stamp for s in scans])
        self.assertAlmostEqual(odom[2].pose.pose.position.x, 0.2)
        self.assertAlmostEqual(yaw(odom[2].pose.pose.orientation), 0.1)

    def test_dpslam_start_time(self):
        scans = self.convert('dpslam', self.dpslam_text(), '--start-time', '5')['/scan']
        self.assertEqual([s.header.stamp.to_sec() for s in scans], [5.0, 5.1, 5.2])

    # ---- malformed input -------------------------------------------------------------------------------
    def expect_failure(self, fmt, text, where, what=None):
        src = self.write('bad.' + fmt, text)
        out = self.path('bad.bag')
        code, stdout, err = run('--format', fmt, src, out)
        self.assertNotEqual(code, 0)
        self.assertIn(where, err)
        if what:
            self.assertIn(what, err)
        self.assertFalse(os.path.exists(out), 'a bag was left behind')
        self.assertFalse(os.path.exists(out + '.tmp'), 'a temporary bag was left behind')

    def test_malformed_lines(self):
        ok = 'FLASER 3 1 2 3 0 0 0 0 0 0 5.0 h 5.0\n'
        self.expect_failure('carmen', ok * 2 + 'FLASER 3 1 2', 'bad.carmen:3:', 'truncated')  # cut last line
        self.expect_failure('carmen', ok + 'FLASER 3 1 x 3 0 0 0 0 0 0 5.1 h 5.1\n', 'bad.carmen:2:', "'x'")
        self.expect_failure('carmen', ok + 'FLASER three 1 2 3\n', 'bad.carmen:2:')
        self.expect_failure('carmen', ok + 'FLASER 3 1 2 3 0 0 0 0 0 0 nan h 5.1\n', 'bad.carmen:2:')
        self.expect_failure('carmen', '# only comments\n', 'no laser scans')
        good = mines_line(1000000, 0, 0, [1000] * 682)
        self.expect_failure('mines', good + mines_line(1100000, 0, 0, [1000] * 681), 'bad.mines:2:', '707')
        self.expect_failure('mines', good + good + good.replace(' 1000 ', ' 1.5e3 ', 1), 'bad.mines:3:')
        self.expect_failure('mines', good + good[:len(good) // 2], 'bad.mines:2:')
        self.expect_failure('dpslam', 'Odometry 0 0 0\nLaser 3 1 2 3\nOdometry 0 0\n', 'bad.dpslam:3:')
        self.expect_failure('dpslam', 'Odometry 0 0 0\nLaser 3 1 2\n', 'bad.dpslam:2:')
        self.expect_failure('dpslam', 'Odometry 0 0 0\nLaser 3 1 2 3\nSonar 1 2\n', 'bad.dpslam:3:', 'Sonar')
        self.expect_failure('dpslam', 'Laser 3 1 2.0.1 3\n', 'bad.dpslam:1:', '2.0.1')

    def test_failure_keeps_an_existing_bag_untouched_and_removes_nothing_else(self):
        out = self.path('keep.bag')
        with open(out, 'w') as f:
            f.write('old')
        src = self.write('bad.dpslam', 'Laser 3 1 2\n')
        code, _, _ = run('--format', 'dpslam', src, out)
        self.assertNotEqual(code, 0)
        with open(out) as f:
            self.assertEqual(f.read(), 'old')

    # ---- real logs (optional) --------------------------------------------------------------------------
    def real(self, fmt, rel, scans, beams, first_stamp):
        src = os.path.join(DATASETS, rel)
        if not os.path.exists(src):
            raise unittest.SkipTest('%s not found (shared/datasets is optional)' % src)
        out = self.path('real.bag')
        code, stdout, err = run('--format', fmt, src, out)
        self.assertEqual(code, 0, err)
        with rosbag.Bag(out) as bag:
            info = bag.get_type_and_topic_info().topics
            self.assertEqual(info['/scan'].message_count, scans)
            self.assertEqual(info['/tf_static'].message_count, 1)
            self.assertEqual(info['/wheel_odom'].message_count, scans)
            first = next(bag.read_messages(topics=['/scan']))[1]
        self.assertEqual(len(first.ranges), beams)
        self.assertEqual((first.header.stamp.secs, first.header.stamp.nsecs), first_stamp)
        return first

    def test_real_mit_csail(self):
        s = self.real('carmen', 'mit-csail/mit-csail.clf', 1988, 361, (1134864629, 895182000))
        self.assertAlmostEqual(s.ranges[0], 1.40, places=5)
        self.assertEqual(s.ranges[24], INF)  # 81.91 in the log

    def test_real_mines_exp2(self):
        self.real('mines', 'urg04lx-mines/exp2.dat', 641, 682, (361, 431443000))

    def test_real_dpslam_loop5(self):
        s = self.real('dpslam', 'dpslam-loop5/loop5.log', 551, 181, (0, 0))
        self.assertAlmostEqual(s.ranges[0], 0.642, places=5)


if __name__ == '__main__':
    unittest.main()
