#!/usr/bin/env python3
"""Figures and PASS/FAIL lines of one soak run (scripts/soak.sh): RSS over the run from dpslam_offline's
--memory-log, its growth after warm-up, and the ancestry tree's size against DP-SLAM's 2P-1 bound.
Usage: soak_report.py OUT_DIR [--warmup FRACTION] [--max-growth PERCENT]
Exit status 1 when a check fails."""
import argparse
import csv
import json
import os
import sys


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--warmup", type=float, default=0.2, help="share of the scans counted as warm-up (0.2)")
    ap.add_argument("--max-growth", type=float, default=10.0, help="allowed RSS growth after warm-up, %% (10)")
    a = ap.parse_args()
    stats = json.load(open(os.path.join(a.out, "stats.json")))
    rows = list(csv.DictReader(open(os.path.join(a.out, "memory.csv"))))
    if not rows:
        print("FAIL no memory samples in %s" % a.out)
        return 1
    # Data time summed over the loops (the stamps go back to the start at each loop).
    data_s, t, prev = [], 0.0, None
    for r in rows:
        s = float(r["stamp"])
        if prev is not None and s > prev:
            t += s - prev
        prev = s
        data_s.append(t)
    n = len(rows)
    print("%d scans (%d loop(s), %d time reset(s)), %.0f s of data in %.1f s wall (%.1fx real time); "
          "SLAM per scan median %.1f ms, p95 %.1f ms; peak RSS %.1f MB"
          % (stats["scans"], stats.get("loops", 1), stats.get("time_resets", 0), stats["data_duration_s"],
             stats["wall_s"], stats["realtime_factor"], stats["slam_ms"]["median"], stats["slam_ms"]["p95"],
             stats["peak_rss_mb"]))
    # One row per tenth of the run: the values at its last scan, the tree's largest size within it.
    print("  %5s %7s %8s %7s %8s %9s %11s %8s" % ("run", "scan", "data s", "wall s", "RSS MB", "tree max", "map entries",
                                                 "SLAM MB"))
    lo = 0
    for pct in range(0, 101, 10):
        i = max(0, pct * n // 100 - 1)
        r = rows[i]
        tree = max(int(x["tree_nodes"]) for x in rows[lo:i + 1])
        print("  %4d%% %7s %8.0f %7.1f %8.1f %9d %11s %8.1f" % (pct, r["scan"], data_s[i], float(r["wall_s"]),
                                                              float(r["rss_mb"]), tree, r["map_entries"],
                                                              float(r["slam_memory_mb"])))
        lo = i + 1
    failed = False
    w = min(n - 1, int(a.warmup * n))
    rss_w, rss_end = float(rows[w]["rss_mb"]), float(rows[-1]["rss_mb"])
    rss_max_after = max(float(r["rss_mb"]) for r in rows[w:])
    growth = 100.0 * (rss_end - rss_w) / rss_w
    growth_max = 100.0 * (rss_max_after - rss_w) / rss_w
    ok = growth <= a.max_growth  # the criterion; the highest value after warm-up is shown too
    failed |= not ok
    print("%s memory flat after warm-up: RSS %.1f MB at %d %% (scan %s) -> %.1f MB at the end (%+.1f %%), "
          "highest after warm-up %.1f MB (%+.1f %%); limit +%.0f %%"
          % ("PASS" if ok else "FAIL", rss_w, round(100 * a.warmup), rows[w]["scan"], rss_end, growth, rss_max_after,
             growth_max, a.max_growth))
    p = stats["particles"]
    tree_max = max(int(r["tree_nodes"]) for r in rows)
    ok = 0 < tree_max <= 2 * p - 1
    failed |= not ok
    print("%s ancestry tree: at most %d nodes over the run (%d at the end) <= 2P-1 = %d (P = %d particles)"
          % ("PASS" if ok else "FAIL", tree_max, int(rows[-1]["tree_nodes"]), 2 * p - 1, p))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
