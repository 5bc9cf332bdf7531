#!/usr/bin/env bash
# scripts/benchmark_corridor.sh: one corridor, for the length of a straight run. Simulates one straight leg
# of a floor plan (default: the loop building's east corridor, plans/loop_building_east.txt) with several
# simulator seeds, runs the laser odometry and the full SLAM on each, and prints how much longer (+) or
# shorter (-) than the truth each made the leg, in % of its length. A map that comes out short in a
# corridor ("maps come out too short", a common complaint about laser-only SLAM) shows here in a minute per seed, where the 2-lap loop
# (scripts/benchmark_loop.sh) takes ten. The leg measured: from the 2nd to the 3rd waypoint, 0.5 m inside.
# Usage: scripts/benchmark_corridor.sh [--seeds "1 2 3"] [--config FILE.yaml] [--plan PLAN.yaml --path WAYPOINTS.txt]
set -euo pipefail
SEEDS="1 2 3"
CONFIG=()
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh" > /dev/null
PLAN="$REPO/plans/loop_building.yaml"
WAYPOINTS="$REPO/plans/loop_building_east.txt"
while (($#)); do
  case "$1" in
    --seeds) SEEDS="$2"; shift 2 ;;
    --config) CONFIG=(--config "$(realpath "$2")"); shift 2 ;;
    --plan) PLAN="$(realpath "$2")"; shift 2 ;;
    --path) WAYPOINTS="$(realpath "$2")"; shift 2 ;;
    *) echo "unknown argument: $1" >&2; exit 2 ;;
  esac
done
# Bags are reused per plan, path and seed.
OUT="$REPO/out/benchmark_corridor/$(basename "$PLAN" .yaml)-$(basename "$WAYPOINTS" .txt)"
mkdir -p "$OUT"

# Length error (%) of the leg between waypoints 2 and 3 (0.5 m inside each end) of an estimate (TUM).
LEG_PY='
import sys, numpy as np
w = np.loadtxt(sys.argv[3], comments="#", ndmin=2)
a, b = w[1], w[2]; u = (b - a) / np.linalg.norm(b - a); a, b = a + 0.5 * u, b - 0.5 * u
def load(f):
    x = np.loadtxt(f, ndmin=2); return x[:, 0], x[:, 1:3]
te, pe = load(sys.argv[1]); tg, pg = load(sys.argv[2])
g = np.stack([np.interp(te, tg, pg[:, 0]), np.interp(te, tg, pg[:, 1])], 1)
i = int(np.argmin(np.linalg.norm(g - a, axis=1))); j = int(np.argmin(np.linalg.norm(g - b, axis=1)))
if j <= i or np.linalg.norm(g[i] - a) > 0.2 or np.linalg.norm(g[j] - b) > 0.2:
    sys.exit("the truth does not drive the leg from waypoint 2 to 3")
L = np.linalg.norm(g[j] - g[i])
print("%+.2f" % (100 * (np.linalg.norm(pe[j] - pe[i]) - L) / L))
'
printf "%-5s | %-22s | %s\n" seed "odometry: leg length %" "SLAM: leg length %"
o_all=(); s_all=()
for seed in $SEEDS; do
  dir="$OUT/seed$seed"
  mkdir -p "$dir"
  if [[ ! -f "$dir/sim.bag" ]]; then
    rosrun laser_dpslam simulate_scans --floorplan "$PLAN" --path "$WAYPOINTS" --seed "$seed" --out "$dir" > /dev/null
  fi
  rosrun laser_dpslam dpslam_offline --bag "$dir/sim.bag" --out "$dir/run" "${CONFIG[@]}" --quiet \
    > /dev/null 2> "$dir/stderr.txt"
  o=$(/usr/bin/python3 -c "$LEG_PY" "$dir/run/odometry.tum" "$dir/ground_truth.tum" "$WAYPOINTS")
  s=$(/usr/bin/python3 -c "$LEG_PY" "$dir/run/trajectory.tum" "$dir/ground_truth.tum" "$WAYPOINTS")
  o_all+=("$o"); s_all+=("$s")
  printf "%-5s | %-22s | %s\n" "$seed" "$o" "$s"
done
mean() { /usr/bin/python3 -c 'import sys; v=[float(x) for x in sys.argv[1:]]; print("%+.2f" % (sum(v)/len(v)))' "$@"; }
printf "%-5s | %-22s | %s\n" mean "$(mean "${o_all[@]}")" "$(mean "${s_all[@]}")"
echo "(outputs in $OUT; + = the estimate's leg is longer than the truth's)"
