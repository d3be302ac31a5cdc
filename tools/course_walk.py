#!/usr/bin/env python3
"""Streamed walks on the VRC Task 2 course, offline and scored, one seed after another: the
measurement behind docs/vrc.md's figures for the walk to gate_1.

    python3 tools/course_walk.py [--to GATE | --waypoints 'X,Y X,Y ...'] [--stride M]
                                 [--no-fit-ground] [--world NAME] [--variant NAME]
                                 [--terrain world|laser] [--mud-damping C] SEED ...

The walk is vrc_walker.py's, offline: the course's legs (course/legs.py) from the world's
start to --to (default gate_1), each planned from where the feet are as it begins; or one
leg through --waypoints. A straight run over a bend or steep ground (the pit's ramps) is
planned on the world's ground (walking/ground_strides.py); --no-fit-ground: equal strides.
--variant: one of the finals' changes to the course (course/variants.py; default the world
as shipped). --terrain laser: each leg planned on the head laser's height map of what it
has seen so far, the spindle spinning (offline/laser_terrain.py; docs/sensors.md).
--mud-damping C: the mud's damping (N s/m) instead of the world's or the variant's: the
margin of a walk through the pit, between the qualification's 40 and the finals' 70.
SEED is an integer (walking/start_noise.py's perturbed start) or `none` (the start as the
world gives it). Each walk prints one JSON line (offline/course_route.py's CourseWalk) as it
ends; a run costs about 300-500 s of CPU on this host (the course's physics). Run it under
tools/lowest_priority.py beside other work. Needs `source ./env.sh`. Exits 0 when every walk
reached the end of its route without a fall, 1 otherwise, 2 for bad arguments.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys

from tutorial_atlas_control.cli.convention import seed_or_none
from tutorial_atlas_control.course import (
    COURSE_VARIANTS,
    GATES,
    CourseVariant,
    Leg,
    check_mud_damping,
    course_variant,
)
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.offline import PLANNING_GROUNDS, course_walk
from tutorial_atlas_control.walking import RouteGait

PROG = 'course_walk.py'


def _waypoints(text: str) -> tuple[tuple[float, float], ...]:
    points = []
    for pair in text.split():
        try:
            x, y = (float(value) for value in pair.split(','))
        except ValueError:
            raise argparse.ArgumentTypeError(f'waypoint {pair!r} is not X,Y') from None
        points.append((x, y))
    if not points:
        raise argparse.ArgumentTypeError('no waypoint given')
    return tuple(points)


def _mud_damping(text: str) -> float:
    try:
        return check_mud_damping(float(text))
    except ValueError:
        raise argparse.ArgumentTypeError(f'mud damping must be a finite number >= 0 (N s/m), '
                                         f'got {text!r}') from None
    except AtlasControlError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def _variant(name: str | None, mud_damping: float | None) -> CourseVariant | None:
    """The variant named (None: the world as shipped), its mud's damping `mud_damping` if
    given."""
    variant = None if name is None else course_variant(name)
    if mud_damping is None:
        return variant
    return (variant or COURSE_VARIANTS[0]).with_mud_damping(mud_damping)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog=PROG, description=__doc__.split('\n\n')[0])
    parser.add_argument('seeds', type=seed_or_none, nargs='+', metavar='SEED')
    parser.add_argument('--to', choices=[gate.name for gate in GATES], default='gate_1',
                        metavar='GATE', help='the last gate (default: %(default)s)')
    parser.add_argument('--waypoints', type=_waypoints, default=None,
                        help='one leg through these world x,y pairs instead of the course\'s')
    parser.add_argument('--stride', type=float, default=0.15, help='longest stride (m)')
    parser.add_argument('--fit-ground', action=argparse.BooleanOptionalAction, default=True,
                        help='plan straight runs over a bend or steep ground on the world\'s '
                        'ground (walking/ground_strides.py: the pit\'s ramps; default: on)')
    parser.add_argument('--terrain', choices=PLANNING_GROUNDS, default='world',
                        help="the ground each leg is planned on: the world's, or the head "
                        "laser's height map of what it has seen (offline/laser_terrain.py)")
    parser.add_argument('--world', default='vrc_task_2', help='a VRC Task 2 world name')
    parser.add_argument('--variant', choices=[v.name for v in COURSE_VARIANTS], default=None,
                        help="one of the VRC finals' changes to the course")
    parser.add_argument('--mud-damping', type=_mud_damping, default=None, metavar='C',
                        help="the mud's damping (N s/m and N m s/rad) instead of the world's "
                        "or the variant's (the qualification's 40, the finals' 70)")
    args = parser.parse_args(argv)
    try:
        gait = RouteGait(stride_m=args.stride, fit_ground=args.fit_ground)
    except AtlasControlError as err:
        parser.error(str(err))
    all_walked = True
    for seed in args.seeds:
        try:
            legs = None if args.waypoints is None else [Leg('route', args.waypoints)]
            walk = course_walk(seed, legs, args.to, args.world, gait,
                               variant=_variant(args.variant, args.mud_damping),
                               terrain=args.terrain)
        except AtlasControlError as err:
            print(f'{PROG}: {err}', file=sys.stderr)
            return 2
        print(json.dumps(dataclasses.asdict(walk)), flush=True)
        all_walked &= walk.outcome == 'walked' and walk.fell_at_s is None
    return 0 if all_walked else 1


if __name__ == '__main__':
    sys.exit(main())
