#!/usr/bin/env bash
# scripts/soak.sh: soak benchmark of the full pipeline (laser odometry + DP-SLAM), issue 6. Prints figures
# and PASS/FAIL lines; a benchmark to run by hand (minutes), not a CI test.
#  (a) bags/demo.bag replayed N times in one process (dpslam_offline --loops N). Each loop starts again at
#      the bag's first stamp, so time goes backwards as with `rosbag play -l`: the odometry resets itself
#      and the SLAM is reset the way dpslam_node does it. What this tests is that a reset gives back
#      everything (memory, tree, state): RSS must stay flat and the last loop's outputs must be identical
#      to a single pass. (Concatenating loops with continuing time would instead make the robot jump from
#      the path's end to its start and mostly test the matcher's recovery; the long run (b) covers the
#      long uninterrupted map.)
#  (b) one long simulated run (simulate_scans on plans/office, the loop path repeated for S seconds of data,
#      1800 by default) through dpslam_offline: memory must stay flat while the map and the ancestry tree
#      keep being updated.
# Memory is VmRSS sampled by dpslam_offline itself after every scan (--memory-log); the tree size is the
# DP-SLAM ancestry tree's node count after every scan. Acceptance: RSS at the end at most 10 % above its
# value at 20 % of the run, and never more than 2P-1 tree nodes.
# Usage: scripts/soak.sh [--loops N] [--duration S] [--out DIR] [--skip-demo] [--skip-long]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh" > /dev/null
LOOPS=10
DURATION=1800
OUT="$REPO/out/soak"
RUN_DEMO=1
RUN_LONG=1
while (($#)); do
  case "$1" in
    --loops) LOOPS="$2"; shift 2 ;;
    --duration) DURATION="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    --skip-demo) RUN_DEMO=0; shift ;;
    --skip-long) RUN_LONG=0; shift ;;
    -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
    *) echo "soak.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
mkdir -p "$OUT"
status=0

offline() {  # name bag [args...]: dpslam_offline with the memory log, timed
  local name="$1" bag="$2"
  shift 2
  rm -rf "${OUT:?}/$name"
  mkdir -p "$OUT/$name"
  local cmd=(rosrun laser_dpslam dpslam_offline --bag "$bag" --out "$OUT/$name" --memory-log "$OUT/$name/memory.csv"
             --seed 1 --quiet "$@")
  echo "command: ${cmd[*]}"
  "${cmd[@]}" 2> "$OUT/$name/stderr.txt" || { cat "$OUT/$name/stderr.txt" >&2; return 1; }
}

if ((RUN_DEMO)); then
  echo "== (a) bags/demo.bag replayed $LOOPS times, time back to the start at each loop =="
  offline demo_loops "$REPO/bags/demo.bag" --loops "$LOOPS"
  /usr/bin/python3 "$REPO/scripts/soak_report.py" "$OUT/demo_loops" || status=1
  # A complete reset: the last loop must give exactly what one pass gives.
  rosrun laser_dpslam dpslam_offline --bag "$REPO/bags/demo.bag" --out "$OUT/demo_once" --seed 1 --quiet
  same=1
  for f in odometry.tum trajectory.tum map.pgm map.yaml; do
    cmp -s "$OUT/demo_loops/$f" "$OUT/demo_once/$f" || { same=0; echo "  differs from one pass: $f"; }
  done
  if ((same)); then
    echo "PASS reset: after $LOOPS loops, odometry.tum, trajectory.tum, map.pgm and map.yaml are byte-identical to one pass"
  else
    echo "FAIL reset: the last loop's outputs differ from one pass (state survives a reset)"
    status=1
  fi
  echo
fi

if ((RUN_LONG)); then
  echo "== (b) one long simulated run: plans/office, loop path, $DURATION s of data =="
  SIM="$OUT/sim_office_${DURATION}s"
  if [[ ! -f "$SIM/sim.bag" ]]; then  # the same arguments give the same bag: generated once
    mkdir -p "$SIM"
    SECONDS=0
    echo "command: rosrun laser_dpslam simulate_scans --floorplan plans/office.yaml --path loop --duration $DURATION --out $SIM --seed 1"
    rosrun laser_dpslam simulate_scans --floorplan "$REPO/plans/office.yaml" --path loop --duration "$DURATION" \
      --out "$SIM" --seed 1 > "$SIM/simulate.txt"
    echo "simulated in $SECONDS s"
  fi
  offline long "$SIM/sim.bag"
  /usr/bin/python3 "$REPO/scripts/soak_report.py" "$OUT/long" || status=1
  echo "trajectory against the ground truth (evaluate_trajectory, SE(2)-aligned):"
  rosrun laser_dpslam evaluate_trajectory --estimate "$OUT/long/trajectory.tum" --reference "$SIM/ground_truth.tum"
  echo
fi
echo "outputs in $OUT"
exit $status
