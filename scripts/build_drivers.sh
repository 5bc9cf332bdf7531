#!/usr/bin/env bash
# scripts/build_drivers.sh: builds the robot's drivers (urg_node, urg_c, laser_proc, create_autonomy with
# create_driver, libcreate, roslint) from source snapshots into a catkin workspace of their own, outside the
# repository, and prints the path of its setup.bash. None of them is a Debian package.
#
# Sources: the archives in $LASER_DPSLAM_DRIVERS (default: ../shared/drivers beside the repository), one
# .tar.gz per package, with debian12.patch (Boost 1.74 placeholders, pluginlib's .hpp header). The build is
# cached under ~/.cache/laser_dpslam/drivers-<hash of the archives> (or $LASER_DPSLAM_DRIVERS_WS): a second
# run only prints the path. Exit status 3 (and the reason on stderr) when the sources are not there.
#
# Usage: scripts/build_drivers.sh            # build if needed, print .../devel_isolated/setup.bash
#        source "$(scripts/build_drivers.sh)" # then roslaunch laser_dpslam robot.launch finds the drivers
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SRC="${LASER_DPSLAM_DRIVERS:-$REPO/../shared/drivers}"
ARCHIVES=(urg_node urg_c laser_proc create_autonomy libcreate roslint)

for a in "${ARCHIVES[@]}"; do
  if [[ ! -f "$SRC/$a.tar.gz" ]]; then
    echo "[build_drivers] driver sources not available: no $SRC/$a.tar.gz (set LASER_DPSLAM_DRIVERS)" >&2
    exit 3
  fi
done
KEY="$(for a in "${ARCHIVES[@]}"; do md5sum < "$SRC/$a.tar.gz"; done; [[ -f "$SRC/debian12.patch" ]] && md5sum < "$SRC/debian12.patch")"
KEY="$(printf '%s' "$KEY" | md5sum | cut -c1-10)"
WS="${LASER_DPSLAM_DRIVERS_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/laser_dpslam/drivers-$KEY}"
SETUP="$WS/devel_isolated/setup.bash"
if [[ -f "$WS/.built" && -f "$SETUP" ]]; then
  echo "$SETUP"
  exit 0
fi

# Debian packages the drivers need beyond the project's own (scripts/setup.sh installs those).
DEB_PACKAGES=(
  libnodeletlib-dev libnodeletlib-tools libnodelet-dev libdiagnostic-updater-dev
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure libtf-dev libboost-all-dev
  libdiagnostic-msgs-dev pluginlib-dev libstd-msgs-dev libsensor-msgs-dev libnav-msgs-dev
  libgeometry-msgs-dev libtf2-ros-dev libtf2-geometry-msgs-dev catkin ros-core-dev libroscpp-dev
  ros-message-generation ros-message-runtime python3-genmsg python3-gencpp python3-genpy
)
missing=()
for p in "${DEB_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "[build_drivers] installing ${#missing[@]} Debian packages: ${missing[*]}" >&2
  SUDO=""
  if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

echo "[build_drivers] building the drivers in $WS (a few minutes, once)" >&2
rm -rf "$WS"
mkdir -p "$WS/src"
for a in "${ARCHIVES[@]}"; do tar -xzf "$SRC/$a.tar.gz" -C "$WS/src"; done
if [[ -f "$SRC/debian12.patch" ]]; then
  (cd "$WS/src" && patch -p1 -s < "$SRC/debian12.patch")
fi
# catkin needs the system Python; libcreate is a plain CMake package, hence catkin_make_isolated.
(
  cd "$WS"
  export PATH="/usr/bin:$PATH"
  if ! catkin_make_isolated -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=Release \
       --make-args -j"$(nproc)" > "$WS/build.log" 2>&1; then
    tail -n 40 "$WS/build.log" >&2
    echo "[build_drivers] build failed (full log: $WS/build.log)" >&2
    exit 1
  fi
)
touch "$WS/.built"
echo "$SETUP"
