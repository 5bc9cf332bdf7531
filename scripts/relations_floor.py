#!/usr/bin/env python3
"""How close to a relations file can any scan matcher get? For each relation (t1, t2, delta*) whose two
stamps are scans of the bag, the scan at t2 is aligned to the scan at t1 by three different matchers, each
started from the true motion delta* and iterated to convergence:
  fwd  point-to-line ICP (Censi 2008's metric) of scan 2 onto scan 1,
  rev  the same of scan 1 onto scan 2, inverted,
  p2p  point-to-point ICP of scan 2 onto scan 1.
If they agree with one another much better than with delta*, the relations carry that much noise of their
own (relative to what the scans support), and no odometry can score below it: the floor. With
--trajectory, the estimate is scored against delta* and against the matchers' motion (their mean).

Usage: relations_floor.py --bag B.bag --relations R [--max-dt S] [--topic /scan] [--trajectory T.tum]
Prints one JSON object (metres, degrees; mean and median of |translation| and mean |rotation|).
"""
import argparse
import json
import math
import os
import sys

import numpy as np


def se2(x):
    c, s = math.cos(x[2]), math.sin(x[2])
    return np.array([[c, -s, x[0]], [s, c, x[1]], [0.0, 0.0, 1.0]])


def vec(m):
    return np.array([m[0, 2], m[1, 2], math.atan2(m[1, 0], m[0, 0])])


def error(est, ref):
    """|translation| (m) and |rotation| (deg) of est * ref^-1, as the relations metric (Kuemmerle 2009)."""
    e = vec(se2(est) @ np.linalg.inv(se2(ref)))
    return math.hypot(e[0], e[1]), abs(math.degrees(e[2]))


def nearest(src, ref):
    """Index of and distance to the nearest ref point of each src point (brute force: scans are small)."""
    d2 = (src * src).sum(axis=1)[:, None] + (ref * ref).sum(axis=1)[None, :] - 2.0 * src @ ref.T
    j = d2.argmin(axis=1)
    return j, np.sqrt(np.maximum(d2[np.arange(len(src)), j], 0.0))


def normals(pts, radius=0.3, k=6):
    """Unit normal of the line through each point's k nearest neighbours within radius; valid only where
    those neighbours are line-like (smaller eigenvalue < 0.1 x the larger)."""
    d2 = ((pts[:, None, :] - pts[None, :, :]) ** 2).sum(axis=2)  # once per scan
    order = np.argsort(d2, axis=1)[:, :k]
    n = np.zeros_like(pts)
    ok = np.zeros(len(pts), bool)
    for i in range(len(pts)):
        q = pts[order[i][d2[i, order[i]] < radius * radius]]
        if len(q) < 4:
            continue
        w, v = np.linalg.eigh(np.cov((q - q.mean(axis=0)).T))
        if w[0] < 0.1 * w[1]:
            n[i], ok[i] = v[:, 0], True
    return n, ok


def align(ref, src, x0, point_to_line=True, max_dist=0.5, scale=0.03, iterations=60):
    """Pose x (x, y, theta) of src's frame in ref's frame minimising Cauchy-weighted point-to-line (or
    point-to-point) residuals, by Gauss-Newton from x0."""
    n, ok = normals(ref) if point_to_line else (None, np.ones(len(ref), bool))
    x = np.array(x0, float)
    for _ in range(iterations):
        c, s = math.cos(x[2]), math.sin(x[2])
        p = src @ np.array([[c, s], [-s, c]]) + x[:2]
        j, d = nearest(p, ref)
        m = (d < max_dist) & ok[j]
        if m.sum() < 10:
            break
        p, q, sp = p[m], ref[j[m]], src[m]
        dp = np.c_[-s * sp[:, 0] - c * sp[:, 1], c * sp[:, 0] - s * sp[:, 1]]  # d p / d theta
        if point_to_line:
            nn = n[j[m]]
            r = ((p - q) * nn).sum(axis=1)
            jac = np.c_[nn, (nn * dp).sum(axis=1)]
        else:
            r = (p - q).ravel()
            jac = np.zeros((len(r), 3))
            jac[0::2, 0], jac[1::2, 1], jac[0::2, 2], jac[1::2, 2] = 1.0, 1.0, dp[:, 0], dp[:, 1]
        w = 1.0 / (1.0 + (r / scale) ** 2)  # Cauchy: outliers and unmatched geometry count little
        step = -np.linalg.solve(jac.T @ (jac * w[:, None]) + 1e-9 * np.eye(3), jac.T @ (w * r))
        x += step
        if np.abs(step).max() < 1e-7:
            break
    return x


def read_scans(bag_path, topic):
    import rosbag  # only here, so the matchers can be imported without ROS
    scans = {}
    with rosbag.Bag(bag_path) as bag:
        for _, msg, _ in bag.read_messages(topics=[topic]):
            r = np.asarray(msg.ranges, float)
            a = msg.angle_min + msg.angle_increment * np.arange(len(r))
            ok = np.isfinite(r) & (r >= msg.range_min) & (r <= msg.range_max)  # REP-117
            scans[msg.header.stamp.to_sec()] = np.c_[r[ok] * np.cos(a[ok]), r[ok] * np.sin(a[ok])]
    return scans


def evaluate_relations_tool():
    """tools/evaluate_relations as a module: its trajectory reader, interpolation and relation error."""
    import importlib.machinery
    import importlib.util
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'tools', 'evaluate_relations')
    loader = importlib.machinery.SourceFileLoader('evaluate_relations', path)
    module = importlib.util.module_from_spec(importlib.util.spec_from_loader('evaluate_relations', loader))
    loader.exec_module(module)
    return module


def summary(errors):
    e = np.array(errors)
    return {"trans_abs_mean": float(e[:, 0].mean()), "trans_abs_median": float(np.median(e[:, 0])),
            "rot_abs_mean_deg": float(e[:, 1].mean())}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bag", required=True)
    ap.add_argument("--relations", required=True)
    ap.add_argument("--max-dt", type=float, default=None)
    ap.add_argument("--topic", default="/scan")
    ap.add_argument("--trajectory")
    a = ap.parse_args(argv)
    scans = read_scans(a.bag, a.topic)
    stamps = np.array(sorted(scans))
    rel = np.loadtxt(a.relations, ndmin=2)
    traj = None
    if a.trajectory:
        er = evaluate_relations_tool()
        rows, lines = er.read_table(a.trajectory, 8, 'TUM trajectory')
        traj = er.Trajectory(rows, lines, a.trajectory)

    def scan_at(t):
        i = int(np.abs(stamps - t).argmin())
        return scans[stamps[i]] if abs(stamps[i] - t) < 1e-3 else None

    out = {k: [] for k in ("fwd", "rev", "p2p", "fwd_vs_rev", "fwd_vs_p2p", "estimate", "estimate_vs_matchers")}
    skipped = 0
    for t1, t2, dx, dy, _, _, _, yaw in rel:
        if a.max_dt is not None and abs(t2 - t1) > a.max_dt:
            continue
        s1, s2 = scan_at(t1), scan_at(t2)
        if s1 is None or s2 is None:
            skipped += 1
            continue
        truth = np.array([dx, dy, yaw])
        fwd = align(s1, s2, truth)
        rev = vec(np.linalg.inv(se2(align(s2, s1, vec(np.linalg.inv(se2(truth)))))))
        p2p = align(s1, s2, truth, point_to_line=False, scale=0.05)
        for key, est, ref in (("fwd", fwd, truth), ("rev", rev, truth), ("p2p", p2p, truth),
                              ("fwd_vs_rev", fwd, rev), ("fwd_vs_p2p", fwd, p2p)):
            out[key].append(error(est, ref))
        if traj is not None:
            # The estimate's motion against delta* and against the matchers' mean motion, as evaluate_relations
            # scores it (same interpolation and error).
            mean = np.mean([fwd, rev, p2p], axis=0)
            pair = np.array([[t1, t2, dx, dy, 0.0, 0.0, 0.0, yaw], [t1, t2, mean[0], mean[1], 0.0, 0.0, 0.0, mean[2]]])
            trans, rot = er.relation_errors(traj, pair)
            out["estimate"].append((trans[0], rot[0]))
            out["estimate_vs_matchers"].append((trans[1], rot[1]))
    if not out["fwd"]:
        print("no relation has both its stamps in %s" % a.bag, file=sys.stderr)
        return 1
    result = {"relations_used": len(out["fwd"]), "relations_without_scans": skipped}
    result.update({k: summary(v) for k, v in out.items() if v})
    print(json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
