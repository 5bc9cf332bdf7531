#!/usr/bin/env bash
# scripts/benchmark_slam.sh: the full SLAM (laser odometry + DP-SLAM, `dpslam_offline`) on every dataset in
# ../shared/datasets (when present) and on the bundled bags/demo.bag, for the default configuration and
# other particle counts, on one thread (`threads: 1`): error, the SLAM step's CPU per scan, the whole run's CPU
# per scan (odometry + SLAM: process CPU / scans) and real-time factor by CPU time (data time / process CPU:
# what one core of this machine sustains), peak memory, ancestry-tree size.
# Error: MIT CSAIL — the relations metric (all 1172 relations, and those <= 10 s apart); demo — ATE RMSE
# against bags/demo_ground_truth.tum; the other logs have no ground truth (look at their map.png).
# --wheel-odom: the logs that carry wheel odometry (/wheel_odom: MIT CSAIL, mines, loop5) run with
# `dpslam_offline --wheel-odom /wheel_odom` (rows "NAME+wheels"); the others are left out.
# Usage: scripts/benchmark_slam.sh [--particles "30 10 60"] [--wheel-odom] [DATASETS_DIR]
set -euo pipefail
PARTICLES="30 10 60"
WHEELS=0
while [[ "${1:-}" == --* ]]; do
  case "$1" in
    --particles) PARTICLES="$2"; shift 2 ;;
    --wheel-odom) WHEELS=1; shift ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh" > /dev/null
DATA="${1:-$REPO/../shared/datasets}"
OUT="$REPO/out/benchmark_slam"
mkdir -p "$OUT"

declare -A BAGS
if [[ -d "$DATA" ]]; then
  # shellcheck source=datasets.sh
  source "$REPO/scripts/datasets.sh"
else
  echo "no datasets at $DATA: only the bundled demo" >&2
fi
BAGS[demo]="$REPO/bags/demo.bag"

printf "%-16s %5s %6s %8s %8s %8s %7s %7s %6s  %s\n" dataset P scans "slam ms" "p95 ms" "CPU ms" "RT x CPU" "RSS MB" "tree" "error"
for name in $(printf "%s\n" "${!BAGS[@]}" | sort); do
  extra=() label=$name suffix=""
  if ((WHEELS)); then
    [[ $name == demo || $name == scan_tools-demo ]] && continue  # no wheel odometry in these
    extra=(--wheel-odom /wheel_odom) label="$name+wheels" suffix="-wheels"
  fi
  for p in $PARTICLES; do
    dir="$OUT/$name-p$p$suffix"
    mkdir -p "$dir"
    printf "particles: %s\nthreads: 1\n" "$p" > "$dir/config.yaml"
    if ! rosrun laser_dpslam dpslam_offline --bag "${BAGS[$name]}" --out "$dir" --config "$dir/config.yaml" \
         "${extra[@]}" --quiet 2> "$dir/stderr.txt" > /dev/null; then
      echo "$name P=$p: dpslam_offline failed, see $dir/stderr.txt"
      continue
    fi
    err="(no ground truth: see $dir/map.png)"
    if [[ $name == mit-csail ]]; then
      rosrun laser_dpslam evaluate_relations --trajectory "$dir/trajectory.tum" --relations "$DATA/mit-csail/mit-csail.relations" > "$dir/relations_all.json"
      rosrun laser_dpslam evaluate_relations --trajectory "$dir/trajectory.tum" --relations "$DATA/mit-csail/mit-csail.relations" --max-dt 10 > "$dir/relations_10s.json"
      err=$(/usr/bin/python3 -c 'import json,sys; a=json.load(open(sys.argv[1])); b=json.load(open(sys.argv[2])); print("relations all %.4f m / %.3f deg (%d); <= 10 s %.4f m / %.3f deg" % (a["trans_abs_mean"], a["rot_abs_mean_deg"], a["used"], b["trans_abs_mean"], b["rot_abs_mean_deg"]))' "$dir/relations_all.json" "$dir/relations_10s.json")
    elif [[ $name == demo ]]; then
      rosrun laser_dpslam evaluate_trajectory --estimate "$dir/trajectory.tum" --reference "$REPO/bags/demo_ground_truth.tum" > "$dir/ate.json"
      err=$(/usr/bin/python3 -c 'import json,sys; a=json.load(open(sys.argv[1])); print("ATE RMSE %.4f m (max %.3f m) over %.1f m" % (a["ate_rmse_m"], a["ate_max_m"], a["distance_m"]))' "$dir/ate.json")
    fi
    /usr/bin/python3 -c 'import json,sys; s=json.load(open(sys.argv[1])); print("%-16s %5d %6d %8.2f %8.2f %8.2f %7.1f %7.0f %6d  %s" % (sys.argv[2], s["particles"], s["scans"], s["slam_ms"]["median"], s["slam_ms"]["p95"], 1e3 * s["cpu_s"] / max(1, s["scans"]), s["data_duration_s"] / max(1e-9, s["cpu_s"]), s["peak_rss_mb"], s.get("tree_nodes", -1), sys.argv[3]))' \
      "$dir/stats.json" "$label" "$err"
  done
done
echo "(slam ms: CPU per scan of the SLAM step; CPU ms: the whole run's process CPU per scan; RT x CPU: data time / process CPU; one thread; outputs in $OUT)"
