"""The whole-body layer's two solvers on slopes, over seeds: what the QP costs per tick and
what it buys (docs/controllers.md, "Solver"; not a `make bench` section: a decision's
figures, run by hand).

    python3 bench/slope_solver.py [--seeds 8] [--slopes 0 8 16] [--duration 10]
                                  [--push-ns 0] [--json out.json]
    python3 bench/slope_solver.py --cost [--slopes 8]

Each seed perturbs the start (walking/start_noise.py: 5 mrad, 5 mrad/s on every joint);
`--push-ns` adds a pelvis push down the slope (-x) of that impulse over 0.2 s at 2 s. Per
slope and solver: the fraction of seeds standing at the end (feet within 2 cm), the soles'
largest displacement, the least pressure-centre margin on either sole (from 1.5 s), and the
controller's process time per tick beside a bare mj_step's timed in the same process.
`--cost` times instead, interleaved in one process, one Stand tick (estimate and solve) by
each solver on the same states (standing, and 0.1 s into a 45 N s push, where the soles'
constraints bind) and a bare mj_step, in rounds: the medians, and their ratios.
"""

from __future__ import annotations

import argparse
import functools
import json
import math
import os
import statistics
import sys
import time
import timeit
from typing import Any

import mujoco

from tutorial_atlas_control.balance import INVERSE_STATICS, QP, Push, StandGains, contact_qp
from tutorial_atlas_control.balance.push_trial import apply_pushes, push_events
from tutorial_atlas_control.balance.slope_trial import (
    place_on_slope,
    slope_model,
    slope_stand_trial,
)
from tutorial_atlas_control.balance.stand_behaviour import StandBehaviour
from tutorial_atlas_control.sim import DEFAULT_GAINS_FILE, AtlasSimulator, Ground, load_gains_yaml
from tutorial_atlas_control.walking import perturb_start

PUSH_AT_S = 2.0


def run(slope_deg: float, solver: str, seed: int, duration_s: float,
        push_ns: float) -> dict[str, float]:
    """One trial's figures."""
    pushes = [Push(PUSH_AT_S, (-push_ns / 0.2, 0.0, 0.0))] if push_ns > 0.0 else []
    result = slope_stand_trial(
        math.radians(slope_deg), StandGains(solver=solver), duration_s,
        perturb=lambda atlas, data: perturb_start(atlas, data, seed, on_ground=False),
        pushes=pushes)
    return {'stood': float(result.stood), 'travel_mm': result.sole_travel_m * 1e3,
            'cop_margin_mm': result.cop_margin_m * 1e3, 'controller_us': result.controller_us,
            'mj_step_us': result.mj_step_us, 'fallbacks': result.qp_fallbacks}


def state_at(slope_deg: float, time_s: float,
             push_ns: float) -> tuple[AtlasSimulator, StandBehaviour]:
    """A simulator standing on the slope (inverse statics) at `time_s`, pushed down it at
    PUSH_AT_S by `push_ns` over 0.2 s when given; and its Stand."""
    atlas = slope_model(math.radians(slope_deg))
    sim = AtlasSimulator(atlas, load_gains_yaml(DEFAULT_GAINS_FILE), time_to_unpin_s=0.0)
    place_on_slope(sim.atlas, sim.data, math.radians(slope_deg), Ground(sim.atlas.model))
    stand = StandBehaviour(sim.atlas)
    sim.install_stand(stand)
    pushes = [Push(PUSH_AT_S, (-push_ns / 0.2, 0.0, 0.0))] if push_ns > 0.0 else []
    events = push_events(pushes, sim.dt_s)
    for step in range(round(time_s / sim.dt_s)):
        apply_pushes(sim, events, step)
        sim.step()
    return sim, stand


def tick_costs(slope_deg: float, time_s: float, push_ns: float, rounds: int,
               calls: int) -> dict[str, float]:
    """One Stand tick (the estimate and the controller's step) by each solver on the state
    at `time_s` (state_at), and a bare mj_step: process time (us), medians of `rounds` of
    `calls`, interleaved."""
    sim, stand = state_at(slope_deg, time_s, push_ns)
    assert stand.controller is not None
    data, atlas = sim.data, sim.atlas
    joints, rates = data.qpos[atlas.qpos_adr], data.qvel[atlas.dof_adr]
    ticks = {}
    for name in (INVERSE_STATICS, QP):
        behaviour = StandBehaviour(atlas, StandGains(solver=name))
        behaviour.start(data)
        assert behaviour.controller is not None
        behaviour.controller.reference = stand.controller.reference
        ticks[name] = functools.partial(_tick, behaviour, data, joints, rates)
    scratch = mujoco.MjData(atlas.model)
    ticks['mj_step'] = functools.partial(mujoco.mj_step, atlas.model, scratch)
    times: dict[str, list[float]] = {name: [] for name in ticks}
    for _ in range(rounds):
        mujoco.mj_copyData(scratch, atlas.model, data)
        for name, tick in ticks.items():
            times[name].append(timeit.timeit(tick, timer=time.process_time, number=calls))
    return {name: statistics.median(t) / calls * 1e6 for name, t in times.items()}


def _tick(behaviour: StandBehaviour, data: mujoco.MjData, joints: object,
          rates: object) -> None:
    assert behaviour.controller is not None
    behaviour.controller.step(behaviour.estimator.estimate(data.qpos, data.qvel), joints,
                              rates)


def print_costs(slope_deg: float, rounds: int = 5, calls: int = 1000) -> None:
    """Each solver's tick beside a bare mj_step, standing and 0.1 s into a 45 N s push."""
    for label, time_s, push_ns in (('standing', 3.0, 0.0), ('pushed', 2.1, 45.0)):
        us = tick_costs(slope_deg, time_s, push_ns, rounds, calls)
        print(f'{slope_deg:g} deg {label}: inverse statics {us[INVERSE_STATICS]:.0f} us '
              f'({us[INVERSE_STATICS] / us["mj_step"]:.1f} mj_step), QP {us[QP]:.0f} us '
              f'({us[QP] / us["mj_step"]:.1f} mj_step), QP/IS '
              f'{us[QP] / us[INVERSE_STATICS]:.2f}, mj_step {us["mj_step"]:.0f} us; load '
              f'{os.getloadavg()[0]:.2f}', flush=True)


def box_about_vertical() -> None:
    """The QP's sole box scaled by 1/n_z (the ground normal's vertical part): the pressure
    centre held about the vertical force, as inverse statics does; an experiment."""
    solve = contact_qp.solve_contact_qp

    def scaled(*args: Any) -> Any:
        frames, (half_length, half_width, torsion, friction) = args[4], args[5]
        up = min(frame[2][2] for frame in frames if frame is not None)
        return solve(*args[:5], (half_length / up, half_width / up, torsion, friction),
                     *args[6:])

    contact_qp.solve_contact_qp = scaled


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--seeds', type=int, default=8)
    parser.add_argument('--slopes', type=float, nargs='+', default=[0.0, 8.0, 16.0])
    parser.add_argument('--duration', type=float, default=10.0)
    parser.add_argument('--push-ns', type=float, default=0.0)
    parser.add_argument('--solvers', nargs='+', default=[INVERSE_STATICS, QP])
    parser.add_argument('--json')
    parser.add_argument('--cost', action='store_true')
    parser.add_argument('--qp-box-vertical', action='store_true',
                        help="the QP's pressure-centre box about the vertical force, as inverse "
                             'statics holds it (1/cos(slope) larger), not the normal one')
    args = parser.parse_args()
    if args.qp_box_vertical:
        box_about_vertical()
    if args.cost:
        for slope in args.slopes:
            print_costs(slope)
        return 0
    print(f'load {os.getloadavg()[0]:.2f}; seeds 0..{args.seeds - 1}, {args.duration} s, '
          f'push {args.push_ns} N s down the slope at {PUSH_AT_S} s', flush=True)
    rows = []
    for slope in args.slopes:
        for solver in args.solvers:
            runs = [run(slope, solver, seed, args.duration, args.push_ns)
                    for seed in range(args.seeds)]
            cost = statistics.median(r['controller_us'] for r in runs)
            step = statistics.median(r['mj_step_us'] for r in runs)
            row = {'slope_deg': slope, 'solver': solver,
                   'stood': sum(r['stood'] for r in runs) / len(runs),
                   'travel_mm_median': statistics.median(r['travel_mm'] for r in runs),
                   'travel_mm_max': max(r['travel_mm'] for r in runs),
                   'cop_margin_mm_min': min(r['cop_margin_mm'] for r in runs),
                   'cop_margin_mm_median': statistics.median(r['cop_margin_mm'] for r in runs),
                   'controller_us': cost, 'mj_step_us': step, 'ratio': cost / step,
                   'fallbacks': sum(r['fallbacks'] for r in runs),
                   'load': os.getloadavg()[0]}
            rows.append(row)
            print(' '.join(f'{k}={v:.3g}' if isinstance(v, float) else f'{k}={v}'
                           for k, v in row.items()), flush=True)
    if args.json:
        with open(args.json, 'w', encoding='utf-8') as out:
            json.dump(rows, out, indent=1)
    return 0


if __name__ == '__main__':
    sys.exit(main())
