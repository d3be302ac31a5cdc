"""The whole-body layer's two solvers on slopes, over seeds: what the QP costs per tick and
what it buys (docs/controllers.md, "Solver"; not a `make bench` section: a decision's
figures, run by hand).

    python3 bench/slope_solver.py [--seeds 8] [--slopes 0 8 16] [--duration 10]
                                  [--push-ns 0] [--json out.json]

Each seed perturbs the start (walking/start_noise.py: 5 mrad, 5 mrad/s on every joint);
`--push-ns` adds a pelvis push down the slope (-x) of that impulse over 0.2 s at 2 s. Per
slope and solver: the fraction of seeds standing at the end (feet within 2 cm), the soles'
largest displacement, the least pressure-centre margin on either sole (from 1.5 s), and the
controller's process time per tick beside a bare mj_step's timed in the same process.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import sys

from tutorial_atlas_control.balance import INVERSE_STATICS, QP, Push, StandGains
from tutorial_atlas_control.balance.slope_trial import slope_stand_trial
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


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--seeds', type=int, default=8)
    parser.add_argument('--slopes', type=float, nargs='+', default=[0.0, 8.0, 16.0])
    parser.add_argument('--duration', type=float, default=10.0)
    parser.add_argument('--push-ns', type=float, default=0.0)
    parser.add_argument('--solvers', nargs='+', default=[INVERSE_STATICS, QP])
    parser.add_argument('--json')
    args = parser.parse_args()
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
