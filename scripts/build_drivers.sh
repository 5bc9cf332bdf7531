#!/usr/bin/env bash
# Builds the robot drivers robot.launch starts (urg_node, create_driver and what they need: urg_c,
# laser_proc, libcreate, roslint) from source snapshots into a catkin workspace of their own, outside the
# repository: none of them is a Debian package. The sources are tar.gz archives in
# $LASER_DPSLAM_DRIVERS (default: ../shared/drivers next to the repository; see its README.md). The
# workspace is ~/.cache/laser_dpslam/drivers-<hash of the archives> ($LASER_DPSLAM_DRIVERS_WS overrides)
# and is reused while the archives are unchanged, so a second run is a no-op.
#
# Prints the workspace's devel_isolated directory on the last line of stdout and exits 0 when the
# drivers are ready; exits 3 with the reason on stderr when there are no sources (callers skip the robot
# test then); any other non-zero exit is a failed build (log in the workspace).
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SRC="${LASER_DPSLAM_DRIVERS:-$REPO/../shared/drivers}"
ARCHIVES=(urg_c urg_node laser_proc libcreate create_autonomy roslint)
DEB_PACKAGES=(libnodeletlib-dev libnodeletlib-tools libnodelet-dev libdiagnostic-updater-dev
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure libtf-dev libboost-all-dev
  libdiagnostic-msgs-dev patch)

for f in "${ARCHIVES[@]/%/.tar.gz}" debian12.patch; do
  if [[ ! -f "$SRC/$f" ]]; then
    echo "driver sources not found: $SRC/$f (set LASER_DPSLAM_DRIVERS to the folder of the" \
         "driver snapshots, see scripts/build_drivers.sh)" >&2
    exit 3
  fi
done

hash="$(cd "$SRC" && cat "${ARCHIVES[@]/%/.tar.gz}" debian12.patch | md5sum | cut -c1-10)"
DWS="${LASER_DPSLAM_DRIVERS_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/laser_dpslam/drivers-$hash}"
mkdir -p "$(dirname "$DWS")"
# One build at a time (test runs of several checkouts share the cache); the others wait for it.
exec 9>"$DWS.lock"
flock 9
if [[ -f "$DWS/.built" ]]; then
  echo "$DWS/devel_isolated"
  exit 0
fi

missing=()
for p in "${DEB_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "[build_drivers] installing ${#missing[@]} Debian packages: ${missing[*]}" >&2
  SUDO=""
  if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq >&2
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
fi

echo "[build_drivers] building the drivers in $DWS (once; log: $DWS/build.log)" >&2
rm -rf "$DWS"
mkdir -p "$DWS/src"
for a in "${ARCHIVES[@]}"; do tar -xzf "$SRC/$a.tar.gz" -C "$DWS/src"; done
(cd "$DWS/src" && patch -p1 --forward -s < "$SRC/debian12.patch") >&2
export PATH="/usr/bin:$PATH"
(
  cd "$DWS"
  if ! catkin_make_isolated -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=Release \
       -j2 > "$DWS/build.log" 2>&1; then
    tail -n 40 "$DWS/build.log" >&2
    echo "[build_drivers] driver build failed (full log: $DWS/build.log)" >&2
    exit 1
  fi
)
touch "$DWS/.built"
echo "$DWS/devel_isolated"
