#!/usr/bin/python3
"""Draws the bundled floor plans (map_server PGM + YAML) and their built-in paths.

    scripts/make_floorplans.py [OUT_DIR]     (default: plans/ next to this script's parent)

Writes, for each plan NAME: NAME.pgm, NAME.yaml, NAME_loop.txt and NAME_explore.txt (waypoints, one
`x y` per line, metres in the map frame; `simulate_scans --path loop` uses NAME_loop.txt).

* office: an office floor 20 m x 12 m: a 2 m corridor along x with 5 rooms north and 4 south, doors
  off the corridor, two doors between neighbouring rooms, furniture boxes and two pillars.
* loop_building: a 30 m x 20 m building with a 2.5 m corridor running around a central block; niches
  in the block, pillars on the outer wall and one side room, irregularly spaced so that the corridor
  is not featureless or periodic.

Everything is kept within the URG-04LX's 5.6 m: corridors <= 3 m wide, rooms about 4 m across.
Only python3 + numpy. The drawing is in metres; all coordinates are multiples of the resolution.
"""
import os
import sys

import numpy as np

RES = 0.05
OCCUPIED, FREE, UNKNOWN = 0, 254, 205
WALL = 0.15  # m, interior walls


class Plan:
    def __init__(self, width_m, height_m, origin=(0.0, 0.0)):
        self.ox, self.oy = origin
        self.w = int(round(width_m / RES))
        self.h = int(round(height_m / RES))
        self.img = np.full((self.h, self.w), UNKNOWN, dtype=np.uint8)

    def rect(self, x0, y0, x1, y1, value):
        """Fills [x0, x1] x [y0, y1] (metres, map frame). Image row 0 is the top (max y)."""
        ix0 = int(round((min(x0, x1) - self.ox) / RES))
        ix1 = int(round((max(x0, x1) - self.ox) / RES))
        iy0 = int(round((min(y0, y1) - self.oy) / RES))
        iy1 = int(round((max(y0, y1) - self.oy) / RES))
        ix0, ix1 = max(ix0, 0), min(ix1, self.w)
        iy0, iy1 = max(iy0, 0), min(iy1, self.h)
        if ix1 > ix0 and iy1 > iy0:
            self.img[self.h - iy1:self.h - iy0, ix0:ix1] = value

    def wall(self, x0, y0, x1, y1):
        self.rect(x0, y0, x1, y1, OCCUPIED)

    def free(self, x0, y0, x1, y1):
        self.rect(x0, y0, x1, y1, FREE)

    def save(self, out_dir, name):
        pgm = os.path.join(out_dir, name + ".pgm")
        with open(pgm, "wb") as f:
            f.write(b"P5\n# laser_dpslam floor plan '%s' (scripts/make_floorplans.py)\n" % name.encode())
            f.write(b"%d %d\n255\n" % (self.w, self.h))
            f.write(self.img.tobytes())
        with open(os.path.join(out_dir, name + ".yaml"), "w") as f:
            f.write("image: %s.pgm\n" % name)
            f.write("resolution: %.3f\n" % RES)
            f.write("origin: [%.3f, %.3f, 0.0]\n" % (self.ox, self.oy))
            f.write("negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")


def write_waypoints(out_dir, name, comment, points):
    with open(os.path.join(out_dir, name + ".txt"), "w") as f:
        for line in comment.strip().splitlines():
            f.write("# %s\n" % line)
        f.write("# x y (metres, map frame)\n")
        for x, y in points:
            f.write("%.2f %.2f\n" % (x, y))


def office(out_dir):
    p = Plan(20.0, 12.0)
    # Building shell: outer wall 0.2 m, interior [0.7, 19.3] x [0.7, 11.3].
    p.wall(0.5, 0.5, 19.5, 11.5)
    p.free(0.7, 0.7, 19.3, 11.3)
    # Corridor y in [5.0, 7.0]: south wall [4.85, 5.0], north wall [7.0, 7.15].
    p.wall(0.7, 4.85, 19.3, 5.0)
    p.wall(0.7, 7.0, 19.3, 7.15)
    # North rooms N1..N5 (y 7.15..11.3) and south rooms S1..S4 (y 0.7..4.85).
    for x in (4.5, 8.5, 12.5, 16.0):
        p.wall(x, 7.15, x + WALL, 11.3)
    for x in (5.5, 10.0, 14.5):
        p.wall(x, 0.7, x + WALL, 4.85)
    # Doors (1 m) off the corridor.
    for x0 in (3.0, 5.2, 10.8, 13.2, 17.5):  # N1..N5
        p.free(x0, 7.0, x0 + 1.0, 7.15)
    for x0 in (3.8, 8.2, 10.8, 15.5):  # S1..S4
        p.free(x0, 4.85, x0 + 1.0, 5.0)
    # Doors between rooms: N2-N3 and S2-S3.
    p.free(8.5, 8.4, 8.65, 9.4)
    p.free(10.0, 3.0, 10.15, 4.0)
    # Corridor features: two pillars and a bench.
    p.wall(9.6, 6.8, 9.9, 7.0)
    p.wall(14.8, 5.0, 15.1, 5.25)
    p.wall(17.0, 5.0, 18.0, 5.4)
    # Furniture.
    boxes = [
        (0.9, 10.5, 2.3, 11.3), (0.7, 7.5, 1.2, 8.5),                   # N1: desk, cabinet
        (6.3, 10.0, 7.3, 10.8), (4.65, 9.8, 5.05, 11.3),                # N2: table, shelf
        (9.0, 10.6, 10.4, 11.3), (12.0, 9.6, 12.5, 11.0), (9.2, 7.15, 9.8, 7.6),  # N3
        (14.5, 10.6, 15.9, 11.3), (13.3, 9.8, 14.1, 10.6),              # N4: desk, table
        (18.8, 8.0, 19.3, 10.0), (16.4, 10.7, 17.6, 11.3),              # N5: cabinet, desk
        (0.9, 0.7, 2.3, 1.4), (4.9, 0.9, 5.5, 2.9),                     # S1: desk, sofa
        (6.0, 0.7, 7.4, 1.4), (8.0, 0.7, 9.4, 1.4),                     # S2: desks
        (12.5, 1.2, 13.7, 2.2), (14.0, 3.0, 14.5, 4.5),                 # S3: table, cabinet
        (17.5, 0.7, 19.1, 1.4), (15.0, 0.9, 15.6, 1.5),                 # S4: desk, box
    ]
    for b in boxes:
        p.wall(*b)
    p.save(out_dir, "office")

    write_waypoints(out_dir, "office_loop", """
office: a closed loop (about 100 s at Create speeds) from the corridor through rooms N2 and N3 (by the
door between them), across the corridor through S3 and S2, and back along the corridor to the start.
The bundled bags/demo.bag drives it once (scripts/make_demo_bag.sh).""", [
        (4.5, 6.0), (5.7, 6.0), (5.7, 8.9), (11.3, 8.9), (11.3, 3.5), (8.7, 3.5), (8.7, 6.0), (4.5, 6.0)])
    write_waypoints(out_dir, "office_explore", """
office: an exploration run (open path) visiting rooms N1, S1, N4, N5 and S4 off the corridor.""", [
        (2.0, 6.0), (3.5, 6.0), (3.5, 9.0), (2.0, 9.0), (3.5, 9.0), (3.5, 6.0), (4.3, 6.0), (4.3, 2.5),
        (2.0, 2.5), (4.3, 2.5), (4.3, 6.0), (13.7, 6.0), (13.7, 9.0), (13.7, 6.0), (18.0, 6.0), (18.0, 9.5),
        (18.0, 6.0), (16.0, 6.0), (16.0, 2.5), (18.0, 2.5)])


def loop_building(out_dir):
    p = Plan(31.0, 21.0)
    # Shell: outer wall 0.2 m, interior [0.7, 30.3] x [0.7, 20.3].
    p.wall(0.5, 0.5, 30.5, 20.5)
    p.free(0.7, 0.7, 30.3, 20.3)
    # Central block [3.2, 27.8] x [3.2, 17.8] (0.2 m walls, unknown inside): 2.5 m corridors around it.
    p.wall(3.2, 3.2, 27.8, 17.8)
    p.rect(3.4, 3.4, 27.6, 17.6, UNKNOWN)
    # Niches into the block (x0, x1 or y0, y1; depth).
    for x0, x1, d in ((6.0, 7.5, 0.8), (13.0, 14.0, 0.5), (21.5, 23.5, 1.0)):  # south face
        p.wall(x0 - 0.2, 3.2, x1 + 0.2, 3.2 + d + 0.2)
        p.free(x0, 3.2, x1, 3.2 + d)
    for x0, x1, d in ((5.0, 6.0, 0.6), (11.5, 13.5, 0.8), (24.0, 25.5, 0.5)):  # north face
        p.wall(x0 - 0.2, 17.8 - d - 0.2, x1 + 0.2, 17.8)
        p.free(x0, 17.8 - d, x1, 17.8)
    for y0, y1, d in ((8.0, 9.5, 0.8),):  # west face
        p.wall(3.2, y0 - 0.2, 3.2 + d + 0.2, y1 + 0.2)
        p.free(3.2, y0, 3.2 + d, y1)
    for y0, y1, d in ((6.0, 7.0, 0.6), (12.0, 14.0, 0.9)):  # east face
        p.wall(27.8 - d - 0.2, y0 - 0.2, 27.8, y1 + 0.2)
        p.free(27.8 - d, y0, 27.8, y1)
    # A side room in the block, door on the east corridor.
    p.wall(23.0, 8.5, 27.8, 11.5)
    p.free(23.2, 8.7, 27.6, 11.3)
    p.free(27.6, 9.5, 27.8, 10.5)
    p.wall(23.6, 10.6, 24.6, 11.3)  # a desk in it
    # Pillars (0.4 m) on the outer wall.
    for x in (10.0, 17.5, 25.0):
        p.wall(x, 0.7, x + 0.4, 1.1)
    for x in (8.5, 16.0, 20.0):
        p.wall(x, 19.9, x + 0.4, 20.3)
    p.wall(0.7, 13.0, 1.1, 13.4)
    p.wall(29.9, 4.5, 30.3, 4.9)
    p.save(out_dir, "loop_building")

    write_waypoints(out_dir, "loop_building_loop", """
loop_building: one counter-clockwise lap of the corridor around the central block (about 88 m,
about 5 minutes at Create speeds), back to the start.""", [
        (15.0, 1.95), (29.05, 1.95), (29.05, 19.05), (1.95, 19.05), (1.95, 1.95), (15.0, 1.95)])
    write_waypoints(out_dir, "loop_building_explore", """
loop_building: an open path along the south and east corridors, into the side room and out, and on
along the north corridor (no loop closure).""", [
        (15.0, 1.95), (29.05, 1.95), (29.05, 10.0), (24.5, 10.0), (29.05, 10.0), (29.05, 19.05),
        (15.0, 19.05)])


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    out_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(root, "plans")
    os.makedirs(out_dir, exist_ok=True)
    office(out_dir)
    loop_building(out_dir)
    print("wrote office and loop_building plans to %s" % out_dir)


if __name__ == "__main__":
    main()
