#!/usr/bin/env bash
# scripts/benchmark_loop.sh: the corridor benchmark. Simulates 2 laps (177 m) of the loop building
# (plans/loop_building: 2.5 m corridors, few features within the URG-04LX's 5.6 m) with several simulator
# seeds, runs the laser odometry and the full SLAM on each, and prints drift and ATE against the truth,
# plus the largest position error the odometry picks up within 10 s (mostly the corridor lag: where the
# scan cannot see motion along the corridor, the estimate falls behind — "maps come out too short").
# One seed is not enough here: the outcome of a corridor stretch varies a lot with the noise.
# --start-jitter: each seed's path is shifted by a seeded sub-cell offset (0-5 cm in x and y) and starts with
# a 1 m lead-in at a seeded heading (within +-5 deg) before the first waypoint. The plan's walls lie on 5 cm
# pixel edges and the SLAM's map frame is the first pose, so without it every wall lies exactly on a cell
# boundary of the 5 cm grid, parallel to its rows: a coincidence a real run never has (doc/experiments.md).
# Usage: scripts/benchmark_loop.sh [--seeds "1 2 3"] [--laps 2] [--config FILE.yaml] [--odometry-only]
#                                  [--start-jitter]
set -euo pipefail
SEEDS="1 2 3"
LAPS=2
CONFIG=()
SLAM=1
JITTER=0
while (($#)); do
  case "$1" in
    --seeds) SEEDS="$2"; shift 2 ;;
    --laps) LAPS="$2"; shift 2 ;;
    --config) CONFIG=(--config "$(realpath "$2")"); shift 2 ;;
    --odometry-only) SLAM=0; shift ;;
    --start-jitter) JITTER=1; shift ;;
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
# Seeded start jitter (see the header): the loop's waypoints shifted by (dx, dy), with a lead-in point 1 m
# behind the first one at heading psi (the laps written out), so that the map frame (the first pose) is off the plan's lattice.
JITTER_PY='
import math, random, sys
src, seed, laps = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
rng = random.Random(1000003 * seed + 17)
dx, dy = rng.uniform(0.0, 0.05), rng.uniform(0.0, 0.05)
psi = math.radians(rng.uniform(-5.0, 5.0))
pts = [tuple(map(float, l.split()[:2])) for l in open(src) if l.strip() and not l.lstrip().startswith("#")]
pts = [(x + dx, y + dy) for x, y in pts]
hx, hy = pts[1][0] - pts[0][0], pts[1][1] - pts[0][1]
h = math.atan2(hy, hx) + psi
print("# %s shifted by (%.4f, %.4f) m, lead-in at %+.2f deg (benchmark_loop.sh --start-jitter, seed %d)"
      % (src, dx, dy, math.degrees(psi), seed))
print("%.4f %.4f" % (pts[0][0] - math.cos(h), pts[0][1] - math.sin(h)))
for x, y in pts + pts[1:] * (laps - 1): print("%.4f %.4f" % (x, y))
'

for seed in $SEEDS; do
  dir="$OUT/seed$seed-laps$LAPS"
  path=(--path loop --laps "$LAPS")
  if ((JITTER)); then
    dir="$dir-jitter"
    mkdir -p "$dir"
    /usr/bin/python3 -c "$JITTER_PY" "$REPO/plans/loop_building_loop.txt" "$seed" "$LAPS" > "$dir/waypoints.txt"
    path=(--path "$dir/waypoints.txt")
  fi
  mkdir -p "$dir"
  if [[ ! -f "$dir/sim.bag" ]]; then
    rosrun laser_dpslam simulate_scans --floorplan "$REPO/plans/loop_building.yaml" "${path[@]}" \
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
