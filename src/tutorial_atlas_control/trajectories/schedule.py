"""traj_yaml's schedule, without ROS: when each command of a trajectory is sent.

Shared by the live player (traj_yaml_node.py: ROS time, a publisher) and offline runs
(offline/player.py: the simulator's own clock, a bag), so both play a trajectory the same way.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence

import numpy as np

from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.trajectories.trajectory import Waypoint, interpolate, sample_count

__all__ = [
    'MOVING_JOINT_THRESHOLD_RAD',
    'TRAJECTORY_LOG_PREFIX',
    'TimeWentBackError',
    'done_line',
    'parse_trajectory_log_line',
    'playing_line',
    'run_trajectory',
    'trajectory_log_line',
]

#: A joint "moves" in a waypoint's log line if its target is this far (rad) from its measured
#: position.
MOVING_JOINT_THRESHOLD_RAD = 0.01
#: Start of the one machine-readable log line a player writes before its first command
#: (followed by JSON with the trajectory file and name): how a bag tells what it played.
TRAJECTORY_LOG_PREFIX = 'trajectory: '


class TimeWentBackError(AtlasControlError):
    """Sim time went back under a playing trajectory (/gazebo/reset_simulation sets it to 0).

    The player stops rather than carry on: its schedule is in sim time, and the reset put
    the robot back at its initial pose, so the rest of the trajectory would start from a
    pose it was not planned from. Running the player again plays it from the start.
    """

    def __init__(self, before_s: float, after_s: float) -> None:
        super().__init__(
            f'sim time went back from {before_s:.3f} s to {after_s:.3f} s (the simulation was '
            'reset: /gazebo/reset_simulation?); trajectory aborted, run traj_yaml.py again to '
            'play it from the start')


def trajectory_log_line(path: str, name: str) -> str:
    """The line a player logs at start: ``trajectory: {"file": ..., "name": ...}``."""
    return TRAJECTORY_LOG_PREFIX + json.dumps({'file': str(path), 'name': name})


def parse_trajectory_log_line(text: str) -> dict[str, str] | None:
    """The file and name of a :func:`trajectory_log_line`, None for any other text."""
    if not text.startswith(TRAJECTORY_LOG_PREFIX):
        return None
    try:
        fields = json.loads(text[len(TRAJECTORY_LOG_PREFIX):])
    except json.JSONDecodeError:
        return None
    if not isinstance(fields, dict) or not all(isinstance(fields.get(key), str)
                                               for key in ('file', 'name')):
        return None
    return {'file': fields['file'], 'name': fields['name']}


def playing_line(name: str, waypoints: Sequence[Waypoint]) -> str:
    """The log line before the first command: waypoints, duration and commands."""
    total = sum(sample_count(waypoint.duration_s) for waypoint in waypoints)
    return (f"playing trajectory '{name}': {len(waypoints)} waypoints, "
            f"{sum(w.duration_s for w in waypoints):g} s, {total} commands")


def done_line(name: str) -> str:
    """The log line after the last command."""
    return f"trajectory '{name}' done"


def run_trajectory(
    waypoints: Sequence[Waypoint],
    measure: Callable[[], np.ndarray],
    send: Callable[[np.ndarray], None],
    sleep: Callable[[float], None],
    log: Callable[[str], None],
    now: Callable[[], float] | None = None,
) -> int:
    """Play `waypoints` as the tutorial did; return the number of commands sent.

    For each waypoint: `measure` the joint positions (rad), `log` one line, then `send`
    each interpolated command, one every ``duration_s / n`` (s). The tutorial slept that
    long after each send, so every late wake-up (a busy machine) stretched the motion; with
    a clock (`now`, s) each send is instead due a fixed interval after the previous one's
    due time, so the trajectory keeps its 50 Hz and its durations. Falling more than one
    interval behind restarts the schedule rather than sending a burst (the publisher keeps
    the tutorial's queue_size=1). Without `now`, ``sleep(duration_s / n)`` as the tutorial.

    Raises:
        TimeWentBackError: `now` went back.
    """
    sent = 0
    due_s = last_s = now() if now is not None else 0.0
    for index, waypoint in enumerate(waypoints):
        initial = measure()
        log(waypoint_line(index, len(waypoints), waypoint, initial))
        for positions, sleep_s in interpolate(initial, waypoint.positions, waypoint.duration_s):
            send(positions)
            sent += 1
            if now is None:
                sleep(sleep_s)
                continue
            due_s += sleep_s
            now_s = now()
            if now_s < last_s:  # (a jump during a sleep is the sleep's to raise)
                raise TimeWentBackError(last_s, now_s)
            last_s = now_s
            remaining_s = due_s - now_s
            if remaining_s > 0.0:
                sleep(remaining_s)
            elif remaining_s < -sleep_s:
                due_s = now()
    return sent


def waypoint_line(index: int, count: int, waypoint: Waypoint, initial: np.ndarray) -> str:
    """The log line of a waypoint's start: its duration, commands and the joints that move."""
    moving = np.flatnonzero(np.abs(waypoint.positions - initial) > MOVING_JOINT_THRESHOLD_RAD)
    if len(moving) == 0:
        joints = 'no joint moves'
    elif len(moving) == NUM_JOINTS:
        joints = 'all joints move'
    else:
        joints = 'moving ' + ', '.join(JOINT_NAMES[i] for i in moving)
    return (f'waypoint {index} ({index + 1} of {count}): {waypoint.duration_s:g} s, '
            f'{sample_count(waypoint.duration_s)} commands; {joints}')
