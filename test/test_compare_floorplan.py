"""tools/compare_floorplan on maps made from the bundled floor plan by known rigid transforms and edits."""
import json
import math
import os
import shutil
import subprocess
import tempfile
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
TOOL = os.path.join(HERE, '..', 'tools', 'compare_floorplan')
PLAN = os.path.join(HERE, '..', 'plans', 'office.yaml')
OCC, FREE, UNKNOWN = 0, 254, 205


def run(*args):
    p = subprocess.run(['/usr/bin/python3', TOOL] + list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       universal_newlines=True)
    return p.returncode, p.stdout, p.stderr


def read_pgm(path):
    with open(path, 'rb') as f:
        data = f.read()
    toks, pos = [], 0
    while len(toks) < 4:
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b'#':
            pos = data.index(b'\n', pos)
            continue
        start = pos
        while not data[pos:pos + 1].isspace():
            pos += 1
        toks.append(data[start:pos])
    w, h = int(toks[1]), int(toks[2])
    return np.frombuffer(data, np.uint8, w * h, pos + 1).reshape(h, w).copy()


def write_map(directory, name, img, res, origin, ascii_pgm=False):
    """img: rows top (max y) first, as map_server stores it."""
    h, w = img.shape
    with open(os.path.join(directory, name + '.pgm'), 'wb') as f:
        if ascii_pgm:
            f.write(b'P2\n# test\n%d %d\n255\n' % (w, h))
            for row in img:
                f.write((' '.join(str(int(v)) for v in row) + '\n').encode())
        else:
            f.write(b'P5\n# test\n%d %d\n255\n' % (w, h))
            f.write(img.astype(np.uint8).tobytes())
    path = os.path.join(directory, name + '.yaml')
    with open(path, 'w') as f:
        f.write('image: %s.pgm\nresolution: %.6f\norigin: [%.6f, %.6f, 0.0]\nnegate: 0\n'
                'occupied_thresh: 0.65\nfree_thresh: 0.196\n' % (name, res, origin[0], origin[1]))
    return path


def plan_image():
    return read_pgm(os.path.join(HERE, '..', 'plans', 'office.pgm')), 0.05, (0.0, 0.0)


def transformed_copy(img, res, origin, angle, t, new_res, new_origin_offset=(0.0, 0.0)):
    """A map whose frame relates to the plan's by p_plan = R(angle) p_map + t, sampled (nearest cell) at
    new_res. Returns (img, origin)."""
    h, w = img.shape
    c, s = math.cos(angle), math.sin(angle)
    corners = np.array([[origin[0], origin[1]], [origin[0] + w * res, origin[1]],
                        [origin[0], origin[1] + h * res], [origin[0] + w * res, origin[1] + h * res]])
    inv = (corners - t) @ np.array([[c, -s], [s, c]])  # R^T (p - t), row-wise
    lo = inv.min(axis=0) - 1.0 + np.array(new_origin_offset)
    hi = inv.max(axis=0) + 1.0
    nw, nh = [int(math.ceil(v)) for v in (hi - lo) / new_res]
    iy, ix = np.mgrid[0:nh, 0:nw]
    mx, my = lo[0] + (ix + 0.5) * new_res, lo[1] + (iy + 0.5) * new_res
    px, py = c * mx - s * my + t[0], s * mx + c * my + t[1]
    cx = np.floor((px - origin[0]) / res).astype(int)
    cy = np.floor((py - origin[1]) / res).astype(int)
    inside = (cx >= 0) & (cy >= 0) & (cx < w) & (cy < h)
    out = np.full((nh, nw), UNKNOWN, dtype=np.uint8)  # row 0 = min y here
    flipped = img[::-1]
    out[inside] = flipped[cy[inside], cx[inside]]
    return out[::-1], (float(lo[0]), float(lo[1]))


def surfaces_only(img):
    """Keeps only the occupied cells with a free 4-neighbour (what a laser sees); the rest of the walls
    become unknown."""
    occ, free = img == OCC, img == FREE
    nb = np.zeros_like(free)
    nb[1:] |= free[:-1]
    nb[:-1] |= free[1:]
    nb[:, 1:] |= free[:, :-1]
    nb[:, :-1] |= free[:, 1:]
    out = img.copy()
    out[occ & ~nb] = UNKNOWN
    return out


class CompareFloorplanTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp()

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def compare(self, map_path, *extra):
        code, out, err = run('--map', map_path, '--floorplan', PLAN, *extra)
        self.assertEqual(code, 0, err)
        r = json.loads(out)
        for k in ('transform', 'precision', 'recall', 'f1'):
            self.assertIn(k, r)
        return r

    def assert_transform(self, r, angle, t, tol_m=0.03, tol_deg=0.3):
        tr = r['transform']
        self.assertLess(abs(math.remainder(math.radians(tr['theta_deg']) - angle, 2 * math.pi)),
                        math.radians(tol_deg), tr)
        self.assertLess(math.hypot(tr['x'] - t[0], tr['y'] - t[1]), tol_m, tr)

    def test_plan_against_itself(self):
        png = os.path.join(self.dir, 'out', 'overlay.png')
        r = self.compare(PLAN, '--out', png)
        self.assertEqual(r['precision'], 1.0)
        self.assertEqual(r['recall'], 1.0)
        self.assertEqual(r['f1'], 1.0)
        self.assert_transform(r, 0.0, (0.0, 0.0), 1e-6, 1e-4)
        with open(png, 'rb') as f:
            self.assertEqual(f.read(8), b'\x89PNG\r\n\x1a\n')
        self.assertEqual(r['overlay'], png)

    def test_rotated_and_shifted_copy_is_realigned(self):
        img, res, origin = plan_image()
        angle, t = math.radians(37.0), np.array([4.3, -2.1])
        copy, corigin = transformed_copy(img, res, origin, angle, t, res, (0.013, -0.021))
        path = write_map(self.dir, 'moved', copy, res, corigin)
        r = self.compare(path)
        self.assert_transform(r, angle, t, 0.05, 0.5)
        self.assertGreater(r['precision'], 0.97)
        self.assertGreater(r['recall'], 0.97)

    def test_laser_like_map_at_another_resolution(self):
        # Only the wall surfaces, rotated by 200 deg, sampled at 0.04 m, written as an ASCII PGM.
        img, res, origin = plan_image()
        angle, t = math.radians(200.0), np.array([-7.0, 12.5])
        copy, corigin = transformed_copy(surfaces_only(img), res, origin, angle, t, 0.04)
        path = write_map(self.dir, 'laser', copy, 0.04, corigin, ascii_pgm=True)
        r = self.compare(path)
        self.assert_transform(r, angle, t, 0.05, 0.5)
        self.assertGreater(r['precision'], 0.97)
        self.assertGreater(r['recall'], 0.9)

    def test_spurious_walls_lower_the_precision(self):
        img, res, origin = plan_image()
        spurious = img.copy()
        rng = np.random.RandomState(5)
        free_rows, free_cols = np.nonzero(img == FREE)
        added = 0
        while added < 1500:  # 15-cell blobs (3 x 5) in free space, away from the walls
            k = rng.randint(len(free_rows))
            r0, c0 = free_rows[k], free_cols[k]
            window = img[max(r0 - 6, 0):r0 + 9, max(c0 - 6, 0):c0 + 11]
            if (window != FREE).any():
                continue
            spurious[r0:r0 + 3, c0:c0 + 5] = OCC
            added += 15
        path = write_map(self.dir, 'spurious', spurious, res, origin)
        r = self.compare(path)
        n_occ = int(np.count_nonzero(img == OCC))
        expected = n_occ / float(np.count_nonzero(spurious == OCC))
        self.assertAlmostEqual(r['precision'], expected, delta=0.01)
        self.assertLess(r['precision'], 0.95)
        self.assertGreater(r['recall'], 0.99)
        self.assert_transform(r, 0.0, (0.0, 0.0), 0.02, 0.2)

    def test_partial_map_lowers_the_recall_only(self):
        # Only the western 40 % of the plan was mapped (the rest unknown).
        img, res, origin = plan_image()
        part = img.copy()
        part[:, int(0.4 * img.shape[1]):] = UNKNOWN
        path = write_map(self.dir, 'part', part, res, origin)
        r = self.compare(path)
        self.assertGreater(r['precision'], 0.99)
        self.assertLess(r['recall'], 0.6)
        self.assertGreater(r['recall_explored'], 0.95)

    def test_bad_input(self):
        code, out, err = run('--map', os.path.join(self.dir, 'missing.yaml'), '--floorplan', PLAN)
        self.assertEqual(code, 1)
        self.assertIn('missing.yaml', err)
        bad = os.path.join(self.dir, 'bad.yaml')
        with open(bad, 'w') as f:
            f.write('image: bad.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n')
        with open(os.path.join(self.dir, 'bad.pgm'), 'wb') as f:
            f.write(b'P6\n2 2\n255\n' + b'\0' * 12)
        code, out, err = run('--map', bad, '--floorplan', PLAN)
        self.assertEqual(code, 1)
        self.assertIn('bad.pgm', err)
        self.assertIn('not a PGM', err)
        with open(os.path.join(self.dir, 'bad.pgm'), 'wb') as f:
            f.write(b'P5\n4 4\n255\n' + b'\0' * 5)
        code, out, err = run('--map', bad, '--floorplan', PLAN)
        self.assertEqual(code, 1)
        self.assertIn('truncated', err)
        with open(bad, 'w') as f:
            f.write('image: bad.pgm\norigin: [0, 0, 0]\n')
        code, out, err = run('--map', bad, '--floorplan', PLAN)
        self.assertEqual(code, 1)
        self.assertIn("missing key 'resolution'", err)
        empty = write_map(self.dir, 'empty', np.full((20, 20), FREE, dtype=np.uint8), 0.05, (0, 0))
        code, out, err = run('--map', empty, '--floorplan', PLAN)
        self.assertEqual(code, 1)
        self.assertIn('no occupied cells', err)
        for e in (err,):
            self.assertNotIn('Traceback', e)


if __name__ == '__main__':
    unittest.main()
