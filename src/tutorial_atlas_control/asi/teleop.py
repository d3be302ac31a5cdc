"""The keyboard teleop's key map and the ego-centric steps each key asks for, ROS-free.

DRCSim's key map: lower case walks dynamically (one WALK goal of the steps), capitals step
statically (one STEP goal per step); `i` and `,` forward and back, `j` and `l` turn left and
right in place, `u` and `o` curve forward to the left and right, `m` and `.` step sideways
to the left and right; `1`-`9` how many steps, `-` and `=` a shorter and longer stride;
`R` stands the robot up from the harness, `H` puts it in the harness, `Q` quits; ours, `S`
asks for Stand (a STAND goal: the default start's hold needs one before walking). Our
numbers: feet 0.24 m apart, 0.63 s a step, a stride of 0.2 m to start (0.05-0.40 m in
steps of 0.05), a turn of 0.1 rad a step, curves of radius 2 m, a side step of half the
stride. Steps are in the pelvis's frame (x ahead, y left), as the actionlib server expects.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from tutorial_atlas_control.asi.errors import AsiInputError
from tutorial_atlas_control.walking import (
    LEFT,
    RIGHT,
    STEP_DURATION_S,
    Footstep,
    circle_steps,
    straight_steps,
    wrap_angle,
)

__all__ = ['MOVES', 'Settings', 'ego_steps', 'key_action']

WIDTH_M = 0.24
TURN_RAD = 0.1
CURVE_RADIUS_M = 2.0
STRIDE_STEP_M = 0.05
STRIDE_RANGE_M = (0.05, 0.40)

#: The walking keys (lower case; a capital steps statically) and what each does.
MOVES = {'i': 'forward', ',': 'back', 'j': 'turn left', 'l': 'turn right',
         'u': 'curve left', 'o': 'curve right', 'm': 'side left', '.': 'side right'}
_CAPITALS = {'I': 'i', '<': ',', 'J': 'j', 'L': 'l', 'U': 'u', 'O': 'o', 'M': 'm', '>': '.'}


@dataclass(frozen=True)
class Settings:
    """How many steps a key walks and how long a stride is (m)."""

    steps: int = 4
    stride_m: float = 0.2


def key_action(key: str, settings: Settings) -> tuple[str, Settings | str | None]:
    """('walk' | 'step', move) for a walking key, ('settings', new Settings) for 1-9, - and
    =, ('stand up' | 'stand' | 'harness' | 'quit', None), or ('unknown', None)."""
    if key in MOVES:
        return 'walk', MOVES[key]
    if key in _CAPITALS:
        return 'step', MOVES[_CAPITALS[key]]
    if key in '123456789' and len(key) == 1:
        return 'settings', replace(settings, steps=int(key))
    if key in ('-', '='):
        low, high = STRIDE_RANGE_M
        change = STRIDE_STEP_M if key == '=' else -STRIDE_STEP_M
        stride = min(max(round(settings.stride_m + change, 2), low), high)
        return 'settings', replace(settings, stride_m=stride)
    return {'R': ('stand up', None), 'S': ('stand', None), 'H': ('harness', None),
            'Q': ('quit', None)}.get(key, ('unknown', None))


def ego_steps(move: str, settings: Settings) -> list[Footstep]:
    """The steps of `move` (a MOVES value) from feet side by side at the pelvis, facing +x."""
    count, stride = settings.steps, settings.stride_m
    if move in ('forward', 'back'):
        sign = 1.0 if move == 'forward' else -1.0
        return straight_steps(count, sign * stride, WIDTH_M, STEP_DURATION_S)
    if move in ('turn left', 'turn right'):
        return _turn(count, TURN_RAD if move == 'turn left' else -TURN_RAD)
    if move in ('curve left', 'curve right'):
        per_circle = max(4, round(2.0 * math.pi * CURVE_RADIUS_M / stride))
        left = circle_steps(CURVE_RADIUS_M, per_circle, 1, WIDTH_M, STEP_DURATION_S)[:count]
        return left if move == 'curve left' else [_mirrored(step) for step in left]
    if move in ('side left', 'side right'):
        return _side(count, 0.5 * stride, LEFT if move == 'side left' else RIGHT)
    raise AsiInputError(f'no such move: {move!r}')


def _turn(count: int, turn_rad: float) -> list[Footstep]:
    """Turning in place: each step turns its foot's heading by `turn_rad` more, the leading
    foot the one on the side turned to."""
    lead = LEFT if turn_rad > 0 else RIGHT
    steps = []
    for k in range(1, count + 1):
        foot = lead if k % 2 == 1 else 1 - lead
        heading = turn_rad * k
        side = WIDTH_M / 2 * (1.0 if foot == LEFT else -1.0)
        steps.append(Footstep(k, foot, -side * math.sin(heading), side * math.cos(heading),
                              wrap_angle(heading), STEP_DURATION_S))
    return steps


def _side(count: int, shift_m: float, lead: int) -> list[Footstep]:
    """Side steps: the leading foot out by `shift_m`, the other foot after it."""
    sign = 1.0 if lead == LEFT else -1.0
    steps = []
    for k in range(1, count + 1):
        foot = lead if k % 2 == 1 else 1 - lead
        moved = shift_m * ((k + 1) // 2)
        base = WIDTH_M / 2 * (1.0 if foot == LEFT else -1.0)
        steps.append(Footstep(k, foot, 0.0, base + sign * moved, 0.0, STEP_DURATION_S))
    return steps


def _mirrored(step: Footstep) -> Footstep:
    """The step mirrored left to right (the other foot, y and yaw negated)."""
    return replace(step, foot_index=1 - step.foot_index, y_m=-step.y_m,
                   yaw_rad=wrap_angle(-step.yaw_rad))
