#!/usr/bin/env bash
# `make test`: every check of the project, in the order that takes least wall time on two
# cores (docs/TESTING.md). Needs `source ./env.sh` (the Makefile does it).
#   1. ruff and catkin_lint (seconds; a lint error is found before anything runs);
#   2. pytest's live tests on two xdist workers, and beside them, in the background, the
#      rostests (mostly waiting on sim time) and, at the lowest priority, the quick bench (it
#      must run and give every figure of its sections that start no launch; their values,
#      measured under load here, are not judged);
#   3. pytest's `serial` tests (timing and memory claims), and beside them, at the lowest
#      priority, the `offline` ones (no ROS, no timing claim: the unit tests and the offline
#      runs) on the CPU the serial tests leave idle (about one core of two).
# Every part runs even if one before it failed; the exit status is 1 if any failed, and the
# last lines name them with each part's wall time.
set -uo pipefail
: "${TAC_WS:?source ./env.sh first}"
cd "$(dirname "$0")/.."

failed=()
timings=()
# The quick bench's sections make test runs: those that start no launch, less the search and
# the sweep (their code runs in test_search and test_sweep; the search's generation of nine
# walks took 365-395 s at the lowest priority and kept the part going after the tests).
BENCH_SECTIONS=physics,offline,analysis,walking

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
# At the lowest priority: at equal priority its rtf-20 runs and searches took the tests' CPU
# and live tutorial runs lost commands. `nice` alone is not enough: its simulators run in
# sessions of their own (roslaunch), which the scheduler served like any test's
# (tools/lowest_priority.py); niced with their sessions, it takes what the tests leave idle.
# Its sections without a launch only: the launches' real-time windows, starved here, took
# 420 s and ran on into part 3 (docs/TESTING.md); `make bench-quick` runs every section.
in_background bench-quick python3 tools/lowest_priority.py \
  bash -c "python3 bench/run_bench.py --quick --runs 1 --only $BENCH_SECTIONS > /dev/null"
# Each worker takes whole modules (test/conftest.py's scheduler): a module's launch starts once.
timed pytest-parallel python3 -m pytest test/integration test/reliability \
  -q -rs -n 2 -m 'not serial and not offline' --durations=15
collect rostests pytest-parallel
collect bench-quick pytest-parallel

# The serial tests take about one core of the two; the offline tests, at the lowest priority
# in sessions of their own, take only what the serial ones leave (measured: the serial part's
# test times unchanged beside the whole quick bench run so).
in_background pytest-offline python3 tools/lowest_priority.py \
  python3 -m pytest test/unit test/integration -q -rs -n 2 -m offline --durations=10
timed pytest-serial python3 -m pytest test/integration test/reliability \
  -q -rs -m serial --durations=5
collect pytest-offline pytest-serial

echo "make test: ${timings[*]/%/;} total $SECONDS s"
if [ "${#failed[@]}" -gt 0 ]; then
  echo "make test: FAILED: ${failed[*]}" >&2
  exit 1
fi
echo 'make test: all passed'
