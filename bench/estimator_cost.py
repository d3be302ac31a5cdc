"""The balance estimator in C against its Python reference: per estimate, and per controller
tick of the bench's Stand and Walk (bench/offline.py's stand_run and walk_run), interleaved
in one process, each figure (process time) beside a bare mj_step timed in the same round
(not a `make bench` section: a decision's figures, run by hand).

    python3 bench/estimator_cost.py [--rounds 9] [--pairs 3] [--skip-runs] [--skip-estimates]
        [--ticks] [--kinds python swing compiled]

The estimator is chosen at its construction by TAC_ESTIMATOR, inverse statics by
TAC_STATICS, Walk's swing servo by TAC_SWING, the whole-body tick around the statics by
TAC_WHOLE_BODY, Walk's one call around the last two by TAC_LEGS, the walk's swinging tick
around that by TAC_WALK_SWING (`python`, else compiled); the runs compare all in Python, the
estimator compiled, the estimator and statics compiled, all but the whole-body tick compiled,
all but the legs' one call, all but the walk's swinging tick, and all compiled (--kinds picks
some); with --ticks, StandController.tick alone on a Stand
run's recorded inputs too. Each round alternates which goes first. Prints the
medians, their ratios to mj_step and to Python's in each pair, and the load (`uptime`)
before and after.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import time

import mujoco
import numpy as np
from node_loop import RESTORE_EVERY_STEPS, STANDING_AFTER_S
from offline import make_simulator, python_reference_switches, stand_run, walk_run

from tutorial_atlas_control.balance import (
    BalanceEstimator,
    StandController,
    TimedStand,
    place_in_stand_pose,
)
from tutorial_atlas_control.sim import model as atlas_model

KINDS = ('python', 'compiled')
#: The variables that switch the estimator, inverse statics, the swing servo, the
#: whole-body tick and Walk's one call around the last two to Python.
SWITCHES = ESTIMATOR, STATICS, SWING, WHOLE_BODY, LEGS, WALK_SWING = python_reference_switches()
#: The runs' kinds: the parts each runs in Python (all; all but the estimator; the swing
#: servo and the whole-body tick; the whole-body tick; Walk's one call around the pieces;
#: none).
RUN_KINDS = {'python': dict.fromkeys(SWITCHES, 'python'),
             'estimator': dict.fromkeys((STATICS, SWING, WHOLE_BODY, LEGS, WALK_SWING),
                                        'python'),
             'statics': dict.fromkeys((SWING, WHOLE_BODY, LEGS, WALK_SWING), 'python'),
             'swing': dict.fromkeys((WHOLE_BODY, LEGS, WALK_SWING), 'python'),
             'legs': dict.fromkeys((LEGS, WALK_SWING), 'python'),
             'walk_swing': {WALK_SWING: 'python'}, 'compiled': {}}


class BareStep:
    """A bare mj_step as bench/node_loop.py's bare_physics_run times it: from the state
    standing at STANDING_AFTER_S under the law, the last torques held, that snapshot
    restored every RESTORE_EVERY_STEPS steps (process time here)."""

    def __init__(self) -> None:
        sim = make_simulator()
        while sim.sim_time_ns < STANDING_AFTER_S * 1e9:
            sim.step()
        self.model, self.data = sim.model, sim.data
        self.spec = mujoco.mjtState.mjSTATE_INTEGRATION
        self.snapshot = np.empty(mujoco.mj_stateSize(self.model, self.spec))
        mujoco.mj_getState(self.model, self.data, self.snapshot, self.spec)

    def us(self, blocks: int = 5) -> float:
        """Process µs of one mj_step, over `blocks` restored blocks."""
        spent = 0.0
        for _ in range(blocks):
            mujoco.mj_setState(self.model, self.data, self.snapshot, self.spec)
            start = time.process_time()
            for _ in range(RESTORE_EVERY_STEPS):
                mujoco.mj_step(self.model, self.data)
            spent += time.process_time() - start
        return spent / (blocks * RESTORE_EVERY_STEPS) * 1e6


def estimate_us(estimator: BalanceEstimator, states: list[tuple[np.ndarray, np.ndarray]],
                repeats: int = 200) -> float:
    """Process µs of one estimate (with its sole contacts read, as Stand reads them)."""
    start = time.process_time()
    for _ in range(repeats):
        for qpos, qvel in states:
            estimator.estimate(qpos, qvel).sole_contacts  # noqa: B018
    return (time.process_time() - start) / (repeats * len(states)) * 1e6


def placed_states(atlas: atlas_model.AtlasModel) -> list[tuple[np.ndarray, np.ndarray]]:
    """Standing, moving, one foot lifted, and in the air."""
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    rng = np.random.default_rng(5)
    moving = rng.normal(0.0, 0.2, atlas.model.nv)
    lifted = data.qpos.copy()
    lifted[atlas.free_qpos_adr + 2] += 0.1
    tilted = data.qpos.copy()
    tilted[atlas.free_qpos_adr + 2] += 0.02
    tilted[atlas.free_qpos_adr + 4] += 0.05  # a roll: one sole off the ground
    return [(data.qpos.copy(), data.qvel.copy()), (data.qpos.copy(), moving),
            (tilted, moving), (lifted, moving)]


def _summary(name: str, figures: dict[str, list[float]], steps: list[float]) -> None:
    step = statistics.median(steps)
    parts = []
    for kind, values in figures.items():
        median = statistics.median(values)
        parts.append(f'{kind} {median:.1f} µs = {median / step:.2f} mj_step '
                     f'({min(values):.1f}–{max(values):.1f})')
    ratios = []
    kinds = list(figures)
    compared = [(kind, 'python') for kind in kinds if kind != 'python' and 'python' in figures]
    if 'statics' in figures and 'swing' in figures:  # what the swing servo's C adds
        compared.append(('swing', 'statics'))
    if 'swing' in figures and 'compiled' in figures:  # what the whole-body tick's C adds
        compared.append(('compiled', 'swing'))
    for kind, base in compared:
        pairs = [c / p for p, c in zip(figures[base], figures[kind], strict=True)]
        ratios.append(f'{kind}/{base} per pair median {statistics.median(pairs):.3f} '
                      f'({min(pairs):.3f}–{max(pairs):.3f})')
    print(f'{name}: {"; ".join(parts)}; {"; ".join(ratios)}; '
          f'bare mj_step {step:.1f} µs ({min(steps):.1f}–{max(steps):.1f})', flush=True)


def compare_estimates(rounds: int) -> None:
    atlas = atlas_model.load_model()
    states = placed_states(atlas)
    estimators = {'python': BalanceEstimator(atlas, compiled=False),
                  'compiled': BalanceEstimator(atlas, compiled=True)}
    assert estimators['compiled'].compiled, 'the compiled library is not built'
    figures: dict[str, list[float]] = {kind: [] for kind in KINDS}
    steps, bare = [], BareStep()
    for round_index in range(rounds):
        order = KINDS if round_index % 2 == 0 else KINDS[::-1]
        steps.append(bare.us())
        for kind in order:
            figures[kind].append(estimate_us(estimators[kind], states))
    _summary('estimate', figures, steps)


def recorded_stand_ticks(ticks: int = 500) -> tuple[StandController, list[tuple]]:
    """A Stand run's controller and its last `ticks` inputs (state, joint positions and
    velocities), standing after the take-over; each state's polygon asked for once."""
    sim = make_simulator()
    stand = TimedStand(sim.atlas)
    sim.install_stand(stand)
    recorded = []
    for step in range(2500 + ticks):
        sim.step()
        if step >= 2500:
            state = stand.last_state
            state.support_polygon  # noqa: B018 - the controller's first ask, done here
            recorded.append((state, sim.data.qpos[sim.atlas.qpos_adr].copy(),
                             sim.data.qvel[sim.atlas.dof_adr].copy()))
    return stand.controller, recorded


def compare_ticks(rounds: int) -> None:
    """StandController.tick alone, Python against compiled, on a run's recorded inputs."""
    base, recorded = recorded_stand_ticks()
    controllers = {kind: StandController(base.mass_kg, base.layer.effort_limit_nm,
                                         base.reference, base.sole_half_size_m, base.gains,
                                         compiled=kind == 'compiled') for kind in KINDS}
    assert controllers['compiled'].compiled, 'the compiled library is not built'
    figures: dict[str, list[float]] = {kind: [] for kind in KINDS}
    steps, bare = [], BareStep()
    for round_index in range(rounds):
        steps.append(bare.us())
        for kind in KINDS if round_index % 2 == 0 else KINDS[::-1]:
            tick = controllers[kind].tick
            start = time.process_time()
            for _ in range(10):
                for state, positions, velocities in recorded:
                    tick(state, positions, velocities)
            figures[kind].append((time.process_time() - start) / (10 * len(recorded)) * 1e6)
    _summary('StandController.tick', figures, steps)


def compare_runs(pairs: int, kinds: list[str]) -> None:
    bare = BareStep()
    stand: dict[str, list[float]] = {kind: [] for kind in kinds}
    walk: dict[str, list[float]] = {kind: [] for kind in kinds}
    steps = []
    for pair in range(pairs):
        for kind in kinds if pair % 2 == 0 else kinds[::-1]:
            for name in SWITCHES:
                os.environ.pop(name, None)
            os.environ.update(RUN_KINDS[kind])
            steps.append(bare.us())
            stand[kind].append(stand_run(steps=3000))
            walk[kind].append(walk_run()[0])
    _summary('Stand µs/tick (stand_run)', stand, steps)
    _summary('Walk µs/tick (walk_run, 6 steps, CPU)', walk, steps)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--rounds', type=int, default=9)
    parser.add_argument('--pairs', type=int, default=3)
    parser.add_argument('--skip-runs', action='store_true', help='only the estimates')
    parser.add_argument('--skip-estimates', action='store_true', help='only the runs')
    parser.add_argument('--ticks', action='store_true',
                        help='also StandController.tick alone, Python against compiled')
    parser.add_argument('--kinds', nargs='+', choices=list(RUN_KINDS), default=list(RUN_KINDS),
                        help='the runs\' kinds (each paired with python\'s, if run)')
    args = parser.parse_args()
    print('load before:', subprocess.run(['uptime'], capture_output=True, text=True).stdout.strip())
    if not args.skip_estimates:
        compare_estimates(args.rounds)
    if args.ticks:
        compare_ticks(args.rounds)
    if not args.skip_runs:
        compare_runs(args.pairs, [kind for kind in RUN_KINDS if kind in args.kinds])
    print('load after:', subprocess.run(['uptime'], capture_output=True, text=True).stdout.strip())


if __name__ == '__main__':
    main()
