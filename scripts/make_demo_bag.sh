#!/usr/bin/env bash
# scripts/make_demo_bag.sh: regenerates the bundled demo data, bags/demo.bag and
# bags/demo_ground_truth.tum, with the simulator: one lap of plans/office_loop.txt (about 98 s, 10 Hz)
# in plans/office.yaml, default URG-04LX noise, seed 1. The output is deterministic.
# To redraw the floor plans themselves first: scripts/make_floorplans.py
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh" >&2

tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
# (rosrun's package search may warn about the workspace's symlink back into the repository: harmless.)
rosrun laser_dpslam simulate_scans --floorplan "$REPO/plans/office.yaml" --path loop --out "$tmp" --seed 1 \
  2> >(grep -v 'File system loop detected' >&2)

mkdir -p "$REPO/bags"
cp "$tmp/sim.bag" "$REPO/bags/demo.bag"
cp "$tmp/ground_truth.tum" "$REPO/bags/demo_ground_truth.tum"

size=$(stat -c %s "$REPO/bags/demo.bag")
echo "[laser_dpslam] wrote bags/demo.bag ($((size / 1024)) KiB) and bags/demo_ground_truth.tum"
if ((size > 5 * 1024 * 1024)); then
  echo "[laser_dpslam] bags/demo.bag is larger than 5 MB: shorten the path" >&2
  exit 1
fi
rosbag info "$REPO/bags/demo.bag"
