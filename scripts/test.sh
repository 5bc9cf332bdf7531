#!/usr/bin/env bash
# scripts/test.sh: set up and build (the package, and the robot drivers from ../shared/drivers when there:
# scripts/build_drivers.sh), run every test (gtest + nosetests + rostest through catkin), print the catkin
# summary, copy the JUnit XML to out/test_results/, exit non-zero on any failure.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
# The robot's drivers (urg_node, create_driver), built once from the source snapshots into a cached workspace
# of their own and put on the package path, so that the robot tests check robot.launch against them. Without
# the snapshots those tests report themselves skipped with the reason.
drivers_status=0
drivers_setup="$("$REPO/scripts/build_drivers.sh" 2> "$WS/drivers.log")" || drivers_status=$?
if ((drivers_status == 0)); then
  set +u
  # shellcheck disable=SC1090
  source "$drivers_setup" --extend
  set -u
  export LASER_DPSLAM_DRIVERS_SKIP=""
elif ((drivers_status == 3)); then
  LASER_DPSLAM_DRIVERS_SKIP="$(tail -n 1 "$WS/drivers.log")"
  export LASER_DPSLAM_DRIVERS_SKIP
  echo "[laser_dpslam] robot tests will be skipped: $LASER_DPSLAM_DRIVERS_SKIP"
else
  cat "$WS/drivers.log" >&2
  echo "[laser_dpslam] building the robot drivers failed" >&2
  exit 1
fi
cd "$WS"
rm -rf "$WS/build/test_results"
status=0
catkin_make run_tests -DPYTHON_EXECUTABLE=/usr/bin/python3 -j"$(nproc)" > "$WS/test.log" 2>&1 || status=$?
grep -E "^\[ +(RUN|OK|FAILED|PASSED) +\]|^\[ROSTEST\]|^FAIL|^ERROR|^Ran |^OK$" "$WS/test.log" | grep -v "^\[ RUN" || true
mkdir -p "$REPO/out/test_results"
rm -rf "$REPO/out/test_results"/*
cp -r "$WS/build/test_results/." "$REPO/out/test_results/" 2>/dev/null || true
summary=0
catkin_test_results "$WS/build/test_results" --verbose > "$WS/test_summary.log" 2>&1 || summary=$?
grep -v "^Skipping" "$WS/test_summary.log" | tail -n 40
if [[ $status -ne 0 ]]; then
  echo "[laser_dpslam] catkin_make run_tests failed (exit $status); log: $WS/test.log" >&2
  tail -n 40 "$WS/test.log" >&2
  exit 1
fi
exit $summary
