#!/usr/bin/env bash
# `make test`: every check of the project, in the order that takes least wall time on two
# cores (docs/TESTING.md). Needs `source ./env.sh` (the Makefile does it).
#   1. ruff and catkin_lint (seconds; a lint error is found before anything runs);
#   2. pytest's live tests on two xdist workers, and beside them, in the background, the
#      rostests (mostly waiting on sim time) and, at the lowest priority, the `offline` tests
#      (no ROS, no timing claim: the unit tests, the offline runs and the quick bench's
#      sections that start no launch, test_bench_quick.py) on whatever CPU the live tests
#      leave idle;
#   3. pytest's `serial` tests (timing and memory claims), the offline tests going on beside
#      them on the CPU the serial tests leave idle (about one core of two).
# Every part runs even if one before it failed; the exit status is 1 if any failed, and the
# last lines name them with each part's wall time.
set -uo pipefail
: "${TAC_WS:?source ./env.sh first}"
cd "$(dirname "$0")/.."

failed=()
timings=()
timed() {  # timed NAME COMMAND...: run it, note its wall time and whether it failed
  local name=$1 started=$SECONDS
  shift
  "$@" || failed+=("$name")
  timings+=("$name $((SECONDS - started)) s")
}

timed ruff ruff check .
timed catkin_lint catkin_lint -W2 "$TAC_WS/src"

declare -A background_pid background_log background_started

in_background() {  # in_background NAME COMMAND...: its output goes to a log shown later
  local name=$1
  shift
  background_log[$name]=$(mktemp "${TMPDIR:-/tmp}/tac_${name}.XXXXXX")
  background_started[$name]=$SECONDS
  (
    "$@"
    status=$?
    echo "$name: finished after $((SECONDS - ${background_started[$name]})) s"
    exit "$status"
  ) > "${background_log[$name]}" 2>&1 &
  background_pid[$name]=$!
}

collect() {  # collect NAME BESIDE: wait for it, show its output, note its time and status
  local name=$1 beside=$2 status=0
  wait "${background_pid[$name]}" || status=$?
  cat "${background_log[$name]}"
  [ "$status" -eq 0 ] || failed+=("$name")
  timings+=("$name $(sed -n "s/^$name: finished after \\([0-9]*\\) s$/\\1/p" \
    "${background_log[$name]}") s (beside $beside)")
  rm -f "${background_log[$name]}"
  unset "background_pid[$name]"
}

stop_background() {
  local name
  for name in "${!background_pid[@]}"; do
    kill -- "${background_pid[$name]}" 2>/dev/null
    rm -f "${background_log[$name]}"
  done
}
trap stop_background EXIT

in_background rostests bash tools/run_rostests.sh
# At the lowest priority and from the start, the offline tests take only the CPU the live
# tests leave idle (little: the quick bench, here before them, got about 60 CPU s in their
# 640 s), then what the serial part leaves (about a core). `nice` alone is not enough: a
# process's nice ranks it only within its session's autogroup, which the offline tests'
# workers and subprocesses would share with the live tests' runner (tools/lowest_priority.py).
in_background pytest-offline python3 tools/lowest_priority.py \
  python3 -m pytest test/unit test/integration -q -rs -n 2 -m offline --durations=10
# Each worker takes whole modules (test/conftest.py's scheduler): a module's launch starts once.
timed pytest-parallel python3 -m pytest test/integration test/reliability \
  -q -rs -n 2 -m 'not serial and not offline' --durations=15
collect rostests pytest-parallel

# The serial tests take about one core of the two (measured: their test times unchanged
# beside the whole quick bench run at the lowest priority in sessions of their own).
timed pytest-serial python3 -m pytest test/integration test/reliability \
  -q -rs -m serial --durations=5
collect pytest-offline 'pytest-parallel, pytest-serial'

echo "make test: ${timings[*]/%/;} total $SECONDS s"
if [ "${#failed[@]}" -gt 0 ]; then
  echo "make test: FAILED: ${failed[*]}" >&2
  exit 1
fi
echo 'make test: all passed'
