#!/usr/bin/env bash
# scripts/test.sh: set up and build (the package, and the robot drivers from ../shared/drivers when there:
# scripts/build_drivers.sh), run every test (gtest + nosetests + rostest through catkin), print the catkin
# summary, copy the JUnit XML to out/test_results/, exit non-zero on any failure.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
# The robot drivers (urg_node, create_driver) for the robot tests: built once here from the source snapshots
# and cached outside the repository (the tests call the same script, a no-op by then); without the sources
# those tests report themselves skipped, after a failed build they fail.
drivers_status=0
"$REPO/scripts/build_drivers.sh" > "$WS/drivers.log" 2>&1 || drivers_status=$?
case $drivers_status in
  0) echo "[laser_dpslam] robot drivers: $(tail -n 1 "$WS/drivers.log")" ;;
  3) echo "[laser_dpslam] robot drivers: not available, the robot tests will be skipped: $(tail -n 1 "$WS/drivers.log")" ;;
  *) echo "[laser_dpslam] robot drivers: build failed (the robot tests will fail); log: $WS/drivers.log" >&2 ;;
esac
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
cat "$WS/build/test_results/laser_dpslam/robot_drivers_summary.txt" 2>/dev/null | sed 's/^/[laser_dpslam] robot test: /' || true
if [[ $status -ne 0 ]]; then
  echo "[laser_dpslam] catkin_make run_tests failed (exit $status); log: $WS/test.log" >&2
  tail -n 40 "$WS/test.log" >&2
  exit 1
fi
exit $summary
