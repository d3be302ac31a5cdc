"""Pushes while walking: sideways pelvis pushes at a random phase every few seconds of a
streamed walk, offline, and the largest push survived.

Each run plays, without ROS: DRCSim 2.7's start (bdi_stand), then from 3 s a client
streaming a WALK of `--steps` straight steps of 0.25 m at 0.63 s on every state (as
walk_client.py), and every `--every` seconds of the walk a push of `--force` N for `--push`
s through the simulator's pelvis wrench (as /atlas/apply_pelvis_force), at a phase and to a
side drawn from the run's seed (walk_trial.random_pushes), which also perturbs the start
(start_noise: the joints' angles and rates). A run falls when the state says ERROR_FALLING.
With `--search`, the force is raised in 25 N steps until a run of the seeds falls.
`run_bench.py` runs it as its `walking` section (bench/walking.py).

usage: python3 bench/walk_pushes.py [--steps N] [--force N] [--push S] [--every S]
       [--runs N] [--first-seed K] [--workers W] [--search]
(after `source ./env.sh`; about 4 CPU s a run of 20 steps). Figures: bench/README.md.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass

from walk_variations import CONFIG, DURATION_S, STEP_S, WIDTH_M, walk_command

from tutorial_atlas_control.asi import AtlasSimInterface, Status, WalkClient
from tutorial_atlas_control.sim import AtlasSimulator, VrcMode, load_gains_yaml, load_model
from tutorial_atlas_control.sim.vrc import WrenchInput
from tutorial_atlas_control.walking import perturb_start, placed, random_pushes, straight_steps

#: The walk starts at this sim time (s): Stand balances from 2 s and settles (a walk sent at
#: 3.0 s, as its transition ends, fell at step 5 of 20 here, one at 4 s walks).
WALK_AT_S = 4.0
STRIDE_M = 0.25
#: Sim time (s) after the walk's last step before a run that stood is over.
SETTLE_S = 3.0
SEARCH_STEP_N = 25.0


@dataclass(frozen=True)
class Outcome:
    """One run: whether it fell, the steps taken, and the pushes given (s of sim time, N)."""

    seed: int
    force_n: float
    fell: bool
    steps: int
    pushes: tuple[tuple[float, float], ...]


def run(seed: int | None, steps: int, force_n: float, push_s: float, every_s: float
        ) -> Outcome:
    """One pushed walk (see the module docstring); seed None: the start unperturbed, the
    pushes drawn from seed 0."""
    sim = AtlasSimulator(load_model(), load_gains_yaml(CONFIG), startup_mode=VrcMode.BDI_STAND)
    perturb_start(sim.atlas, sim.data, seed, on_ground=False)  # pinned in the air at first
    interface = AtlasSimInterface(sim, True)
    walk_at = round(WALK_AT_S / STEP_S)
    duration = steps * DURATION_S + SETTLE_S
    pushes = [(round(p.start_s / STEP_S), round((p.start_s + p.duration_s) / STEP_S),
               p.force_n[1])  # (start step, end step, signed force)
              for p in random_pushes(0 if seed is None else seed, WALK_AT_S,
                                     WALK_AT_S + steps * DURATION_S, force_n, push_s, every_s)]
    client: WalkClient | None = None
    taken = 0
    state = interface.state()
    for k in range(walk_at + round(duration / STEP_S)):
        for start, end, force in pushes:
            if k == start:
                sim.apply_input(WrenchInput((0.0, force, 0.0), (0.0, 0.0, 0.0)))
            elif k == end:
                sim.apply_input(WrenchInput((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)))
        if k == walk_at:
            feet = state.foot_poses
            origin = (0.5 * float(feet[0][0] + feet[1][0]), 0.5 * float(feet[0][1] + feet[1][1]))
            client = WalkClient(placed(straight_steps(steps, STRIDE_M, WIDTH_M, DURATION_S),
                                       origin, 0.0))
        if client is not None and client.outcome is None:
            feedback = state.walk_feedback
            window = client.on_state(state.current_behavior,
                                     state.behavior_feedback.status_flags,
                                     feedback.current_step_index,
                                     feedback.next_step_index_needed)
            if window is not None:
                interface.apply(walk_command(window))
        sim.step()
        state = interface.state()  # the state the step publishes: the client's next input
        interface.end_step()
        taken = max(taken, state.walk_feedback.current_step_index)
        if state.behavior_feedback.status_flags == Status.ERROR_FALLING:
            return Outcome(-1 if seed is None else seed, force_n, True, taken,
                           tuple((round(s * STEP_S, 3), f) for s, _, f in pushes
                                 if s <= k))
    return Outcome(-1 if seed is None else seed, force_n, False, taken,
                   tuple((round(s * STEP_S, 3), f) for s, _, f in pushes))


def _run(job: tuple[int, int, float, float, float]) -> Outcome:
    return run(*job)


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog='walk_pushes.py', description=__doc__.split('\n\n')[0],
        epilog='Prints one JSON line a run, then a summary line.')
    parser.add_argument('--steps', type=int, default=8, help='steps of the walk (default 8)')
    parser.add_argument('--force', type=float, default=150.0, help='push (N; default 150)')
    parser.add_argument('--push', type=float, default=0.1, help='push length (s; default 0.1)')
    parser.add_argument('--every', type=float, default=5.0,
                        help='one push in each this many seconds of the walk (default 5)')
    parser.add_argument('--runs', type=int, default=4, help='seeds (default 4)')
    parser.add_argument('--first-seed', type=int, default=0, help='first seed (default 0)')
    parser.add_argument('--workers', type=int, default=2, help='processes (default 2)')
    parser.add_argument('--search', action='store_true',
                        help=f'raise the force by {SEARCH_STEP_N:g} N from --force until a '
                             'run falls; print the largest force every seed survived')
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = _parser()
    args = parser.parse_args(argv)
    if args.steps < 1 or args.runs < 1 or args.workers < 1 or args.first_seed < 0 \
            or not (math.isfinite(args.force) and args.force >= 0.0) \
            or not 0.0 < args.push < args.every:
        parser.error('--steps, --runs and --workers are at least 1, --first-seed at least 0, '
                     '--force at least 0 N, 0 < --push < --every')
    seeds = range(args.first_seed, args.first_seed + args.runs)
    force, survived = args.force, None
    with ProcessPoolExecutor(args.workers) as pool:
        while True:
            jobs = [(seed, args.steps, force, args.push, args.every) for seed in seeds]
            outcomes = list(pool.map(_run, jobs))
            for outcome in outcomes:
                print(json.dumps(asdict(outcome)), flush=True)
            fell = sum(outcome.fell for outcome in outcomes)
            print(f'{force:g} N for {args.push:g} s ({force * args.push:g} N s): {fell} of '
                  f'{len(outcomes)} fell', flush=True)
            if fell or not args.search:
                break
            survived = force
            force += SEARCH_STEP_N
    if args.search:
        print('largest push every seed survived: '
              + ('none' if survived is None else f'{survived:g} N ({survived * args.push:g} N s)'))
    return 0


if __name__ == '__main__':
    sys.exit(main())
