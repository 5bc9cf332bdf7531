#!/usr/bin/env bash
# scripts/benchmark_loop.sh: the corridor benchmark. Simulates 2 laps (177 m) of the loop building
# (plans/loop_building: 2.5 m corridors, few features within the URG-04LX's 5.6 m) with several simulator
# seeds, runs the laser odometry and the full SLAM on each, and prints drift and ATE against the truth,
# plus the largest position error the odometry picks up within 10 s (mostly the corridor lag: where the
# scan cannot see motion along the corridor, the estimate falls behind — "maps come out too short").
# One seed is not enough here: the outcome of a corridor stretch varies a lot with the noise.
# Usage: scripts/benchmark_loop.sh [--seeds "1 2 3"] [--laps 2] [--config FILE.yaml] [--odometry-only]
set -euo pipefail
SEEDS="1 2 3"
LAPS=2
CONFIG=()
SLAM=1
while (($#)); do
  case "$1" in
    --seeds) SEEDS="$2"; shift 2 ;;
    --laps) LAPS="$2"; shift 2 ;;
    --config) CONFIG=(--config "$(realpath "$2")"); shift 2 ;;
    --odometry-only) SLAM=0; shift ;;
    *) echo "unknown argument: $1" >&2; exit 2 ;;
  esac
done
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh" > /dev/null
OUT="$REPO/out/benchmark_loop"
mkdir -p "$OUT"

# Largest growth of the position error within 10 s (m), from an estimate and the truth (TUM).
LAG_PY='
import sys, numpy as np
def load(f):
    a = np.loadtxt(f, ndmin=2)
    return a[:, 0], a[:, 1], a[:, 2], 2 * np.arctan2(a[:, 6], a[:, 7])
t, x, y, th = load(sys.argv[1]); gt = load(sys.argv[2])
gx, gy = np.interp(t, gt[0], gt[1]), np.interp(t, gt[0], gt[2])
gth = np.interp(t, gt[0], np.unwrap(gt[3]))
# Align the first poses; e = position error vector.
d = gth[0] - th[0]; c, s = np.cos(d), np.sin(d)
e = np.stack([c * (x - x[0]) - s * (y - y[0]) + gx[0] - gx, s * (x - x[0]) + c * (y - y[0]) + gy[0] - gy], 1)
worst, at = 0.0, 0.0
j = 0
for i in range(len(t)):
    while t[i] - t[j] > 10.0: j += 1
    g = np.linalg.norm(e[j:i + 1] - e[i], axis=1)
    if g.max() > worst: worst, at = g.max(), t[i] - t[0]
print("%.2f m at %.0f s" % (worst, at))
'
ate() {  # estimate reference -> "ATE-RMSE drift-% distance-m"
  rosrun laser_dpslam evaluate_trajectory --estimate "$1" --reference "$2" |
    /usr/bin/python3 -c 'import json,sys; d=json.load(sys.stdin); print("%.3f %.2f %.1f" % (d["ate_rmse_m"], d["drift_percent"], d["distance_m"]))'
}

printf "%-5s %7s | %-28s %-22s | %-10s %s\n" seed "metres" "odometry: ATE m, drift %" "worst 10 s error growth" "SLAM ATE m" "SLAM ms/scan (median)"
for seed in $SEEDS; do
  dir="$OUT/seed$seed-laps$LAPS"
  mkdir -p "$dir"
  if [[ ! -f "$dir/sim.bag" ]]; then
    rosrun laser_dpslam simulate_scans --floorplan "$REPO/plans/loop_building.yaml" --path loop --laps "$LAPS" \
      --seed "$seed" --out "$dir" > /dev/null
  fi
  mode=(--odometry-only)
  ((SLAM)) && mode=()
  rosrun laser_dpslam dpslam_offline --bag "$dir/sim.bag" --out "$dir/run" "${CONFIG[@]}" "${mode[@]}" --quiet \
    > /dev/null 2> "$dir/stderr.txt"
  read -r o_ate o_drift metres < <(ate "$dir/run/odometry.tum" "$dir/ground_truth.tum")
  lag=$(/usr/bin/python3 -c "$LAG_PY" "$dir/run/odometry.tum" "$dir/ground_truth.tum")
  s_ate="-"; s_ms="-"
  if ((SLAM)); then
    read -r s_ate _ _ < <(ate "$dir/run/trajectory.tum" "$dir/ground_truth.tum")
    s_ms=$(/usr/bin/python3 -c 'import json,sys; print("%.1f" % json.load(open(sys.argv[1]))["slam_ms"]["median"])' "$dir/run/stats.json")
  fi
  printf "%-5s %7s | %-28s %-22s | %-10s %s\n" "$seed" "$metres" "$o_ate, $o_drift %" "$lag" "$s_ate" "$s_ms"
done
echo "(outputs in $OUT; drift = final position error / distance, after aligning the first poses)"
