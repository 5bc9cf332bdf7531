#!/usr/bin/env python3
"""Scoring for scripts/benchmark_buildings.sh.

    benchmark_buildings_score.py row RUN_DIR GROUND_TRUTH.tum SLAM(0|1)
        prints "metres odometry-ATE drift-% SLAM-ATE" of one dpslam_offline run (evaluate_trajectory)
    benchmark_buildings_score.py wheels BAG GROUND_TRUTH.tum
        prints the drift % of the bag's /wheel_odom alone (the prior the wheel mode gets)
    benchmark_buildings_score.py summary MODE SLAM(0|1) < rows
        prints the median / 90th percentile / worst of the drift and the SLAM ATE over the rows, and whether
        they meet the targets of that mode, and the medians per building family (laser: drift median <= 1 %, p90 <= 2 %, SLAM ATE median <= 0.05 m,
        worst <= 0.5 m; wheels: SLAM ATE median <= 0.03 m, worst <= 0.2 m). A failed run counts as worst.
"""
import json
import math
import os
import subprocess
import sys

TARGETS = {"laser": {"drift": (1.0, 2.0, None), "slam": (0.05, None, 0.5)},
           "wheels": {"drift": (None, None, None), "slam": (0.03, None, 0.2)}}


def evaluate(estimate, reference):
    out = subprocess.run(["rosrun", "laser_dpslam", "evaluate_trajectory", "--estimate", estimate,
                          "--reference", reference], capture_output=True, text=True, check=True).stdout
    return json.loads(out)


def row(run, gt, slam):
    o = evaluate(os.path.join(run, "odometry.tum"), gt)
    s = "%9s" % "-"
    if slam == "1":
        s = "%9.3f" % evaluate(os.path.join(run, "trajectory.tum"), gt)["ate_rmse_m"]
    print("%7.1f %9.3f %8.2f %s" % (o["distance_m"], o["ate_rmse_m"], o["drift_percent"], s))


def wheel_drift(bag_path, gt_path):
    import numpy as np
    import rosbag
    odom = []
    with rosbag.Bag(bag_path) as bag:
        for _, m, _ in bag.read_messages(topics=["/wheel_odom"]):
            odom.append((m.header.stamp.to_sec(), m.pose.pose.position.x, m.pose.pose.position.y))
    if not odom:
        sys.exit("%s: no /wheel_odom" % bag_path)
    gt, odom = np.loadtxt(gt_path, ndmin=2), np.array(odom)
    # The odom frame is the first true pose: put the final odometry position into the map frame.
    th = 2 * math.atan2(gt[0, 6], gt[0, 7])
    x = math.cos(th) * odom[-1, 1] - math.sin(th) * odom[-1, 2] + gt[0, 1]
    y = math.sin(th) * odom[-1, 1] + math.cos(th) * odom[-1, 2] + gt[0, 2]
    gx, gy = np.interp(odom[-1, 0], gt[:, 0], gt[:, 1]), np.interp(odom[-1, 0], gt[:, 0], gt[:, 2])
    distance = np.sum(np.hypot(np.diff(gt[:, 1]), np.diff(gt[:, 2])))
    print("%.2f" % (100.0 * math.hypot(x - gx, y - gy) / distance))


def percentile(v, q):
    v = sorted(v)
    k = (len(v) - 1) * q / 100.0
    lo, hi = int(math.floor(k)), int(math.ceil(k))
    return v[lo] + (v[hi] - v[lo]) * (k - lo)


def summary(mode, slam):
    drift, ate, failed, families = [], [], 0, {}
    for line in sys.stdin:
        f = line.split()
        if len(f) < 7 or f[3] == "FAIL":
            failed += 1
            continue
        drift.append(float(f[5]))
        families.setdefault(f[1], []).append((float(f[5]), float(f[6]) if slam == "1" else None))
        if slam == "1":
            ate.append(float(f[6]))
    inf = float("inf")
    for name, values, unit in (("drift %", drift, "%"), ("SLAM ATE", ate, "m")):
        if (unit == "m" and slam != "1") or (not values and not failed):
            continue
        values = values + [inf] * failed
        stats = (percentile(values, 50), percentile(values, 90), max(values))
        key = "drift" if unit == "%" else "slam"
        verdict = []
        for label, value, limit in zip(("median", "p90", "worst"), stats, TARGETS[mode][key]):
            if limit is not None:
                verdict.append("%s %s %g" % (label, "<=" if value <= limit else ">", limit))
        print("%-7s %-8s median %7.3f  p90 %7.3f  worst %7.3f  over %d runs%s   targets: %s" % (
            mode, name, stats[0], stats[1], stats[2], len(values), " (%d failed)" % failed if failed else "",
            ", ".join(verdict) or "none"))
    if len(families) > 1:  # where the estimator loses: the median per family
        print("%-7s by family (median drift %%%s): %s" % (mode, " / SLAM ATE m" if slam == "1" else "", ", ".join(
            "%s %.2f%s" % (name, percentile([d for d, _ in v], 50),
                           " / %.3f" % percentile([a for _, a in v], 50) if slam == "1" else "")
            for name, v in sorted(families.items()))))


if __name__ == "__main__":
    if len(sys.argv) == 5 and sys.argv[1] == "row":
        row(*sys.argv[2:])
    elif len(sys.argv) == 4 and sys.argv[1] == "wheels":
        wheel_drift(*sys.argv[2:])
    elif len(sys.argv) == 4 and sys.argv[1] == "summary":
        summary(sys.argv[2], sys.argv[3])
    else:
        sys.exit(__doc__)
