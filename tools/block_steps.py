#!/usr/bin/env python3
"""Static steps onto a cinder block and off again, offline, one seed after another: the
measurement behind docs/vrc.md's figures for Step on a block.

    python3 tools/block_steps.py [--on-side] [--plan back|across] SEED [SEED ...]

SEED is an integer (walking/start_noise.py's perturbed start) or `none` (the deterministic
start). Each trial (offline/block_step.py) prints one line as it ends: whether the robot
stood, the pelvis's lowest clearance, each step's goal height and its sole's landing errors
(across the ground, height, yaw), the block's displacement, and the process time per tick
against a bare mj_step's. A trial costs about 10-20 s of CPU. Run it under
tools/lowest_priority.py beside other work. Needs `source ./env.sh`. Exits 0 when every
trial stood, 1 otherwise, 2 for bad arguments.
"""

from __future__ import annotations

import argparse
import sys

from tutorial_atlas_control.cli.convention import seed_or_none
from tutorial_atlas_control.offline import PLANS, CinderBlock, block_step_trial

PROG = 'block_steps.py'


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog=PROG, description=__doc__.split('\n\n')[0])
    parser.add_argument('seeds', type=seed_or_none, nargs='+', metavar='SEED')
    parser.add_argument('--on-side', action='store_true', help='the block on a long side')
    parser.add_argument('--plan', choices=PLANS, default='back',
                        help="'back': the left foot onto it and back; 'across': both feet "
                             'onto it, then down its far side')
    args = parser.parse_args(argv)
    all_stood = True
    for seed in args.seeds:
        run = block_step_trial(CinderBlock(on_side=args.on_side), seed, args.plan)
        landings = ', '.join(
            f'step {s.goal.step_index} to z {s.goal.z_m:.3f}: {s.horizontal_error_m * 1e3:.1f} mm'
            f' / {s.height_error_m * 1e3:.1f} mm / {s.yaw_error_rad:.3f} rad' for s in run.steps)
        print(f'seed {seed}: stood {run.stood}, lowest pelvis {run.lowest_clearance_m:.3f} m, '
              f'{len(run.steps)} steps ({landings}), block moved {run.block_moved_m * 1e3:.1f} '
              f'mm and {run.block_turned_rad:.3f} rad, {run.tick_us:.0f} us a tick '
              f'({run.tick_us / run.mj_step_us:.1f} x a bare mj_step)', flush=True)
        all_stood &= run.stood
    return 0 if all_stood else 1


if __name__ == '__main__':
    sys.exit(main())
