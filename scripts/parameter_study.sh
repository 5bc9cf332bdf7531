#!/usr/bin/env bash
# scripts/parameter_study.sh: the thesis's laser-odometry parameter studies (DE population NP and generations
# G, NDT cell sizes, uniform vs saliency resampling) on simulated bags with ground truth.
#
# Usage: scripts/parameter_study.sh [--bag B.bag --truth T.tum [--name NAME]] [--full] [--seeds N] [--jobs N]
#                                 [--no-build]
#
# Default datasets: the loop of plans/loop_building simulated once with simulate_scans (seed 1; kept in
# out/parameter_study/sim_loop_building/ and re-simulated only when the plan or simulate_scans changed) and
# the bundled bags/demo.bag (plans/office). --bag/--truth replace them with one bag of your own (outputs
# then in out/parameter_study_NAME/).
# For every setting: dpslam_offline --odometry-only --config <generated yaml>, then tools/evaluate_trajectory
# against the ground truth, for DE seeds 1..N (default 3; 2 runs at a time); see scripts/parameter_study.py
# for the settings. Writes out/parameter_study/table.md (medians over the seeds of ATE, drift, RPE, bad-match
# share, median/p95 CPU ms per scan; worst drift), results.json and parameter_study.png. About 5 minutes on
# 2 idle cores by default (--full: 96 settings per dataset instead of 16, about 6 x longer).
# --no-build: use the already built workspace instead of running scripts/setup.sh (install + build).
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
BAG="" TRUTH="" NAME="custom" BUILD=1
PASS=()
while (($#)); do
  case "$1" in
    --bag) BAG="$2"; shift 2 ;;
    --truth) TRUTH="$2"; shift 2 ;;
    --name) NAME="$2"; shift 2 ;;
    --full) PASS+=(--full); shift ;;
    --jobs) PASS+=(--jobs "$2"); shift 2 ;;
    --seeds) PASS+=(--seeds "$2"); shift 2 ;;
    --no-build) BUILD=0; shift ;;
    -h|--help) sed -n '2,17p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "parameter_study.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
if [[ -n "$BAG" && -z "$TRUTH" ]] || [[ -z "$BAG" && -n "$TRUTH" ]]; then
  echo "parameter_study.sh: --bag and --truth go together" >&2
  exit 2
fi

if ((BUILD)); then
  source "$HERE/setup.sh" >&2
else
  REPO="$(cd "$HERE/.." && pwd)"
  WS="${LASER_DPSLAM_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/laser_dpslam/ws-$(printf '%s' "$REPO" | md5sum | cut -c1-10)}"
  if [[ ! -f "$WS/devel/setup.bash" ]]; then
    echo "parameter_study.sh: no built workspace at $WS (run without --no-build)" >&2
    exit 1
  fi
  export PATH="/usr/bin:$PATH"
  set +u
  # shellcheck disable=SC1091
  source "$WS/devel/setup.bash"
  set -u
fi

OUT="$REPO/out/parameter_study"
if [[ -n "$BAG" ]]; then OUT="$REPO/out/parameter_study_$NAME"; fi
mkdir -p "$OUT"
DATASETS=()
if [[ -n "$BAG" ]]; then
  DATASETS+=(--dataset "$NAME" "$BAG" "$TRUTH")
else
  SIM="$OUT/sim_loop_building"
  SIMULATOR="$(catkin_find --first-only laser_dpslam simulate_scans 2>/dev/null || true)"
  stale=0
  for f in "$REPO/plans/loop_building.yaml" "$REPO/plans/loop_building.pgm" "$REPO/plans/loop_building_loop.txt" \
           "$SIMULATOR"; do
    if [[ -n "$f" && "$f" -nt "$SIM/sim.bag" ]]; then stale=1; fi
  done
  if [[ ! -f "$SIM/sim.bag" || ! -f "$SIM/ground_truth.tum" ]] || ((stale)); then
    echo "[parameter_study] simulating the loop of plans/loop_building (seed 1) -> $SIM" >&2
    rosrun laser_dpslam simulate_scans --floorplan "$REPO/plans/loop_building.yaml" --path loop --out "$SIM" \
      --seed 1 >&2
  fi
  DATASETS+=(--dataset loop_building "$SIM/sim.bag" "$SIM/ground_truth.tum")
  DATASETS+=(--dataset demo_office "$REPO/bags/demo.bag" "$REPO/bags/demo_ground_truth.tum")
fi
exec /usr/bin/python3 "$HERE/parameter_study.py" "${DATASETS[@]}" --out "$OUT" ${PASS[@]+"${PASS[@]}"}
