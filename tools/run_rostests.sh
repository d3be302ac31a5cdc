#!/usr/bin/env bash
# Runs every rostest registered with add_rostest (catkin's run_tests target), then
# summarises the results; exits non-zero if any failed. Needs `source ./env.sh`.
set -euo pipefail
: "${TAC_WS:?source ./env.sh first}"
cd "$TAC_WS"
rm -rf "$TAC_WS/build/test_results/tutorial_atlas_control"
catkin_make -j1 run_tests_tutorial_atlas_control -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 > "$TAC_WS/run_tests.log" 2>&1 \
  || { tail -60 "$TAC_WS/run_tests.log" >&2; echo "rostests: the run failed; full log: $TAC_WS/run_tests.log" >&2; exit 1; }
status=0
summary=$(catkin_test_results --verbose "$TAC_WS/build/test_results/tutorial_atlas_control") || status=$?
printf '%s\n' "$summary"
# The plain closing line: "rostests: N passed, N failed".
counts=$(printf '%s\n' "$summary" | sed -n \
  's/^Summary: \([0-9]*\) tests, \([0-9]*\) errors, \([0-9]*\) failures, \([0-9]*\) skipped$/\1 \2 \3 \4/p')
if [ -n "$counts" ]; then
  read -r tests errors failures skipped <<< "$counts"
  echo "rostests: $((tests - errors - failures - skipped)) passed, $((errors + failures)) failed, $skipped skipped"
  # As for pytest (test/conftest.py): with TAC_REQUIRE_ALL=1 (CI) a skip fails the run.
  if [ "$skipped" -gt 0 ] && [ "${TAC_REQUIRE_ALL:-0}" != 0 ]; then
    echo "rostests: TAC_REQUIRE_ALL=1: $skipped test(s) skipped, which fails the run" >&2
    status=1
  fi
fi
exit "$status"
