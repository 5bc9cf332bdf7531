#!/usr/bin/env bash
# scripts/benchmark_odometry.sh: laser odometry on the real logs in ../shared/datasets (when present):
# CPU per scan (median / p95), real-time factor, share of weak or degenerate matches, and on MIT CSAIL
# the relations error (≤ 10 s apart, and all relations), for saliency and uniform resampling.
# Usage: scripts/benchmark_odometry.sh [DATASETS_DIR]   (default: ../shared/datasets beside the repo)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh" > /dev/null
DATA="${1:-$REPO/../shared/datasets}"
if [[ ! -d "$DATA" ]]; then
  echo "no datasets at $DATA: nothing to benchmark" >&2
  exit 0
fi
OUT="$REPO/out/benchmark"
mkdir -p "$OUT"

# shellcheck source=datasets.sh
source "$REPO/scripts/datasets.sh"

printf "%-16s %-9s %6s %9s %9s %8s %7s %s\n" dataset resampling scans "med ms" "p95 ms" "RT x" "bad %" "relations (<=10 s | all): trans m / rot deg"
# run_one LABEL BAG RESAMPLING [EXTRA_YAML]: one odometry run and its row (relations on the CSAIL bag).
run_one() {
  local label=$1 bag=$2 method=$3 extra=${4:-}
  local dir="$OUT/$label-$method"
  mkdir -p "$dir"
  printf "resampling: %s\n%s" "$method" "$extra" > "$dir/config.yaml"
  rosrun laser_dpslam dpslam_offline --bag "$bag" --out "$dir" --odometry-only --config "$dir/config.yaml" \
    --quiet 2> "$dir/stderr.txt"
  local rel="-"
  if [[ $label == mit-csail* ]]; then
    local local_json all_json
    local_json=$(rosrun laser_dpslam evaluate_relations --trajectory "$dir/odometry.tum" --relations "$DATA/mit-csail/mit-csail.relations" --max-dt 10)
    all_json=$(rosrun laser_dpslam evaluate_relations --trajectory "$dir/odometry.tum" --relations "$DATA/mit-csail/mit-csail.relations")
    echo "$local_json" > "$dir/relations_10s.json"
    echo "$all_json" > "$dir/relations_all.json"
    rel=$(/usr/bin/python3 -c 'import json,sys; a=json.loads(sys.argv[1]); b=json.loads(sys.argv[2]); print("%.4f / %.3f (%d) | %.4f / %.3f (%d)" % (a["trans_abs_mean"], a["rot_abs_mean_deg"], a["used"], b["trans_abs_mean"], b["rot_abs_mean_deg"], b["used"]))' "$local_json" "$all_json")
  fi
  /usr/bin/python3 -c 'import json,sys; s=json.load(open(sys.argv[1])); print("%-16s %-9s %6d %9.3f %9.3f %8.0f %7.1f %s" % (sys.argv[2], sys.argv[3], s["scans"], s["odometry_ms"]["median"], s["odometry_ms"]["p95"], s["realtime_factor"], s["bad_match_percent"], sys.argv[4]))' \
    "$dir/stats.json" "$label" "$method" "$rel"
}

for name in $(printf "%s\n" "${!BAGS[@]}" | sort); do
  for method in saliency uniform; do
    run_one "$name" "${BAGS[$name]}" "$method"
  done
done
# The CSAIL log cut to an URG-04LX's 5.6 m: real data with ground truth for a short-range laser.
if [[ -n ${BAGS[mit-csail]:-} ]]; then
  run_one mit-csail-5.6m "${BAGS[mit-csail]}" saliency "max_range: 5.6
"
fi
echo "(CPU time per scan on one thread; outputs in $OUT)"
