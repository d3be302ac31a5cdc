"""A change's before and after in one process: another revision's package, copied and renamed
`tac_before` (its own compiled library beside it), against this tree's, interleaved, each
figure (process time) beside a bare mj_step timed in the same round (not a `make bench`
section: a decision's figures, run by hand).

    python3 bench/before_after.py --ref main --library OLD.so [--rounds 9] [--pairs 3] [--loop]

--library: the library built from that revision's sources (e.g. the main checkout's
devel/lib/libtutorial_atlas_control_law.so, copied before it is rebuilt); this tree's comes
from the environment as usual. Figures: one estimate (four states, as estimator_cost.py's;
its sole contacts and support polygon asked for), the balancing Stand's tick (stand_run's,
process time) and Walk's (walk_trial of 6 steps, CPU); with --loop the whole offline walk's
CPU per simulated step too. Prints the medians, their ratios to
mj_step and after/before per pair, and the load (`uptime`) before and after.
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from types import ModuleType

from estimator_cost import BareStep, placed_states
from harness import REPO_DIR
from offline import GAINS_YAML

AFTER, BEFORE = 'tutorial_atlas_control', 'tac_before'
#: The copy's native.LIBRARY_ENV, so that each package loads its own library.
BEFORE_LIBRARY_ENV = 'TAC_LAW_LIBRARY_BEFORE'


def copy_renamed(ref: str, directory: Path) -> None:
    """`ref`'s package as `directory`/tac_before: imports renamed, its data read from this
    checkout's package directory, its library from BEFORE_LIBRARY_ENV."""
    archive = subprocess.run(['git', '-C', str(REPO_DIR), 'archive', ref,
                              'src/tutorial_atlas_control'], capture_output=True, check=True)
    subprocess.run(['tar', '-x', '-C', str(directory)], input=archive.stdout, check=True)
    package = directory / BEFORE
    (directory / 'src' / AFTER).rename(package)
    data = REPO_DIR / 'src' / AFTER
    for path in package.rglob('*.py'):
        text = re.sub(rf'\b(from|import) {AFTER}\b', rf'\1 {BEFORE}', path.read_text())
        text = text.replace("_MODULE_DIR = Path(__file__).resolve().parent",
                            f"_MODULE_DIR = Path('{data}')")
        text = text.replace("LIBRARY_ENV = 'TAC_LAW_LIBRARY'",
                            f"LIBRARY_ENV = '{BEFORE_LIBRARY_ENV}'")
        path.write_text(text)


def _module(package: str, name: str) -> ModuleType:
    return importlib.import_module(f'{package}.{name}')


def estimate_us(package: str, repeats: int = 300) -> float:
    """Process µs of one compiled estimate, its contacts and polygon asked for."""
    atlas = _module(package, 'sim.model').load_model()
    estimator = _module(package, 'balance').BalanceEstimator(atlas, compiled=True)
    if not estimator.compiled:
        raise SystemExit(f'{package}: the compiled library did not load')
    states = placed_states(atlas)
    start = time.process_time()
    for _ in range(repeats):
        for qpos, qvel in states:
            state = estimator.estimate(qpos, qvel)
            state.sole_contacts, state.support_polygon  # noqa: B018
    return (time.process_time() - start) / (repeats * len(states)) * 1e6


def stand_us(package: str, warmup_steps: int = 2500, steps: int = 3000) -> float:
    """Process µs of the balancing Stand's torque() a step (offline.stand_run's run)."""
    sim = _module(package, 'sim.simulator').AtlasSimulator(
        _module(package, 'sim.model').load_model(),
        _module(package, 'sim.controller').load_gains_yaml(GAINS_YAML))
    stand = _module(package, 'balance').TimedStand(sim.atlas, clock=time.process_time)
    sim.install_stand(stand)
    for _ in range(warmup_steps):
        sim.step()
    stand.spent_s = 0.0
    for _ in range(steps):
        sim.step()
    return stand.spent_s / steps * 1e6


def walk_us(package: str, steps: int = 6) -> float:
    """Walk's controller CPU µs a step over offline.walk_run's trial."""
    walking, trial_module = _module(package, 'walking'), _module(package, 'walking.walk_trial')
    trial = trial_module.walk_trial(walking.straight_steps(steps, 0.25),
                                    trial_module.SETTLE_S + 0.6 + steps * 0.63 + 0.8)
    if trial.fell or trial.steps != steps:
        raise SystemExit(f'{package}: the walk fell or took {trial.steps} of {steps} steps')
    return trial.cost_per_step_us


def walk_loop_us(package: str, steps: int = 6) -> float:
    """The whole offline walk's CPU µs per simulated step (offline.walk_run's trial: set-up,
    physics, controller and the trial's bookkeeping): over a bare mj_step, the
    walk_offline_bare_ratio of the same trial."""
    walking, trial_module = _module(package, 'walking'), _module(package, 'walking.walk_trial')
    sim_s = trial_module.SETTLE_S + 0.6 + steps * 0.63 + 0.8
    start = time.process_time()
    trial = trial_module.walk_trial(walking.straight_steps(steps, 0.25), sim_s)
    spent = time.process_time() - start
    if trial.fell or trial.steps != steps:
        raise SystemExit(f'{package}: the walk fell or took {trial.steps} of {steps} steps')
    return spent / round(sim_s / 0.001) * 1e6


def compare(name: str, measure: Callable[[str], float], rounds: int, bare: BareStep) -> None:
    """`rounds` interleaved pairs of `measure`, each round beside a bare mj_step."""
    figures: dict[str, list[float]] = {BEFORE: [], AFTER: []}
    steps = []
    for index in range(rounds):
        steps.append(bare.us())
        for package in (BEFORE, AFTER) if index % 2 == 0 else (AFTER, BEFORE):
            figures[package].append(measure(package))
    step = statistics.median(steps)
    parts = [f'{label} {statistics.median(v):.1f} µs = {statistics.median(v) / step:.2f} '
             f'mj_step ({min(v):.1f}–{max(v):.1f})'
             for label, v in (('before', figures[BEFORE]), ('after', figures[AFTER]))]
    pairs = [a / b for b, a in zip(figures[BEFORE], figures[AFTER], strict=True)]
    print(f'{name}: {"; ".join(parts)}; after/before per pair {statistics.median(pairs):.3f} '
          f'({min(pairs):.3f}–{max(pairs):.3f}); bare mj_step {step:.1f} µs '
          f'({min(steps):.1f}–{max(steps):.1f})', flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--ref', default='main', help='the revision before the change')
    parser.add_argument('--library', type=Path, required=True,
                        help="the library built from that revision's sources")
    parser.add_argument('--rounds', type=int, default=9, help='estimate rounds')
    parser.add_argument('--pairs', type=int, default=3, help='Stand and Walk rounds')
    parser.add_argument('--loop', action='store_true',
                        help="also the whole offline walk's CPU per simulated step")
    args = parser.parse_args()
    if not args.library.is_file():
        raise SystemExit(f'before_after.py: --library {args.library}: no such file')
    os.environ[BEFORE_LIBRARY_ENV] = str(args.library)
    with tempfile.TemporaryDirectory(prefix='tac_before_') as directory:
        copy_renamed(args.ref, Path(directory))
        sys.path.insert(0, directory)
        uptime = ['uptime']
        print('load before:', subprocess.run(uptime, capture_output=True, text=True).stdout.strip())
        bare = BareStep()
        compare('estimate', estimate_us, args.rounds, bare)
        compare('Stand µs/tick (torque(), process time)', stand_us, args.pairs, bare)
        compare('Walk µs/tick (walk_trial, 6 steps, CPU)', walk_us, args.pairs, bare)
        if args.loop:
            compare('offline walk µs/step (walk_trial, 6 steps, whole CPU)', walk_loop_us,
                    args.pairs, bare)
        print('load after:', subprocess.run(uptime, capture_output=True, text=True).stdout.strip())


if __name__ == '__main__':
    main()
