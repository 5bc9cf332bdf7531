#!/usr/bin/env bash
# scripts/demo.sh: set up and build, then run the offline pipeline on the bundled bags/demo.bag (a
# simulated URG-04LX run in plans/office) and print a summary with the error against its ground truth.
# Until the DP-SLAM stage lands this runs the laser odometry (--odometry-only).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
OUT="$REPO/out/demo"
mkdir -p "$OUT"
echo "[laser_dpslam] running the laser odometry on bags/demo.bag -> out/demo/"
rosrun laser_dpslam dpslam_offline --bag "$REPO/bags/demo.bag" --out "$OUT" --odometry-only --seed 1
/usr/bin/python3 "$REPO/scripts/summarize_run.py" "$OUT" "$REPO/bags/demo_ground_truth.tum"
