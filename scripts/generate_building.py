#!/usr/bin/env python3
"""Draws a random indoor building and a path through it, for the simulator (simulate_scans) and the
benchmark over buildings (scripts/benchmark_buildings.sh). The same seed gives the same building.

    generate_building.py --seed N --out DIR [--family ring|grid|hall|deadend|blank] [--range 5.6]

A building is a ring of corridors (1.2-4 m wide, each its own width) around blocks of offices; the family
adds to it: `grid` cross corridors, `hall` a hall with pillars and furniture on one side, `deadend` a
dead-end corridor the path drives into and back out of, `blank` one side 2-8 x the laser range long with
nothing along it. Every family has rooms with and without doors and niches in the outer walls, so that
some corridor stretches have something in view and some have nothing. The whole building is then turned
by a random angle and shifted off any lattice. The family defaults to one of the five by the seed.

The path is one lap of the ring (through the dead end, the hall, the cross corridors) and on around the
first side(s) again, so that the SLAM can close the loop on a revisit. Two flavours:
  path_laser.txt   stops, dwells and speed changes only where a surface facing along the travel is in view
                   within the laser's 240 degrees, arriving and driving off (corners, junctions); a dead end
                   is left where the corridor it opens into is in view ahead; constant speed through blank
                   stretches
  path_wheels.txt  the same route, plus stops (2-8 s) and speed changes inside the blank stretches, which
                   only wheel odometry can measure
"Blank": a point of the path from which no corner, door jamb, pillar or piece of furniture is within the
laser range with a clear line of sight (only straight parallel walls are in view).

Writes DIR/plan.txt (geometry: the VectorPlan format, doc/simulation.md), DIR/plan.yaml + plan.pgm (the same
plan rasterised at 5 cm for compare_floorplan: free space 254, walls and solid mass 0), DIR/path_laser.txt,
DIR/path_wheels.txt (`x y pause_s speed_mps`) and DIR/meta.json (seed, family, angle, path lengths, blank
stretches).
"""
import argparse
import json
import math
import os
import random
import sys

import numpy as np
from matplotlib.path import Path as MplPath

FAMILIES = ["ring", "grid", "hall", "deadend", "blank"]
WALL = 0.15        # m, thickness of the wall mass between corridor and rooms
ROBOT = 0.17       # m, the Create's radius
SPEEDS = [0.2, 0.25, 0.3, 0.35, 0.4]  # m/s


class Building:
    """Free space as a union of axis-aligned rectangles (building frame), plus solid pillars and furniture."""

    def __init__(self):
        self.free = []       # (x0, y0, x1, y1)
        self.circles = []    # (cx, cy, r)
        self.polygons = []   # [(x, y), ...]

    def add(self, x0, y0, x1, y1):
        self.free.append((min(x0, x1), min(y0, y1), max(x0, x1), max(y0, y1)))

    def walls(self):
        """The boundary of the free space as maximal straight segments."""
        xs = sorted({round(v, 9) for r in self.free for v in (r[0], r[2])})
        ys = sorted({round(v, 9) for r in self.free for v in (r[1], r[3])})
        cx = [(a + b) / 2 for a, b in zip(xs, xs[1:])]
        cy = [(a + b) / 2 for a, b in zip(ys, ys[1:])]
        free = np.zeros((len(cx) + 2, len(cy) + 2), bool)  # padded by a solid border
        for i, x in enumerate(cx):
            for j, y in enumerate(cy):
                free[i + 1, j + 1] = any(r[0] < x < r[2] and r[1] < y < r[3] for r in self.free)
        segs = []
        for i, x in enumerate(xs):  # vertical edges on x = xs[i]: between cells i-1 and i (padded i, i+1)
            segs += merge_runs([free[i, j + 1] != free[i + 1, j + 1] and (1 if free[i + 1, j + 1] else 2)
                                for j in range(len(cy))], ys, lambda a, b, x=x: ((x, a), (x, b)))
        for j, y in enumerate(ys):
            segs += merge_runs([free[i + 1, j] != free[i + 1, j + 1] and (1 if free[i + 1, j + 1] else 2)
                                for i in range(len(cx))], xs, lambda a, b, y=y: ((a, y), (b, y)))
        return segs

    def is_free(self, x, y):
        """Vectorised: whether points (arrays) lie in free space (not in a wall, pillar or furniture)."""
        f = np.zeros(x.shape, bool)
        for x0, y0, x1, y1 in self.free:
            f |= (x > x0) & (x < x1) & (y > y0) & (y < y1)
        for cx, cy, r in self.circles:
            f &= (x - cx) ** 2 + (y - cy) ** 2 > r * r
        pts = np.stack([x.ravel(), y.ravel()], 1)
        for poly in self.polygons:
            f &= ~MplPath(poly).contains_points(pts).reshape(x.shape)
        return f


def merge_runs(flags, coords, make):
    """Consecutive edges with the same free side (flag 1 or 2) joined into one segment."""
    out, start = [], None
    for k, f in enumerate(flags + [False]):
        if start is not None and f != flags[start]:
            out.append(make(coords[start], coords[k]))
            start = None
        if f and start is None:
            start = k
    return out


class Layout:
    """Corridor centrelines of a ring (0..W x 0..H) with per-corridor widths, and what hangs off it."""

    def __init__(self, rng, family, rng_range):
        self.rng, self.family, self.range = rng, family, rng_range
        if family == "blank":
            self.W = rng.uniform(2.0, 8.0) * rng_range  # plus the side corridors, below
            self.H = rng.uniform(6.0, 10.0)
        else:
            self.W, self.H = rng.uniform(14.0, 22.0), rng.uniform(8.0, 13.0)
        self.width = {k: rng.uniform(1.2, 4.0) for k in ("bottom", "top", "left", "right")}
        if family == "blank":  # the stretch between the openings of the side corridors is 2-8 x the range
            self.W += (self.width["left"] + self.width["right"]) / 2
        self.cross = []
        if family == "grid" or (family == "ring" and rng.random() < 0.2):
            n = 1 if self.W < 18 or rng.random() < 0.5 else 2
            self.cross = sorted(rng.uniform(0.3, 0.7) * self.W if n == 1 else (k + rng.uniform(0.7, 1.3)) * self.W / 3
                                for k in range(n))
            self.cross_width = [rng.uniform(1.2, 3.0) for _ in self.cross]
        self.spur = None
        if family == "deadend":
            self.spur = (rng.uniform(0.3, 0.7) * self.W, rng.uniform(6.0, 20.0), rng.uniform(1.2, 2.5))
        self.hall = None
        if family == "hall":
            hw = rng.uniform(8.0, min(14.0, self.W - 4.0))
            x0 = rng.uniform(2.0, self.W - 2.0 - hw)
            self.hall = (x0, x0 + hw, rng.uniform(5.0, 9.0))

    def corridors(self, b):
        W, H, w = self.W, self.H, self.width
        b.add(-w["left"] / 2, -w["bottom"] / 2, W + w["right"] / 2, w["bottom"] / 2)
        b.add(-w["left"] / 2, H - w["top"] / 2, W + w["right"] / 2, H + w["top"] / 2)
        b.add(-w["left"] / 2, -w["bottom"] / 2, w["left"] / 2, H + w["top"] / 2)
        b.add(W - w["right"] / 2, -w["bottom"] / 2, W + w["right"] / 2, H + w["top"] / 2)
        for x, cw in zip(self.cross, getattr(self, "cross_width", [])):
            b.add(x - cw / 2, 0.0, x + cw / 2, H)
        if self.spur:
            x, length, sw = self.spur
            b.add(x - sw / 2, -length, x + sw / 2, 0.0)
        if self.hall:
            x0, x1, depth = self.hall
            b.add(x0, H, x1, H + w["top"] / 2 + depth)

    def blocks(self):
        """The office blocks between the corridors: (x0, x1) spans, y from bottom to top corridor."""
        edges = [self.width["left"] / 2] + sum(([x - cw / 2, x + cw / 2] for x, cw in
                                               zip(self.cross, getattr(self, "cross_width", []))), []) + \
                [self.W - self.width["right"] / 2]
        return [(edges[k] + WALL, edges[k + 1] - WALL) for k in range(0, len(edges), 2)]

    def rooms(self, b):
        """Rows of offices along the bottom and top corridors; some with a door, some without."""
        rng, W, H = self.rng, self.W, self.H
        y_lo, y_hi = self.width["bottom"] / 2 + WALL, H - self.width["top"] / 2 - WALL
        if y_hi - y_lo < 2.0:
            return  # too shallow for offices: a solid block
        blank_bottom = self.family == "blank"
        mid = (y_lo + y_hi) / 2
        for x0, x1 in self.blocks():
            for row, (r0, r1) in (("bottom", (y_lo, mid - WALL / 2)), ("top", (mid + WALL / 2, y_hi))):
                x = x0
                while x1 - x > 2.5:
                    xr = min(x1, x + rng.uniform(2.5, 5.0))
                    if x1 - xr < 2.5:
                        xr = x1
                    b.add(x, r0, xr, r1)
                    door_p = 0.0 if (blank_bottom and row == "bottom") else 0.55
                    if self.hall and row == "top" and xr > self.hall[0] - 1 and x < self.hall[1] + 1:
                        door_p = 0.3
                    if rng.random() < door_p and xr - x > 1.6:
                        d = rng.uniform(x + 0.3, xr - 1.2)
                        if row == "bottom":
                            b.add(d, y_lo - WALL - 0.01, d + 0.9, r0 + 0.01)
                        else:
                            b.add(d, r1 - 0.01, d + 0.9, y_hi + WALL + 0.01)
                    x = xr + WALL

    def niches(self, b):
        """Recesses in the outer walls: features along an otherwise blank corridor."""
        rng, W, H, w = self.rng, self.W, self.H, self.width
        sides = ["top", "left", "right"] + ([] if self.family == "blank" else ["bottom"])
        for side in sides:
            for _ in range(rng.randint(0, 2)):
                depth, size = rng.uniform(0.3, 0.8), rng.uniform(0.8, 2.0)
                if side in ("bottom", "top"):
                    x = rng.uniform(1.0, W - 1.0 - size)
                    if side == "top" and self.hall and x + size > self.hall[0] - 0.5 and x < self.hall[1] + 0.5:
                        continue
                    if side == "bottom" and self.spur and abs(x + size / 2 - self.spur[0]) < size / 2 + self.spur[2]:
                        continue
                    y = -w["bottom"] / 2 if side == "bottom" else H + w["top"] / 2
                    b.add(x, y, x + size, y - depth if side == "bottom" else y + depth)
                else:
                    y = rng.uniform(1.0, H - 1.0 - size)
                    x = -w["left"] / 2 if side == "left" else W + w["right"] / 2
                    b.add(x, y, x - depth if side == "left" else x + depth, y + size)

    def hall_contents(self, b):
        """Pillars on a grid and furniture (turned boxes) in the hall, clear of the path along y = H."""
        if not self.hall:
            return
        rng, H = self.rng, self.H
        x0, x1, depth = self.hall
        y_top = H + self.width["top"] / 2 + depth
        keep = H + 0.9 + ROBOT  # nothing below this: the path runs along y = H
        pitch = rng.uniform(2.5, 4.0)
        r = rng.uniform(0.1, 0.3)
        x = x0 + pitch / 2
        while x < x1 - 0.5:
            y = keep + r + 0.3
            while y < y_top - 0.8:
                b.circles.append((x, y, r))
                y += pitch
            x += pitch
        for _ in range(rng.randint(2, 5)):
            sx, sy, a = rng.uniform(0.4, 1.5), rng.uniform(0.4, 1.0), rng.uniform(0, math.pi)
            cx, cy = rng.uniform(x0 + 1.0, x1 - 1.0), rng.uniform(keep + 1.0, y_top - 1.0)
            if cy - 0.9 < keep or any(math.hypot(cx - px, cy - py) < pr + 1.0 for px, py, pr in b.circles):
                continue
            c, s = math.cos(a), math.sin(a)
            b.polygons.append([(cx + c * u - s * v, cy + s * u + c * v) for u, v in
                               ((-sx / 2, -sy / 2), (sx / 2, -sy / 2), (sx / 2, sy / 2), (-sx / 2, sy / 2))])

    def route(self):
        """Waypoints (building frame): a lap from a random corner, into the dead end, on over the first
        side(s) again; a grid adds a pass through each cross corridor."""
        rng, W, H = self.rng, self.W, self.H
        ring = [(0.0, 0.0), (W, 0.0), (W, H), (0.0, H)]
        if rng.random() < 0.5:
            ring.reverse()
        k = rng.randrange(4)
        ring = ring[k:] + ring[:k]
        pts = [ring[0]]
        for corner in ring[1:] + [ring[0]]:
            a = pts[-1]
            if self.spur and a[1] == 0.0 and corner[1] == 0.0:  # the bottom side: drive into the dead end
                x, length, sw = self.spur
                pts += [(x, 0.0), (x, -length + sw / 2 + 0.6), (x, 0.0)]
            pts.append(corner)
        lap = sum(math.dist(a, b) for a, b in zip(pts, pts[1:]))
        revisit = 0.0
        for corner in ring[1:] + [ring[0]]:  # at least one side again, and on until the path is 80 m
            revisit += math.dist(pts[-1], corner)
            pts.append(corner)
            if revisit >= 8.0 and lap + revisit >= 80.0:
                break
        for x in self.cross:  # down and up each cross corridor, back on the ring
            near = min(((0.0, 0.0), (0.0, H), (W, 0.0), (W, H)), key=lambda c: math.dist(c, pts[-1]))
            y0 = near[1]
            if pts[-1] != near:
                pts.append(near)
            pts += [(x, y0), (x, H - y0)]
            pts.append((W if near[0] == 0.0 else 0.0, H - y0) if rng.random() < 0.5 else (near[0], H - y0))
        return pts


def visible_features(segs, circles, polygons):
    """Points the laser can place itself by: wall ends (corners, door jambs), pillars, furniture corners."""
    ends = {}
    for a, b in segs:
        for p in (a, b):
            ends[p] = ends.get(p, 0) + 1
    pts = list(ends) + [(c[0], c[1]) for c in circles] + [v for poly in polygons for v in poly]
    return np.array(pts)


def _within_fov(p, q, heading, half_fov):
    """Whether the point q (or each row of an array of points) lies within half_fov of the heading from p."""
    q = np.asarray(q)
    bearing = np.arctan2(q[..., 1] - p[1], q[..., 0] - p[0]) - heading
    return np.abs(np.arctan2(np.sin(bearing), np.cos(bearing))) <= half_fov


def _clear(p, q, seg_a, seg_b):
    """No wall between p and q (q itself may lie on one)."""
    r = q - p
    e = seg_b - seg_a
    den = r[0] * e[:, 1] - r[1] * e[:, 0]
    f = seg_a - p
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (f[:, 0] * e[:, 1] - f[:, 1] * e[:, 0]) / den
        u = (f[:, 0] * r[1] - f[:, 1] * r[0]) / den
    return not ((np.abs(den) > 1e-12) & (t > 1e-6) & (t < 1 - 1e-4) & (u >= 0) & (u <= 1)).any()


def in_view(p, feats, seg_a, seg_b, rng_range, heading=None, half_fov=math.radians(120.0)):
    """Whether any feature lies within range of p with a clear line of sight and, given the robot's heading,
    within the laser's field of view (the URG-04LX's 240 degrees: a wall end behind the robot is not seen)."""
    d = np.hypot(feats[:, 0] - p[0], feats[:, 1] - p[1])
    near = d <= rng_range
    if heading is not None:
        near &= _within_fov(p, feats, heading, half_fov)
    return any(_clear(p, q, seg_a, seg_b) for q in feats[near])


def heading(a, b):
    return math.atan2(b[1] - a[1], b[0] - a[0])


FACING_ANGLE = math.radians(60.0)  # a surface within 30 deg of square to the travel tells the motion along it
FACING_MIN = 0.5                   # m of such surface in one piece (see facing_in_view)
LASER_X = 0.1                      # m, the laser ahead of the robot's centre (simulate_scans' default mount)
SAMPLE = 0.05                      # m between the points a wall is checked at


def facing_in_view(p, heading, circles, seg_a, seg_b, rng_range, half_fov=math.radians(120.0)):
    """Whether the laser on the robot at p, facing `heading`, sees something that fixes its position along
    that heading: a pillar, or a piece of wall FACING_MIN long and more than FACING_ANGLE off the heading,
    within range, within the field of view and with a clear line of sight. A piece that long leaves a
    scan matcher a surface whose direction it can fit away from the piece's ends (where an occluding edge
    or the field of view cuts it). A wall's end seen edge-on (the mouth of a corridor ahead, a door jamb in
    a side wall) does not count: it ends a grazing run of returns, and neither a scan match nor the
    odometry's blank test can place the robot along the corridor by it."""
    p = np.asarray(p, dtype=float) + LASER_X * np.array([math.cos(heading), math.sin(heading)])
    for cx, cy, r in circles:
        q = np.array([cx, cy])
        if np.hypot(*(q - p)) - r <= rng_range and _within_fov(p, q, heading, half_fov) and _clear(p, q, seg_a, seg_b):
            return True
    d = seg_b - seg_a
    length = np.hypot(d[:, 0], d[:, 1])
    off = np.abs(np.arctan2(d[:, 1], d[:, 0]) - heading) % math.pi
    facing = np.minimum(off, math.pi - off) > FACING_ANGLE
    for i in np.nonzero(facing & (length >= FACING_MIN))[0]:
        n = max(1, int(math.ceil(length[i] / SAMPLE)))
        run = 0
        for q in seg_a[i] + d[i] * ((np.arange(n) + 0.5) / n)[:, None]:
            seen = np.hypot(*(q - p)) <= rng_range and _within_fov(p, q, heading, half_fov) and _clear(p, q, seg_a, seg_b)
            run = run + 1 if seen else 0
            if run * length[i] / n >= FACING_MIN:
                return True
    return False


def stop_in_view(pts, k, circles, seg_a, seg_b, rng_range):
    """Whether the laser can observe the stop at waypoint k and the start from it: a surface facing along
    the heading the robot arrives in, and along the heading it drives off in (it turns in place between)."""
    p = np.array(pts[k][:2])
    if k > 0 and not facing_in_view(p, heading(pts[k - 1], pts[k]), circles, seg_a, seg_b, rng_range):
        return False
    return k + 1 == len(pts) or facing_in_view(p, heading(pts[k], pts[k + 1]), circles, seg_a, seg_b, rng_range)


def turn_where_in_view(laser, circles, seg_a, seg_b, rng_range, step=0.25):
    """The laser path's out-and-back legs (a dead end) turn round at the deepest point from which a surface
    facing along the travel is in view both arriving and driving off: at the end of a dead end longer than
    the range the end wall is behind the robot as it starts back, and that start is invisible to the laser."""
    pts = list(laser)
    for k in range(1, len(pts) - 1):
        a, b = pts[k - 1], pts[k]
        if math.dist(a[:2], pts[k + 1][:2]) > 1e-6 or stop_in_view(pts, k, circles, seg_a, seg_b, rng_range):
            continue
        length = math.dist(a[:2], b[:2])
        for s in np.arange(length - step, 0.0, -step):
            q = (a[0] + (b[0] - a[0]) * s / length, a[1] + (b[1] - a[1]) * s / length) + tuple(b[2:])
            if stop_in_view(pts[:k] + [q] + pts[k + 1:], k, circles, seg_a, seg_b, rng_range):
                pts[k] = q
                break
    return pts


def blank_intervals(a, b, feats, seg_a, seg_b, rng_range, step=0.25):
    """Sub-intervals [s0, s1] (m from a) of segment a-b from which nothing is in view."""
    a, b = np.array(a), np.array(b)
    length = np.linalg.norm(b - a)
    n = max(1, int(math.ceil(length / step)))
    out, start = [], None
    for k in range(n + 1):
        s = length * k / n
        blank = not in_view(a + (b - a) * (s / length), feats, seg_a, seg_b, rng_range)
        if blank and start is None:
            start = s
        if (not blank or k == n) and start is not None:
            end = s if blank else length * (k - 1) / n
            if end > start:
                out.append((start, end))
            start = None
    return out


def make_paths(rng, route, feats, circles, seg_a, seg_b, rng_range):
    """The laser and wheel flavours of the route (lists of (x, y, pause, speed)) and the blank stretches."""
    laser, wheels, blanks = [], [], []
    route = [p for k, p in enumerate(route) if k == 0 or math.dist(p, route[k - 1]) > 1e-6]
    for i, (a, b) in enumerate(zip(route, route[1:])):
        speed = rng.choice(SPEEDS)
        pause = rng.uniform(1.0, 5.0) if i > 0 and rng.random() < 0.3 else 0.0
        laser.append((a[0], a[1], pause, speed))
        wheels.append((a[0], a[1], pause, speed))
        length = math.dist(a, b)
        ivs = blank_intervals(a, b, feats, seg_a, seg_b, rng_range)
        blanks += [s1 - s0 for s0, s1 in ivs]
        stops = sorted(rng.uniform(s0 + 0.2 * (s1 - s0), s1 - 0.2 * (s1 - s0))
                       for s0, s1 in ivs if s1 - s0 > 1.0 for _ in range(rng.randint(1, 2)))
        if not ivs and length > 6.0 and rng.random() < 0.3:  # a stop in a corridor that is not blank
            stops = [rng.uniform(2.0, length - 2.0)]
        for s in stops:
            x, y = a[0] + (b[0] - a[0]) * s / length, a[1] + (b[1] - a[1]) * s / length
            wheels.append((x, y, rng.uniform(2.0, 8.0), rng.choice(SPEEDS)))
    laser.append((route[-1][0], route[-1][1], 0.0, 0.0))
    wheels.append((route[-1][0], route[-1][1], 0.0, 0.0))
    laser = turn_where_in_view(laser, circles, seg_a, seg_b, rng_range)
    # Check: the laser flavour stops and starts only where a surface facing along the travel is in view.
    for k, (x, y, _, _) in enumerate(laser):
        if not stop_in_view(laser, k, circles, seg_a, seg_b, rng_range):
            raise RuntimeError("laser-flavour waypoint (%.2f, %.2f) is blank" % (x, y))
    return laser, wheels, blanks


def rasterise(b, transform, out_dir, res=0.05):
    """plan.pgm + plan.yaml: cells whose centre is free space 254, the rest 0, over the building + 1 m."""
    th, ox, oy = transform
    xs = [v for r in b.free for v in (r[0], r[2])]
    ys = [v for r in b.free for v in (r[1], r[3])]
    corners = [(x, y) for x in (min(xs), max(xs)) for y in (min(ys), max(ys))]
    wc = [(math.cos(th) * x - math.sin(th) * y + ox, math.sin(th) * x + math.cos(th) * y + oy) for x, y in corners]
    x0 = min(p[0] for p in wc) - 1.0
    y0 = min(p[1] for p in wc) - 1.0
    nx = int(math.ceil((max(p[0] for p in wc) + 1.0 - x0) / res))
    ny = int(math.ceil((max(p[1] for p in wc) + 1.0 - y0) / res))
    gx, gy = np.meshgrid(x0 + (np.arange(nx) + 0.5) * res, y0 + (np.arange(ny) + 0.5) * res)
    bx = math.cos(th) * (gx - ox) + math.sin(th) * (gy - oy)  # back into the building frame
    by = -math.sin(th) * (gx - ox) + math.cos(th) * (gy - oy)
    img = np.where(b.is_free(bx, by), 254, 0).astype(np.uint8)[::-1]  # PGM row 0 is the top
    with open(os.path.join(out_dir, "plan.pgm"), "wb") as f:
        f.write(b"P5\n%d %d\n255\n" % (nx, ny))
        f.write(img.tobytes())
    with open(os.path.join(out_dir, "plan.yaml"), "w") as f:
        f.write("image: plan.pgm\nresolution: %.3f\norigin: [%.6f, %.6f, 0.0]\nnegate: 0\n"
                "occupied_thresh: 0.65\nfree_thresh: 0.196\n" % (res, x0, y0))


def generate(seed, family, out_dir, rng_range):
    rng = random.Random(seed * 7919 + 11)
    family = family or FAMILIES[seed % len(FAMILIES)]
    lay = Layout(rng, family, rng_range)
    b = Building()
    lay.corridors(b)
    lay.rooms(b)
    lay.niches(b)
    lay.hall_contents(b)
    route = lay.route()
    segs = b.walls()
    seg_a = np.array([s[0] for s in segs] + [e for p in b.polygons for e in p])
    seg_b = np.array([s[1] for s in segs] + [p[(i + 1) % len(p)] for p in b.polygons for i in range(len(p))])
    feats = visible_features(segs, b.circles, b.polygons)
    laser, wheels, blanks = make_paths(rng, route, feats, b.circles, seg_a, seg_b, rng_range)

    # Turn the whole building by a random angle and shift it off any lattice.
    th, ox, oy = rng.uniform(0, 2 * math.pi), rng.uniform(-10, 10), rng.uniform(-10, 10)
    c, s = math.cos(th), math.sin(th)
    tf = lambda p: (c * p[0] - s * p[1] + ox, s * p[0] + c * p[1] + oy)  # noqa: E731
    os.makedirs(out_dir, exist_ok=True)
    with open(os.path.join(out_dir, "plan.txt"), "w") as f:
        f.write("# generate_building.py --seed %d --family %s: turned %.4f deg, shifted (%.4f, %.4f) m\n"
                % (seed, family, math.degrees(th), ox, oy))
        for a, e in segs:
            f.write("wall %.6f %.6f %.6f %.6f\n" % (tf(a) + tf(e)))
        for cx, cy, r in b.circles:
            f.write("circle %.6f %.6f %.6f\n" % (tf((cx, cy)) + (r,)))
        for poly in b.polygons:
            f.write("polygon " + " ".join("%.6f %.6f" % tf(v) for v in poly) + "\n")
    for name, pts in (("path_laser.txt", laser), ("path_wheels.txt", wheels)):
        with open(os.path.join(out_dir, name), "w") as f:
            f.write("# x y pause_s speed_mps (generate_building.py --seed %d, %s)\n" % (seed, name[5:-4]))
            for x, y, pause, speed in pts:
                f.write("%.6f %.6f %.2f %.2f\n" % (tf((x, y)) + (pause, speed)))
    rasterise(b, (th, ox, oy), out_dir)
    meta = {"seed": seed, "family": family, "angle_deg": math.degrees(th), "offset": [ox, oy],
            "route_m": sum(math.dist(a, e) for a, e in zip(route, route[1:])),
            "ring_m": [round(lay.W, 2), round(lay.H, 2)],
            "corridor_widths_m": {k: round(v, 2) for k, v in lay.width.items()},
            "blank_side_m": round(lay.W - (lay.width["left"] + lay.width["right"]) / 2, 2) if family == "blank" else None,
            "cross_corridors": len(lay.cross), "dead_end_m": round(lay.spur[1], 2) if lay.spur else None,
            "hall_m": [round(lay.hall[1] - lay.hall[0], 2), round(lay.hall[2], 2)] if lay.hall else None,
            "walls": len(segs), "pillars": len(b.circles), "furniture": len(b.polygons),
            "blank_stretches_m": [round(v, 2) for v in blanks],
            "longest_blank_m": round(max(blanks, default=0.0), 2),
            "wheel_stops_in_corridors": len(wheels) - len(laser)}
    with open(os.path.join(out_dir, "meta.json"), "w") as f:
        json.dump(meta, f, indent=1)
    return meta


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seed", type=int, required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--family", choices=FAMILIES)
    ap.add_argument("--range", type=float, default=5.6, help="laser range that makes a stretch blank (m)")
    a = ap.parse_args()
    if a.seed < 0:
        ap.error("--seed must be >= 0")
    meta = generate(a.seed, a.family, a.out, a.range)
    print(json.dumps(meta))


if __name__ == "__main__":
    sys.exit(main())
