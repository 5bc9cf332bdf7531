#!/usr/bin/env python3
"""Prints a short summary of a dpslam_offline output directory, and the error of its odometry against a
ground-truth TUM file (both trajectories expressed relative to their first pose)."""
import json
import math
import os
import sys

import numpy as np


def load_tum(path):
    a = np.loadtxt(path, ndmin=2)
    return a[:, 0], a[:, 1], a[:, 2], 2.0 * np.arctan2(a[:, 6], a[:, 7])


def relative_to_first(x, y, th):
    c, s = math.cos(th[0]), math.sin(th[0])
    dx, dy = x - x[0], y - y[0]
    return c * dx + s * dy, -s * dx + c * dy, np.arctan2(np.sin(th - th[0]), np.cos(th - th[0]))


def main():
    out, truth = sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else None
    stats = json.load(open(os.path.join(out, "stats.json")))
    print("scans %d, %.1f s of data in %.2f s (%.0fx real time); odometry %.3f ms median, %.3f ms p95 per scan"
          % (stats["scans"], stats["data_duration_s"], stats["wall_s"], stats["realtime_factor"],
             stats["odometry_ms"]["median"], stats["odometry_ms"]["p95"]))
    print("weak or degenerate matches: %.1f %%; skipped: %s" % (stats["bad_match_percent"], stats["skipped"] or "none"))
    if truth and os.path.exists(truth):
        for name in ("odometry.tum", "trajectory.tum"):
            if os.path.exists(os.path.join(out, name)):
                report(os.path.join(out, name), truth)
    print("outputs in %s%s" % (out, " (map: %s)" % os.path.join(out, "map.png") if os.path.exists(os.path.join(out, "map.png")) else ""))


def report(estimate, truth):
    if True:
        t, x, y, th = load_tum(estimate)
        gt, gx, gy, gth = load_tum(truth)
        ex, ey, eth = relative_to_first(x, y, th)
        # Ground truth at the estimate's stamps (the simulator writes one pose per scan).
        ix = np.clip(np.searchsorted(gt, t - 1e-6), 0, len(gt) - 1)
        rx, ry, rth = relative_to_first(gx[ix], gy[ix], gth[ix])
        err = np.hypot(ex - rx, ey - ry)
        dist = np.sum(np.hypot(np.diff(rx), np.diff(ry)))
        label = "SLAM trajectory" if estimate.endswith("trajectory.tum") else "laser odometry"
        print("%s vs ground truth (first poses aligned): RMSE %.3f m, final error %.3f m (%.2f %% of %.1f m "
              "travelled), max %.3f m, final heading error %.2f deg"
              % (label, math.sqrt(np.mean(err ** 2)), err[-1], 100.0 * err[-1] / max(dist, 1e-9), dist, err.max(),
                 math.degrees(abs(math.atan2(math.sin(eth[-1] - rth[-1]), math.cos(eth[-1] - rth[-1]))))))


if __name__ == "__main__":
    main()
