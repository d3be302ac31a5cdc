# The project's commands. Each one sets the project up first when needed.
#   make setup   Debian packages, virtualenv, catkin workspace (idempotent)
#   make test    unit, integration and reliability tests (pytest), ruff and catkin_lint, the
#                rostests, and a one-run --quick bench of physics, offline, analysis and walking
#                (its code, not its speed: test_bench_quick.py)
#   make demo    the tutorial end to end, headless (TRAJ=step_and_fall|touchdown|touchdown_exhausted)
#                or a step that stands: make demo TRAJ=step_and_stand (Stepping.yaml, its gains)
#                or Atlas walking: make demo TRAJ=walk_straight (or walk_circle; run_demo.py --help)
#                or the VRC walking course, scored: make demo TRAJ=vrc_task_2 (vrc_walker.py)
#                (TRAJ=vrc_task_2_laser: each leg planned on what the head's laser has seen)
#                RTF=0.5 runs the simulator at half real time (a busy machine's late commands
#                matter half as much in sim time); TABLE=1 lists every joint's tracking error
#   make bench   the performance benchmark
#   make clean-bags  delete the bags in $TAC_BAG_DIR (else ~/.ros/tutorial_atlas_control/bags);
#                KEEP=N keeps the newest N
SHELL := /bin/bash
.SHELLFLAGS := -eo pipefail -c
TRAJ ?= step_and_fall
RTF ?= 1.0
IN_ENV := source ./env.sh &&

.PHONY: setup test unit-test lint rostest demo bench bench-quick clean-workspace clean-bags

setup:
	@bash tools/setup.sh

unit-test: setup
	@$(IN_ENV) python3 -m pytest test/unit -q -rs -n 2

lint: setup
	@$(IN_ENV) ruff check .
	@$(IN_ENV) catkin_lint -W2 "$$TAC_WS/src"

rostest: setup
	@$(IN_ENV) bash tools/run_rostests.sh

# Lint, the live tests on two workers beside the rostests, the serial tests, and the offline
# tests (the quick bench's offline sections among them) at the lowest priority throughout
# (tools/run_tests.sh; docs/TESTING.md).
test: setup
	@$(IN_ENV) bash tools/run_tests.sh

# Every section once, short windows (about 3.5 min): fails if the bench crashes or a figure is
# missing or NaN; a MISSED target does not fail it (bench/README.md).
bench-quick: setup
	@$(IN_ENV) python3 bench/run_bench.py --quick --runs 1

demo: setup
	@$(IN_ENV) python3 scripts/run_demo.py "$(TRAJ)" --real-time-factor "$(RTF)" $(if $(TABLE),--table)

bench: setup
	@$(IN_ENV) python3 bench/run_bench.py

clean-bags: setup
	@$(IN_ENV) python3 -m tutorial_atlas_control.cli.bag_housekeeping clean --keep "$(or $(KEEP),0)"

clean-workspace:
	@bash -c 'repo_dir=$$(pwd -P); source tools/paths.sh; rm -rf "$$TAC_HOME"; echo "removed $$TAC_HOME"'
