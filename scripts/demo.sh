#!/usr/bin/env bash
# scripts/demo.sh: set up and build, then run the offline pipeline on the bundled bags/demo.bag (a
# simulated URG-04LX run in plans/office) and print a summary with the error against its ground truth.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
OUT="$REPO/out/demo"
mkdir -p "$OUT"
echo "[laser_dpslam] running laser odometry + DP-SLAM on bags/demo.bag -> out/demo/"
rosrun laser_dpslam dpslam_offline --bag "$REPO/bags/demo.bag" --out "$OUT" --seed 1
echo "[laser_dpslam] against the ground truth (evaluate_trajectory, SE(2)-aligned):"
rosrun laser_dpslam evaluate_trajectory --estimate "$OUT/trajectory.tum" --reference "$REPO/bags/demo_ground_truth.tum"
/usr/bin/python3 "$REPO/scripts/summarize_run.py" "$OUT" "$REPO/bags/demo_ground_truth.tum"
