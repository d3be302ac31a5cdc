"""When the simulator's messages are due and which time each carries.

One rule for the two writers of those messages: the ROS node (stepping/loop.py) and
offline runs (offline/player.py), so that a bag of either has the same messages at the
same stamps.
"""

from __future__ import annotations

from typing import TypeVar

from tutorial_atlas_control import topics

__all__ = ['STAMPED_AT_STEP_END', 'step_stamp', 'steps_between']

#: The per-step messages stamped at the end of the step that made them: the joint states
#: (positions, velocities, and the torque applied during the step), and AtlasState, which
#: repeats them (its IMU and wrenches, as /atlas/imu's, are from the step's start), and the
#: world's positions the cameras render. The others, poses and sensors, describe the state at
#: the step's start (MuJoCo computes them before it integrates), and carry that time.
STAMPED_AT_STEP_END = frozenset({topics.JOINT_STATES, topics.ATLAS_STATE, topics.RENDER_STATE})

Stamp = TypeVar('Stamp')


def steps_between(rate_hz: float, dt_s: float) -> int:
    """Publish every N steps for `rate_hz`; 0 or a rate at/above the step rate = every step."""
    if rate_hz <= 0.0 or rate_hz * dt_s >= 1.0:
        return 1
    return max(1, int(round(1.0 / (rate_hz * dt_s))))


def step_stamp(topic: str, end_ns: Stamp, start_ns: Stamp) -> Stamp:
    """The stamp of `topic`'s message from a step that started at `start_ns` and ended at
    `end_ns` (ns of sim time; numbers or arrays of them, one per step)."""
    return end_ns if topic in STAMPED_AT_STEP_END else start_ns
