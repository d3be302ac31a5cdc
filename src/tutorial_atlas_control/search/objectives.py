"""Named objectives over a sweep row: a cost to minimise, from the row's figures only.

Given on the command line as `NAME` or `NAME:KEY=VALUE,KEY=VALUE` (e.g.
`step_forward:dx=0.15,stand=5`). Each cost is 0 or more, and 0 only when every goal holds
(stay_up excepted: it also counts the pelvis's drift), so the search can stop on 0.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from tutorial_atlas_control.search.runs import SweepError

__all__ = ['Objective', 'OBJECTIVES', 'parse_objective']

#: A fall costs this much on top of the seconds of standing it lost.
FALL_PENALTY = 1.0
#: Weight of a shortfall in metres against one in seconds (1 cm ~ 0.1 s).
PER_M = 10.0
#: A step_forward run that falls costs at least this: more than any that stands (whose
#: shortfalls in metres, x PER_M, stay below it for any step the robot can take).
FALLEN_STEP_COST = 10.0
#: The swing foot must rise at least this much (m) to count as lifted, not slid.
MIN_LIFT_M = 0.03
#: steps_forward counts a foot's end height off the ground up to this (m): it bounds the cost
#: of a run that stands, so that any fall costs more.
MAX_DZ_M = 0.1


@dataclass(frozen=True)
class Objective:
    """A named cost with its parameters; settle_s is how long a run must go on after the
    trajectory for the cost to be judged."""

    name: str
    params: Mapping[str, float]
    cost_of: Callable[[Mapping[str, Any], Mapping[str, float]], float]

    def cost(self, row: Mapping[str, Any]) -> float:
        value = self.cost_of(row, self.params)
        return value if math.isfinite(value) else math.inf

    @property
    def settle_s(self) -> float:
        return float(self.params.get('stand', self.params.get('settle', 1.0)))

    def text(self) -> str:
        if not self.params:
            return self.name
        return self.name + ':' + ','.join(f'{k}={v:g}' for k, v in sorted(self.params.items()))


def _fall_cost(row: Mapping[str, Any], stand_s: float) -> float:
    """Seconds of the run lost to a fall (+ FALL_PENALTY), or of standing short after it:
    a later fall costs less, so the search has a slope to follow among runs that fall."""
    if row['fell']:
        return FALL_PENALTY + max(0.0, float(row['played_s']) + stand_s
                                  - float(row['fall_time_s']))
    return max(0.0, stand_s - float(row['stood_after_s']))


def _stay_up(row: Mapping[str, Any], p: Mapping[str, float]) -> float:
    fall = 0.0
    if row['fell']:
        fall = FALL_PENALTY + max(0.0, float(row['played_s']) + p['settle']
                                  - float(row['fall_time_s']))
    drift_m = math.hypot(float(row['pelvis_dx_m']), float(row['pelvis_dy_m']))
    return fall + drift_m


def _step_forward(row: Mapping[str, Any], p: Mapping[str, float]) -> float:
    if row['fell']:  # where the feet lie after a fall says nothing: only when it fell counts
        return FALLEN_STEP_COST + _fall_cost(row, p['stand'])
    forward = max(0.0, p['dx'] - float(row['r_foot_dx_m']))
    lift = max(0.0, MIN_LIFT_M - float(row['r_foot_lift_max_m']))
    down = abs(float(row['r_foot_dz_end_m']))
    low = max(0.0, p['z'] - float(row['pelvis_z_end_m']))
    return _fall_cost(row, p['stand']) + PER_M * (forward + lift + down + low)


def _steps_bound(p: Mapping[str, float]) -> float:
    """The most a steps_forward run that stands can cost (every shortfall at its cap)."""
    return p['stand'] + PER_M * (p['r'] + p['l'] + 2 * (p['lift'] + MAX_DZ_M) + max(0.0, p['z']))


def _steps_forward(row: Mapping[str, Any], p: Mapping[str, float]) -> float:
    """Both feet lifted and put down R and L m further forward (a walk's steps), then stand."""
    if row['fell']:  # as step_forward: a fall costs more than any run that stands
        return _steps_bound(p) + FALL_PENALTY + _fall_cost(row, p['stand'])
    short = 0.0
    for foot in ('r', 'l'):
        short += max(0.0, p[foot] - max(0.0, float(row[f'{foot}_foot_dx_m'])))
        short += max(0.0, p['lift'] - max(0.0, float(row[f'{foot}_foot_lift_max_m'])))
        short += min(MAX_DZ_M, abs(float(row[f'{foot}_foot_dz_end_m'])))
    low = min(max(0.0, p['z']), max(0.0, p['z'] - float(row['pelvis_z_end_m'])))
    return _fall_cost(row, p['stand']) + PER_M * (short + low)


def _pelvis_height(row: Mapping[str, Any], p: Mapping[str, float]) -> float:
    return abs(float(row['pelvis_z_end_m']) - p['z']) + (FALL_PENALTY if row['fell'] else 0.0)


#: name -> (cost, default parameters, what it asks).
OBJECTIVES: dict[str, tuple[Callable[[Mapping[str, Any], Mapping[str, float]], float],
                            dict[str, float], str]] = {
    'stay_up': (_stay_up, {'settle': 3.0},
                'stand SETTLE s after the trajectory, pelvis where it started'),
    'step_forward': (_step_forward, {'dx': 0.15, 'stand': 5.0, 'z': 0.8},
                     'lift the right foot, put it down DX m further forward, stand STAND s '
                     'after with the pelvis above Z m'),
    'steps_forward': (_steps_forward,
                      {'r': 0.15, 'l': 0.15, 'lift': MIN_LIFT_M, 'stand': 5.0, 'z': 0.8},
                      'lift each foot at least LIFT m; the right ends R m and the left L m '
                      'further forward; stand STAND s after with the pelvis above Z m'),
    'pelvis_height': (_pelvis_height, {'z': 0.85, 'settle': 0.5},
                      'end with the pelvis at Z m, standing (a toy problem)'),
}


def parse_objective(text: str) -> Objective:
    """`NAME[:KEY=VALUE,...]` -> Objective.

    Raises:
        SweepError: unknown name or key, or a value that is not a finite number.
    """
    name, _, rest = text.partition(':')
    if name not in OBJECTIVES:
        raise SweepError(f'unknown objective {name!r}; known: {", ".join(sorted(OBJECTIVES))}')
    cost_of, defaults, _ = OBJECTIVES[name]
    params = dict(defaults)
    for item in filter(None, rest.split(',')) if rest else ():
        key, sep, value = item.partition('=')
        if not sep or key not in defaults:
            raise SweepError(f'objective {text!r}: {item!r} is not KEY=VALUE with KEY one of '
                             f'{", ".join(sorted(defaults))}')
        try:
            number = float(value)
        except ValueError:
            number = math.nan
        if not math.isfinite(number):
            raise SweepError(f'objective {text!r}: {key}={value!r} is not a finite number')
        params[key] = number
    if rest == '' and text.endswith(':'):
        raise SweepError(f'objective {text!r}: nothing after the colon')
    return Objective(name, params, cost_of)
