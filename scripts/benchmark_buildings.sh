#!/usr/bin/env bash
# scripts/benchmark_buildings.sh: the laser odometry and the SLAM over many generated buildings, not one.
# Each case is a building drawn by scripts/generate_building.py from a fixed seed (ring and grid corridors
# 1.2-4 m wide, offices with and without doors, halls with pillars and furniture, dead ends, corridors with
# nothing in view for 2-8 x the laser's 5.6 m, turned to an arbitrary angle), simulated with simulate_scans
# (seed 1) and run through dpslam_offline; plans/loop_building (2 laps) stays as one regression case.
# Two modes per case:
#   laser   the laser-only path (path_laser.txt: constant speed through blank stretches, stops and speed
#           changes only where a surface facing along the travel is in view), no wheel odometry
#   wheels  the wheel path (path_wheels.txt: also stops and speed changes inside blank stretches), with
#           /wheel_odom passed to dpslam_offline --wheel-odom
# Prints one row per run (case, family, metres, odometry ATE, drift %, SLAM ATE) and, per mode, the median /
# 90th percentile / worst of the drift and the SLAM ATE against the targets.
# Two fixed seed lists: `bench` to tune on, `holdout` to evaluate only at the end (never tune on it).
# Usage: scripts/benchmark_buildings.sh [--list bench|holdout] [--cases N] [--odometry-only]
#          [--mode laser|wheels|both] [--config FILE.yaml] [--jobs 2] [--tag NAME] [--seeds "S ..."]
# --seeds runs the given generated buildings instead of a list (to look into one case).
# Outputs: out/benchmark_buildings/buildings/seedN/ (plan, paths, bags; cached: delete it after changing the
#          generator or the simulator) and out/benchmark_buildings/runs/TAG-MODE[-odometry]/CASE/
#          (dpslam_offline's outputs, rerun every time). Wheel rows add the drift of /wheel_odom alone.
set -euo pipefail
BENCH_SEEDS="1001 1002 1003 1004 1005 1006 1007 1008 1009 1010 1011 1012 1013 1014 1015
             1016 1017 1018 1019 1020 1021 1022 1023 1024 1025 1026 1027 1028 1029 1030"
HOLDOUT_SEEDS="2001 2002 2003 2004 2005 2006 2007 2008 2009 2010 2011 2012 2013 2014 2015
               2016 2017 2018 2019 2020 2021 2022 2023 2024 2025 2026 2027 2028 2029 2030"
LIST=bench
CASES=0
SLAM=1
MODE=both
CONFIG=""
JOBS=2
TAG=default
OVERRIDE=""
while (($#)); do
  case "$1" in
    --list) LIST="$2"; shift 2 ;;
    --cases) CASES="$2"; shift 2 ;;
    --odometry-only) SLAM=0; shift ;;
    --mode) MODE="$2"; shift 2 ;;
    --config) CONFIG="$(realpath "$2")"; shift 2 ;;
    --jobs) JOBS="$2"; shift 2 ;;
    --tag) TAG="$2"; shift 2 ;;
    --seeds) OVERRIDE="$2"; shift 2 ;;
    -h|--help) sed -n '2,23p' "$0"; exit 0 ;;
    *) echo "unknown argument: $1" >&2; exit 2 ;;
  esac
done
case "$LIST" in bench) SEEDS=$BENCH_SEEDS ;; holdout) SEEDS=$HOLDOUT_SEEDS ;;
  *) echo "--list must be bench or holdout" >&2; exit 2 ;; esac
[[ -n $OVERRIDE ]] && SEEDS=$OVERRIDE LIST=custom
case "$MODE" in laser|wheels|both) ;; *) echo "--mode must be laser, wheels or both" >&2; exit 2 ;; esac
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh" > /dev/null
OUT="$REPO/out/benchmark_buildings"
mkdir -p "$OUT/buildings"

CASE_LIST=()
for s in $SEEDS; do CASE_LIST+=("seed$s"); done
if ((CASES > 0)); then CASE_LIST=("${CASE_LIST[@]:0:CASES}"); elif [[ $LIST == bench ]]; then CASE_LIST+=(loop_building); fi
for s in $SEEDS; do [[ $s =~ ^[0-9]+$ ]] || { echo "seed '$s' is not a number" >&2; exit 2; }; done
MODES=()
[[ $MODE != wheels ]] && MODES+=(laser)
if [[ $MODE != laser ]]; then
  if rosrun laser_dpslam dpslam_offline --help 2>&1 | grep -q -- '--wheel-odom'; then
    MODES+=(wheels)
  else
    echo "(wheel rows not available: dpslam_offline has no --wheel-odom option yet)"
  fi
fi
((${#MODES[@]})) || exit 0

# One run: generate and simulate (cached), dpslam_offline, score. Writes ROW to RUN/row.txt.
run_case() {
  local case="$1" mode="$2" dir plan path family bag run extra=()
  if [[ $case == loop_building ]]; then
    dir="$OUT/buildings/loop_building"; plan="$REPO/plans/loop_building.yaml"; family=regression
    path=(--path "$REPO/plans/loop_building_loop.txt" --laps 2)
  else
    dir="$OUT/buildings/$case"; plan="$dir/plan.txt"
    [[ -f $dir/meta.json ]] || /usr/bin/python3 "$REPO/scripts/generate_building.py" --seed "${case#seed}" \
      --out "$dir" > /dev/null
    family=$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["family"])' "$dir/meta.json")
    path=(--path "$dir/path_$mode.txt")
  fi
  local sim="$dir/sim_$mode"
  [[ $mode == wheels ]] && extra=(--wheel-odometry)
  if [[ ! -f $sim/sim.bag ]]; then
    rosrun laser_dpslam simulate_scans --floorplan "$plan" "${path[@]}" "${extra[@]}" --seed 1 --out "$sim.tmp" \
      > /dev/null && mv "$sim.tmp" "$sim"
  fi
  run="$OUT/runs/$TAG-$mode$RUN_SUFFIX/$case"
  rm -rf "$run"; mkdir -p "$run"
  local args=(--bag "$sim/sim.bag" --out "$run/out" --quiet)
  [[ -n $CONFIG ]] && args+=(--config "$CONFIG")
  ((SLAM)) || args+=(--odometry-only)
  [[ $mode == wheels ]] && args+=(--wheel-odom /wheel_odom)
  local row
  if rosrun laser_dpslam dpslam_offline "${args[@]}" > /dev/null 2> "$run/stderr.txt"; then
    row=$(/usr/bin/python3 "$REPO/scripts/benchmark_buildings_score.py" row "$run/out" "$sim/ground_truth.tum" "$SLAM")
    if [[ $mode == wheels ]]; then
      [[ -f $sim/wheel_drift.txt ]] || /usr/bin/python3 "$REPO/scripts/benchmark_buildings_score.py" wheels \
        "$sim/sim.bag" "$sim/ground_truth.tum" > "$sim/wheel_drift.txt"
      row="$row $(printf "%9s" "$(cat "$sim/wheel_drift.txt")")"
    fi
  else
    row="FAIL - - - (see $run/stderr.txt)"
  fi
  printf "%-14s %-10s %-7s %s\n" "$case" "$family" "$mode" "$row" > "$run/row.txt"
  echo "  done: $case $mode" >&2
}
export -f run_case
RUN_SUFFIX=""
((SLAM)) || RUN_SUFFIX=-odometry
export OUT REPO TAG CONFIG SLAM RUN_SUFFIX

for mode in "${MODES[@]}"; do
  printf '%s\n' "${CASE_LIST[@]}" | xargs -P "$JOBS" -I{} bash -c 'run_case "$1" "$2"' _ {} "$mode" || true
done
# Rows in list order, then the summaries.
printf "%-14s %-10s %-7s %7s %9s %8s %9s %9s\n" case family mode metres "odo ATE" "drift %" "SLAM ATE" \
  "(wheels %)"
for mode in "${MODES[@]}"; do
  rows=()
  for c in "${CASE_LIST[@]}"; do rows+=("$OUT/runs/$TAG-$mode$RUN_SUFFIX/$c/row.txt"); done
  cat "${rows[@]}" 2>/dev/null
  cat "${rows[@]}" 2>/dev/null | /usr/bin/python3 "$REPO/scripts/benchmark_buildings_score.py" summary "$mode" "$SLAM"
done
echo "(list $LIST, ${#CASE_LIST[@]} cases; outputs in $OUT/runs/$TAG-*; drift = final position error / distance;"
echo " (wheels %) = the drift of /wheel_odom alone)"
