#!/usr/bin/env python3
"""Straight walks on the course's kinds of ground, one case at a time, offline, over seeds:
the measurement behind docs/vrc.md's table of Walk on mud and slopes.

    python3 tools/terrain_walk.py [--push N] CASE SEED [SEED ...]

CASE is one of offline/terrain_trial.py's TERRAINS (mud_40, mud_70, up_8deg, down_8deg,
up_16deg, down_16deg, ramp_up_22deg, ramp_down_22deg: 3.6 m, the steps planned on the
ground); SEED an integer (walking/start_noise.py's perturbed start, and the pushes' draw)
or `none`; --push N pushes the pelvis sideways by N newtons for 0.1 s once every 5 s of the
walk.
Each walk prints one JSON line as it ends: whether it fell, the steps landed of those
planned, the worst landing (m), the lowest pelvis over the ground (m), where the pelvis
ended, the CPU it took. Needs `source ./env.sh`. Exits 0 when no walk fell, 1 otherwise, 2
for bad arguments.
"""

from __future__ import annotations

import argparse
import json
import sys
import time

from tutorial_atlas_control.cli.convention import non_negative_number, seed_or_none
from tutorial_atlas_control.offline import TERRAINS, planned_steps, terrain_walk

PROG = 'terrain_walk.py'


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog=PROG, description=__doc__.split('\n\n')[0])
    parser.add_argument('case', choices=sorted(TERRAINS), metavar='CASE',
                        help=f'one of {", ".join(TERRAINS)}')
    parser.add_argument('seeds', type=seed_or_none, nargs='+', metavar='SEED')
    parser.add_argument('--push', type=non_negative_number, default=0.0, metavar='N',
                        help='pelvis pushes of N newtons (default 0: none)')
    args = parser.parse_args(argv)
    terrain = TERRAINS[args.case]
    planned = planned_steps(terrain)
    none_fell = True
    for seed in args.seeds:
        started = time.process_time()
        trial = terrain_walk(terrain, seed, args.push)
        print(json.dumps({
            'case': terrain.name, 'seed': seed, 'push_n': args.push, 'fell': trial.fell,
            'steps': trial.steps, 'planned': planned,
            'worst_landing_m': round(trial.worst_landing_m, 4),
            'lowest_pelvis_m': round(trial.lowest_pelvis_m, 3),
            'pelvis_end': [round(float(value), 3) for value in trial.pelvis_end],
            'cpu_s': round(time.process_time() - started, 1)}), flush=True)
        none_fell &= not trial.fell
    return 0 if none_fell else 1


if __name__ == '__main__':
    sys.exit(main())
