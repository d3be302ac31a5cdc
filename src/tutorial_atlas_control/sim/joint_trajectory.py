"""gazebo_ros_joint_trajectory's /joint_trajectory, checked whole before playback.

DRCSim's plugin set each point with Joint::SetAngle, whatever the joint's limits, and
added each point's `time_from_start` to a running start. DRC-era clients (DRCSim's own
animate-joints tutorial: 1500 points of 0.01 s, ±0.5 rad sines) rely on both, so:
* a position outside its joint's limits is clamped to the limit (the message says which
  joints and by how much: one warning per message), not refused;
* times that do not increase are read as DRCSim read them (one info line says so): point 0
  at the start, point k at the start + the first k points' `time_from_start` (the last
  point's is not used); strictly increasing times keep the message's own definition, each
  point at the start + its `time_from_start`. (2.5.2's SetTrajectory copied only the
  positions into the points it played, so there every time_from_start read as 0 and each
  point came one world update, 1 ms, after the last; the port plays the times the client
  sent, as the tutorial's 0.01 s means.)
Anything else that cannot be played is refused whole, with one line naming the field:
NaN/Inf or absurd numbers, unknown or repeated joint names, lengths that do not match,
negative times, a frame that is no link of the robot.
"""

from __future__ import annotations

import logging
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from tutorial_atlas_control.joints import JOINT_NAMES, bare_joint_name, joint_index
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.vrc import (
    InputError,
    InputNote,
    TrajectoryInput,
    finite_values,
)
from tutorial_atlas_control.units import NS_PER_S

__all__ = ['MAX_TRAJECTORY_POINTS', 'TrajectoryMessage', 'trajectory_input']

MAX_TRAJECTORY_POINTS = 100_000
#: Positions (rad) and the ignored fields past these are refused as absurd, not clamped.
MAX_POSITION_RAD = 1e3
MAX_UNUSED_VALUE = 1e6
#: `header.frame_id`s that keep the robot's own pose (gazebo_ros_joint_trajectory's
#: world/map; the pelvis is the model's root). Any other names a link kept in place.
WORLD_FRAMES = ('', 'world', 'map', '/map')
#: The fields of a point that playback ignores, as gazebo_ros_joint_trajectory did.
UNUSED_FIELDS = ('velocities', 'accelerations', 'effort')


@dataclass(frozen=True)
class TrajectoryMessage:
    """A trajectory_msgs/JointTrajectory's fields, as playback reads them.

    `times_ns`: each point's time_from_start (ns); `unused`: per point, the fields playback
    ignores (velocities, accelerations, effort), still checked so that a broken message is
    refused whole.
    """

    frame_id: str
    stamp_ns: int
    joint_names: Sequence[str]
    positions: Sequence[Sequence[float]]
    times_ns: Sequence[int]
    unused: Sequence[Mapping[str, Sequence[float]]] = ()

    @classmethod
    def from_ros(cls, msg: Any) -> TrajectoryMessage:
        """The fields of a trajectory_msgs/JointTrajectory object (genpy times)."""
        points = msg.points
        return cls(msg.header.frame_id, msg.header.stamp.to_nsec(), msg.joint_names,
                   [point.positions for point in points],
                   [point.time_from_start.to_nsec() for point in points],
                   [{name: getattr(point, name) for name in UNUSED_FIELDS} for point in points])


def trajectory_input(message: TrajectoryMessage, lower_rad: np.ndarray, upper_rad: np.ndarray,
                     links: Collection[str] = (atlas_model.PELVIS_BODY,)) -> TrajectoryInput:
    """Check a /joint_trajectory message whole and make it a playback input.

    `header.frame_id` is world/map (or empty: the robot keeps its pose) or one of `links`
    (bare or `atlas::`), kept in place as gazebo_ros_joint_trajectory's reference link.
    The input's notes say what was clamped and how the times were read.

    Raises:
        InputError: what cannot be played (see the module's docstring), naming the field.
    """
    reference = _reference_link(message.frame_id, links)
    joints = _joint_indices(message.joint_names)
    positions = message.positions
    if not positions:
        raise InputError('the trajectory has no points')
    if len(positions) > MAX_TRAJECTORY_POINTS:
        raise InputError(f'{len(positions)} points (at most {MAX_TRAJECTORY_POINTS})')
    rows = [_position_row(number, row, len(joints)) for number, row in enumerate(positions)]
    _check_unused(message.unused, len(joints))
    times, timing = _point_times(message.times_ns, len(rows))
    clamped, clamping = _clamp_to_limits(np.array(rows), joints, lower_rad, upper_rad)
    notes = tuple(note for note in (clamping, timing) if note is not None)
    return TrajectoryInput(joints, tuple(tuple(float(v) for v in row) for row in clamped),
                           times, int(message.stamp_ns), reference, notes)


def _reference_link(frame_id: str, links: Collection[str]) -> str:
    """The link kept in place ('' for the pelvis, the model's root)."""
    reference = bare_joint_name(frame_id)
    if frame_id in WORLD_FRAMES or reference == atlas_model.PELVIS_BODY:
        return ''
    if reference not in links:
        raise InputError(f'header.frame_id {frame_id[:40]!r} is neither world, map nor a link '
                         'of the robot')
    return reference


def _joint_indices(joint_names: Sequence[str]) -> tuple[int, ...]:
    """Each name's index in JOINT_NAMES (bare or `atlas::`)."""
    if not joint_names:
        raise InputError('joint_names is empty')
    joints: list[int] = []
    for name in joint_names:
        index = joint_index(name)
        if index is None:
            raise InputError(f'unknown joint name {name[:40]!r}')
        if index in joints:
            raise InputError(f'joint {name[:40]!r} named twice')
        joints.append(index)
    return tuple(joints)


def _position_row(number: int, row: Sequence[float], joint_count: int) -> tuple[float, ...]:
    if len(row) != joint_count:
        raise InputError(f'point {number} has {len(row)} positions for {joint_count} joint names')
    return finite_values(row, f'point {number} position', MAX_POSITION_RAD)


def _check_unused(unused: Sequence[Mapping[str, Sequence[float]]], joint_count: int) -> None:
    for number, fields in enumerate(unused):
        for name, values in fields.items():
            if len(values) not in (0, joint_count):
                raise InputError(f'point {number} has {len(values)} {name} for '
                                 f'{joint_count} joint names')
            finite_values(values, f'point {number} {name}', MAX_UNUSED_VALUE)


def _point_times(times_ns: Sequence[int], point_count: int
                 ) -> tuple[tuple[int, ...], InputNote | None]:
    """Each point's time after the start (ns), and a note if read as DRCSim 2.5.2 did."""
    times = [int(t) for t in times_ns]
    if len(times) != point_count:
        raise InputError(f'{len(times)} times for {point_count} points')
    for number, time_ns in enumerate(times):
        if time_ns < 0:
            raise InputError(f'point {number} time_from_start {time_ns / NS_PER_S:g} s is '
                             'negative')
    stall = next((k for k in range(1, len(times)) if times[k] <= times[k - 1]), None)
    if stall is None:
        return tuple(times), None
    running = [0]
    for duration_ns in times[:-1]:
        running.append(running[-1] + duration_ns)
    return tuple(running), InputNote(logging.INFO, (
        f'time_from_start does not increase (point {stall}: {times[stall] / NS_PER_S:g} s '
        f'after {times[stall - 1] / NS_PER_S:g} s), read as DRCSim 2.5.2 read it: each '
        f"point's time_from_start added to the previous point's time; the {point_count} "
        f'points play over {running[-1] / NS_PER_S:g} s'))


def _clamp_to_limits(rows: np.ndarray, joints: tuple[int, ...], lower_rad: np.ndarray,
                     upper_rad: np.ndarray) -> tuple[np.ndarray, InputNote | None]:
    """The positions clamped to their joints' limits, and a note naming what was clamped."""
    lower, upper = lower_rad[list(joints)], upper_rad[list(joints)]
    clamped = np.clip(rows, lower, upper)
    excess = np.abs(rows - clamped)
    outside = np.flatnonzero(excess.max(axis=0) > 0.0)
    if not outside.size:
        return clamped, None
    parts = []
    for column in outside:
        name, beyond = JOINT_NAMES[joints[column]], excess[:, column]
        parts.append(f'{name} by up to {beyond.max():.3g} rad beyond [{lower[column]:g}, '
                     f'{upper[column]:g}] ({np.count_nonzero(beyond)} of {len(rows)} points)')
    return clamped, InputNote(logging.WARNING, (
        "positions outside their joints' limits, clamped to the limits: " + '; '.join(parts)))
