#!/usr/bin/env bash
# Shared set-up for demo.sh, test.sh and run.sh: install the missing Debian packages, then build a
# catkin workspace whose src/laser_dpslam links to this repository. The workspace lives outside the
# repository (~/.cache/laser_dpslam/ws-<hash of the path>, or $LASER_DPSLAM_WS) so that rospack does not
# see a file-system loop. Idempotent and quick when nothing changed. Source it: it exports REPO and WS
# and sources the workspace.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
WS="${LASER_DPSLAM_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/laser_dpslam/ws-$(printf '%s' "$REPO" | md5sum | cut -c1-10)}"
export REPO WS

DEB_PACKAGES=(
  build-essential cmake catkin ros-core-dev libroscpp-dev librosbag-dev
  libtf2-ros-dev libtf2-geometry-msgs-dev libtf2-msgs-dev libsensor-msgs-dev libnav-msgs-dev
  libgeometry-msgs-dev libdiagnostic-updater-dev libdiagnostic-msgs-dev libeigen3-dev libyaml-cpp-dev libgtest-dev
  python3-rosbag python3-rostest python3-rosunit python3-rospy python3-nose rosbash
  python3-sensor-msgs python3-nav-msgs python3-geometry-msgs python3-tf2-msgs python3-tf2-ros tf2-tools
  python3-diagnostic-msgs
  python3-numpy python3-matplotlib python3-yaml
  ros-message-generation ros-message-runtime python3-genmsg python3-gencpp python3-genpy
)

missing=()
for p in "${DEB_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "[laser_dpslam] installing ${#missing[@]} Debian packages: ${missing[*]}"
  SUDO=""
  if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

mkdir -p "$WS/src"
if [[ "$(readlink "$WS/src/laser_dpslam" 2>/dev/null)" != "$REPO" ]]; then
  rm -f "$WS/src/laser_dpslam"
  ln -s "$REPO" "$WS/src/laser_dpslam"
fi

# catkin needs the system Python (not a pyenv one that may be first on PATH).
export PATH="/usr/bin:$PATH"
echo "[laser_dpslam] building in $WS"
(
  cd "$WS"
  if ! catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=Release \
       -j"$(nproc)" > "$WS/build.log" 2>&1; then
    tail -n 60 "$WS/build.log"
    echo "[laser_dpslam] build failed (full log: $WS/build.log)" >&2
    exit 1
  fi
)
# Sourced from a function so that catkin's setup does not see the caller's arguments.
_laser_dpslam_source_ws() {
  set +u
  # shellcheck disable=SC1091
  source "$WS/devel/setup.bash"
  set -u
}
_laser_dpslam_source_ws
