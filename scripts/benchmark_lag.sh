#!/usr/bin/env bash
# scripts/benchmark_lag.sh: dpslam_node when the CPU is short. bags/demo.bag is played at 1x (`rosbag play
# --clock`, use_sim_time) through laser_odometry_node and dpslam_node (launch/slam.launch, config/*.yaml),
# both pinned to one core (`taskset -c CORE`), with the SLAM's work stretched by `work_multiplier` (after each
# scan dpslam_node busy-waits (multiplier - 1) x the CPU time the scan took: a CPU that many times slower).
# rosbag play and the listener (scripts/lag_listener.py) run on the other core. One row per multiplier:
#   scans processed / skipped   from dpslam_node's /diagnostics at the end
#   lag median / p95 / max      of every map -> odom transform: /clock time when it arrived - its stamp
#   ATE                         RMSE against bags/demo_ground_truth.tum (evaluate_trajectory, SE(2)
#                               aligned) of the last `trajectory` path (up to the last map publication,
#                               <= map_update_interval before the end) and of the live `pose`
#   WARN/all                    dpslam_node's /diagnostics statuses that were WARN (scans skipped or lag
#                               > 1 s in their second) / all of them
# Usage: scripts/benchmark_lag.sh [--multipliers "1 3"] [--core 0] [--player-core 1]
# The ROS master runs on a port of its own (BENCHMARK_PORT, default a free one); everything started here is
# stopped at the end. Outputs in out/benchmark_lag/xM/.
set -euo pipefail
MULTIPLIERS="1 3"
CORE=0
PLAYER_CORE=1
while [[ "${1:-}" == --* ]]; do
  case "$1" in
    --multipliers) MULTIPLIERS="$2"; shift 2 ;;
    --core) CORE="$2"; shift 2 ;;
    --player-core) PLAYER_CORE="$2"; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh" > /dev/null
BAG="$REPO/bags/demo.bag"
REFERENCE="$REPO/bags/demo_ground_truth.tum"
OUT="$REPO/out/benchmark_lag"
mkdir -p "$OUT"

free_port() { /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])'; }
PORT="${BENCHMARK_PORT:-$(free_port)}"
export ROS_MASTER_URI="http://localhost:$PORT"
export ROS_LOG_DIR="$OUT/log"

CORE_PID="" LAUNCH_PID="" LISTENER_PID="" PLAY_PID=""
# stop PID: SIGINT (roslaunch, roscore and rospy stop their children and write their outputs), then TERM.
stop() {
  local pid=$1
  [[ -n "$pid" ]] && kill -0 "$pid" 2>/dev/null || return 0
  kill -INT "$pid" 2>/dev/null || true
  for _ in $(seq 1 40); do kill -0 "$pid" 2>/dev/null || return 0; sleep 0.25; done
  kill -TERM "$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || true
}
cleanup() {
  stop "$PLAY_PID"; stop "$LISTENER_PID"; stop "$LAUNCH_PID"; stop "$CORE_PID"
  PLAY_PID="" LISTENER_PID="" LAUNCH_PID="" CORE_PID=""
}
trap cleanup EXIT

wait_for() {  # wait_for SECONDS COMMAND...: until COMMAND succeeds
  local t=$1; shift
  for _ in $(seq 1 $((t * 4))); do "$@" > /dev/null 2>&1 && return 0; sleep 0.25; done
  return 1
}
subscribed() { rostopic info /scan 2>/dev/null | grep -q dpslam_node; }

printf "%-5s %9s %7s %10s %10s %10s %11s %11s %9s\n" mult processed skipped "lag med s" "lag p95 s" "lag max s" "ATE traj m" "ATE pose m" "WARN/all"
for m in $MULTIPLIERS; do
  dir="$OUT/x$m"
  rm -rf "$dir"
  mkdir -p "$dir"
  taskset -c "$PLAYER_CORE" roscore -p "$PORT" > "$dir/roscore.log" 2>&1 &
  CORE_PID=$!
  wait_for 30 rosparam list || { tail "$dir/roscore.log"; echo "roscore did not start" >&2; exit 1; }
  rosparam set use_sim_time true
  rosparam set /dpslam_node/work_multiplier "$m"
  taskset -c "$CORE" roslaunch laser_dpslam slam.launch > "$dir/nodes.log" 2>&1 &
  LAUNCH_PID=$!
  taskset -c "$PLAYER_CORE" /usr/bin/python3 "$REPO/scripts/lag_listener.py" --out "$dir" > "$dir/listener.log" 2>&1 &
  LISTENER_PID=$!
  wait_for 60 subscribed || { tail "$dir/nodes.log"; echo "dpslam_node did not subscribe to /scan" >&2; exit 1; }
  sleep 2
  taskset -c "$PLAYER_CORE" rosbag play --clock --quiet --delay=1 "$BAG" > "$dir/play.log" 2>&1 &
  PLAY_PID=$!
  wait "$PLAY_PID" || true
  PLAY_PID=""
  sleep 3  # the last scans' processing and diagnostics
  stop "$LISTENER_PID"; LISTENER_PID=""
  stop "$LAUNCH_PID"; LAUNCH_PID=""
  stop "$CORE_PID"; CORE_PID=""
  ate() {
    if [[ -s "$dir/$1.tum" ]] && rosrun laser_dpslam evaluate_trajectory --estimate "$dir/$1.tum" \
         --reference "$REFERENCE" > "$dir/ate_$1.json" 2> "$dir/ate_$1.err"; then
      /usr/bin/python3 -c 'import json,sys; print("%.4f" % json.load(open(sys.argv[1]))["ate_rmse_m"])' "$dir/ate_$1.json"
    else
      echo "-"
    fi
  }
  ate_traj=$(ate trajectory)
  ate_pose=$(ate pose)
  /usr/bin/python3 - "$dir/summary.json" "$m" "$ate_traj" "$ate_pose" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1]))
d = (s.get("diagnostics") or {}).get("values", {})
f = lambda v: "-" if v is None else "%.3f" % v
levels = s.get("diagnostics_levels", {})
warn = "%d/%d" % (levels.get("1", 0), sum(levels.values()))
print("%-5s %9s %7s %10s %10s %10s %11s %11s %9s" % (sys.argv[2], d.get("scans processed", "-"), d.get("scans skipped", "-"),
      f(s["lag_median_s"]), f(s["lag_p95_s"]), f(s["lag_max_s"]), sys.argv[3], sys.argv[4], warn))
EOF
done
echo "(nodes on core $CORE, rosbag play at 1x and the listener on core $PLAYER_CORE; outputs in $OUT)"
