#!/usr/bin/env bash
# scripts/screenshot_rviz.sh [OUT.png] [roslaunch args…]: replay a bag through launch/bag.launch with rviz
# in a virtual X server (Xvfb, software OpenGL) and save a screenshot, then stop everything.
#   scripts/screenshot_rviz.sh                       # demo bag, SLAM, fixed frame map -> doc/rviz.png
#   scripts/screenshot_rviz.sh out/odom.png slam:=false   # laser odometry only (fixed frame odom)
# WAIT=S: seconds of wall time before the shot (default 45; the demo bag is 98 s at rate 1).
# Installs xvfb, rviz and imagemagick with apt when missing (idempotent). No roscore needed: roslaunch
# starts a private master on a free port, so it does not disturb a running ROS system.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="$REPO/doc/rviz.png"
if [[ $# -gt 0 && "$1" != *:=* ]]; then OUT="$1"; shift; fi
case "$OUT" in /*) ;; *) OUT="$PWD/$OUT" ;; esac
WAIT="${WAIT:-45}"

missing=()
for p in xvfb rviz imagemagick; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "[screenshot_rviz] installing ${missing[*]}"
  SUDO=""
  if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# shellcheck source=setup.sh
source "$REPO/scripts/setup.sh"   # builds the workspace and sources it

free_port() { /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("",0)); print(s.getsockname()[1])'; }
PORT="$(free_port)"
export ROS_MASTER_URI="http://localhost:$PORT"
DISPLAY_NUM=$((90 + RANDOM % 100))
while [[ -e "/tmp/.X${DISPLAY_NUM}-lock" ]]; do DISPLAY_NUM=$((DISPLAY_NUM + 1)); done
export DISPLAY=":$DISPLAY_NUM"
export LIBGL_ALWAYS_SOFTWARE=1
LOG_DIR="$(mktemp -d /tmp/screenshot_rviz.XXXXXX)"

XVFB_PID="" LAUNCH_PID=""
cleanup() {
  # Stop only what this script started: roslaunch (SIGINT, it stops its nodes and master), then Xvfb.
  if [[ -n "$LAUNCH_PID" ]] && kill -0 "$LAUNCH_PID" 2>/dev/null; then
    kill -INT "$LAUNCH_PID" 2>/dev/null || true
    for _ in $(seq 1 30); do kill -0 "$LAUNCH_PID" 2>/dev/null || break; sleep 0.5; done
    kill -TERM "$LAUNCH_PID" 2>/dev/null || true
  fi
  if [[ -n "$XVFB_PID" ]]; then kill -TERM "$XVFB_PID" 2>/dev/null || true; fi
}
trap cleanup EXIT

Xvfb "$DISPLAY" -screen 0 1200x800x24 -nolisten tcp > "$LOG_DIR/xvfb.log" 2>&1 &
XVFB_PID=$!
sleep 2
kill -0 "$XVFB_PID" 2>/dev/null || { cat "$LOG_DIR/xvfb.log"; echo "[screenshot_rviz] Xvfb failed" >&2; exit 1; }

echo "[screenshot_rviz] roslaunch laser_dpslam bag.launch rviz:=true $* (display $DISPLAY, master port $PORT)"
roslaunch -p "$PORT" laser_dpslam bag.launch rviz:=true "$@" > "$LOG_DIR/roslaunch.log" 2>&1 &
LAUNCH_PID=$!
for _ in $(seq 1 "$WAIT"); do
  sleep 1
  kill -0 "$LAUNCH_PID" 2>/dev/null || { tail -n 30 "$LOG_DIR/roslaunch.log"; echo "[screenshot_rviz] roslaunch exited early" >&2; exit 1; }
done
mkdir -p "$(dirname "$OUT")"
import -display "$DISPLAY" -window root "$OUT"
echo "[screenshot_rviz] wrote $OUT (logs in $LOG_DIR)"
