"""A recorded run's laser: its /multisense_sl/laser/scan stream, its spindle's commands, and
the scans' points placed in the world (`analyze_bag.py --scan-cloud`).

The scans are parsed straight from their ROS 1 bytes (a header, seven float32 figures, the
ranges, the intensities): a minute of scans is 2 400 messages of 720 ranges. A point's place
is the scan's stamp's pose of the `head` body (the model placed as the bag recorded it:
bags/feet.RecordedKinematics), multisense_sl.urdf's frames (sensors/frames.py) and the
spindle's angle then: from the recorded /tf's head -> hokuyo_link transforms (the
simulator's, 50 Hz, stamped with the sim time they hold), linear between them (the spindle
turns at a steady speed); a bag without them (the tf off) simulates the spindle again from
the recorded set_spindle_speed commands (sensors/spindle.py) from 0 at sim time 0, each
taken at its record time. That time is the recorder's receipt on its own clock, not the step
the simulator took the command in: on a live run's bag the spindle so simulated lagged the
recorded /tf by 94 mrad throughout (5.4 degrees of the scan's plane; the height map's error
at the footsteps p95 2.0 cm, against 2 mm from /tf).
"""

from __future__ import annotations

import copy
import math
import struct
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tutorial_atlas_control import topics
from tutorial_atlas_control.bags.feet import RecordedKinematics
from tutorial_atlas_control.bags.reader import BagData
from tutorial_atlas_control.bags.records import open_bag
from tutorial_atlas_control.course import course_height_m
from tutorial_atlas_control.sensors import (
    HEAD_HOKUYO_FRAME,
    HEAD_LINK,
    HOKUYO_LINK,
    HeightMap,
    Spindle,
    frame_in_head,
    scan_points,
    spindle_command,
)
from tutorial_atlas_control.units import NS_PER_S

__all__ = ['LaserScans', 'hokuyo_angles', 'laser_height_map', 'map_error_lines',
           'placed_scans', 'read_laser_scans', 'scan_cloud', 'spindle_angles',
           'spindle_command_steps']

_HEADER = struct.Struct('<III')
_U32 = struct.Struct('<I')
_FIGURES = struct.Struct('<7f')
_QUATERNION = struct.Struct('<4d')
#: The robot's body whose (x, y) centres the height map's self filter.
PELVIS_LINK = 'pelvis'
#: The physics step the spindle is simulated at (s): the simulator's.
SPINDLE_STEP_S = 0.001
#: How far (s) from its record time a spindle command may have first acted: the record
#: time is the recorder's receipt on its clock (94 ms off on a live bag).
COMMAND_SEARCH_S = 1.0
#: The samples after a candidate step that must match the spindle it would give (s).
COMMAND_CHECK_S = 0.06
#: A recorded angle and the one simulated are the same within this (rad): /tf holds the
#: angle as a quaternion's half angle, float64.
SAME_ANGLE_RAD = 1e-9


@dataclass(frozen=True)
class LaserScans:
    """The scans of a bag: stamps (sim time, ns), ranges (scans, rays; float32, as sent),
    the first scan's frame and angles, and set_spindle_speed as recorded: (record time in
    sim ns, value)."""

    stamp_ns: np.ndarray
    ranges: np.ndarray
    frame_id: str
    angle_min: float
    angle_increment: float
    spindle_commands: list[tuple[int, float]]
    #: The recorded /tf's hokuyo_joint: (stamps in sim ns, angles in rad, unwrapped); None:
    #: the bag has none.
    spindle_samples: tuple[np.ndarray, np.ndarray] | None = None

    def angles(self) -> np.ndarray:
        return self.angle_min + self.angle_increment * np.arange(self.ranges.shape[1])


def _parse_scan(raw: bytes) -> tuple[int, str, tuple[float, ...], np.ndarray]:
    """(stamp ns, frame_id, the seven figures, ranges) of one serialized LaserScan."""
    _seq, secs, nsecs = _HEADER.unpack_from(raw, 0)
    (length,) = _U32.unpack_from(raw, 12)
    frame = raw[16:16 + length].decode()
    at = 16 + length
    figures = _FIGURES.unpack_from(raw, at)
    (count,) = _U32.unpack_from(raw, at + _FIGURES.size)
    ranges = np.frombuffer(raw, dtype='<f4', count=count, offset=at + _FIGURES.size + 4)
    return secs * NS_PER_S + nsecs, frame, figures, ranges


def read_laser_scans(path: Path | str) -> LaserScans | None:
    """The bag's scans and spindle commands; None when it has no scan."""
    records = open_bag(Path(path))
    try:
        scan_connections = [c for c in records.connections if c.topic == topics.LASER_SCAN]
        if not scan_connections:
            return None
        _times, raws = records.raw_messages(scan_connections)
        speed_connections = [c for c in records.connections
                             if c.topic == topics.SET_SPINDLE_SPEED]
        speed_times, speed_raws = records.raw_messages(speed_connections)
        _tf_times, tf_raws = records.raw_messages(
            [c for c in records.connections if c.topic == topics.TF])
    finally:
        records.close()
    if not raws:
        return None
    parsed = [_parse_scan(raw) for raw in raws]
    _stamp, frame, figures, _ranges = parsed[0]
    commands = [(int(t), struct.unpack_from('<d', raw, 0)[0])
                for t, raw in zip(speed_times.tolist(), speed_raws)]
    return LaserScans(np.array([p[0] for p in parsed], dtype=np.int64),
                      np.stack([p[3] for p in parsed]), frame, figures[0], figures[2], commands,
                      hokuyo_angles(tf_raws))


def hokuyo_angles(tf_raws: list[bytes]) -> tuple[np.ndarray, np.ndarray] | None:
    """The hokuyo_joint's angles in serialized /tf messages (tf2_msgs/TFMessage): the
    transforms to hokuyo_link, their stamps (ns) and angles about x (rad, unwrapped), in
    stamp order; None without any. Only messages naming the link are parsed."""
    child = HOKUYO_LINK.encode()
    found: list[tuple[int, float]] = []
    for raw in tf_raws:
        if child not in raw:
            continue
        (count,) = _U32.unpack_from(raw, 0)
        at = 4
        for _ in range(count):
            _seq, secs, nsecs = _HEADER.unpack_from(raw, at)
            (length,) = _U32.unpack_from(raw, at + 12)
            at += 16 + length
            (length,) = _U32.unpack_from(raw, at)
            name = raw[at + 4:at + 4 + length]
            at += 4 + length
            qx, _qy, _qz, qw = _QUATERNION.unpack_from(raw, at + 24)  # after the translation
            at += 56
            if name == child:
                found.append((secs * NS_PER_S + nsecs, 2.0 * float(np.arctan2(qx, qw))))
    if not found:
        return None
    stamps, first = np.unique(np.array([stamp for stamp, _ in found], dtype=np.int64),
                              return_index=True)  # sorted; a stamp sent twice counted once
    return stamps, np.unwrap(np.array([angle for _, angle in found])[first])


def spindle_angles(scans: LaserScans) -> np.ndarray:
    """The spindle's angle (rad) at each scan's stamp: linear between the recorded /tf's
    (beyond its first or last two, along them), else simulated again from the commands."""
    if scans.spindle_samples is not None and len(scans.spindle_samples[0]) >= 2:
        return _between(scans.spindle_samples, scans.stamp_ns)
    angles = np.zeros(len(scans.stamp_ns))
    if not scans.spindle_commands:
        return angles
    spindle = Spindle(SPINDLE_STEP_S)
    step_ns = round(SPINDLE_STEP_S * NS_PER_S)
    commands = sorted(scans.spindle_commands)
    now_ns, next_command = 0, 0
    for row, stamp in enumerate(scans.stamp_ns.tolist()):
        while now_ns < stamp:
            while next_command < len(commands) and commands[next_command][0] <= now_ns:
                speed = spindle_command(commands[next_command][1]).speed
                if speed is not None:
                    spindle.command(speed)
                next_command += 1
            spindle.step()
            now_ns += step_ns
        angles[row] = spindle.angle
    return angles


def spindle_command_steps(scans: LaserScans) -> list[tuple[int, float]] | None:
    """When each recorded spindle command first acted: (the sim time (ns) at the end of the
    first spindle step that had its speed, the speed), in order, found where the spindle
    simulated from rest at sim time 0 gives the recorded /tf's angles; None when the bag
    has no /tf samples of the spindle or no step within COMMAND_SEARCH_S of a command's
    record time gives them. Ignored commands (NaN) are left out."""
    if scans.spindle_samples is None:
        return None
    stamps, angles = scans.spindle_samples
    step_ns = round(SPINDLE_STEP_S * NS_PER_S)
    search_ns = round(COMMAND_SEARCH_S * NS_PER_S)
    spindle, now_ns = Spindle(SPINDLE_STEP_S), 0  # the base: the commands found so far
    found: list[tuple[int, float]] = []
    for record_ns, value in sorted(scans.spindle_commands):
        speed = spindle_command(value).speed
        if speed is None:
            continue
        first_ns = max(now_ns + step_ns, (record_ns - search_ns) // step_ns * step_ns)
        acted = None
        for end_ns in range(first_ns, record_ns + search_ns + 1, step_ns):
            while now_ns < end_ns - step_ns:  # the base up to the candidate step's start
                spindle.step()
                now_ns += step_ns
                if not _same(_recorded_at(stamps, angles, now_ns), spindle.angle):
                    return None  # the recorded angle left the base before any candidate
            trial = copy.copy(spindle)
            trial.command(speed)
            if _follows(trial, end_ns, stamps, angles, step_ns):
                acted = end_ns
                break
        if acted is None:
            return None
        spindle.command(speed)
        found.append((acted, speed))
    return found


def _recorded_at(stamps: np.ndarray, angles: np.ndarray, at_ns: int) -> float | None:
    """The recorded angle stamped `at_ns`, or None when no sample is."""
    row = int(np.searchsorted(stamps, at_ns))
    return float(angles[row]) if row < len(stamps) and stamps[row] == at_ns else None


def _same(recorded: float | None, angle_rad: float) -> bool:
    """Whether `angle_rad` is the recorded angle (no sample: nothing says otherwise)."""
    return recorded is None or \
        abs(math.remainder(recorded - angle_rad, 2.0 * math.pi)) < SAME_ANGLE_RAD


def _follows(trial: Spindle, end_ns: int, stamps: np.ndarray, angles: np.ndarray,
             step_ns: int) -> bool:
    """Whether `trial`, stepped from the step ending at `end_ns`, gives every recorded
    sample over the next COMMAND_CHECK_S (at least one)."""
    checked = 0
    for at_ns in range(end_ns, end_ns + round(COMMAND_CHECK_S * NS_PER_S) + 1, step_ns):
        trial.step()
        recorded = _recorded_at(stamps, angles, at_ns)
        if not _same(recorded, trial.angle):
            return False
        checked += recorded is not None
    return checked > 0


def _between(samples: tuple[np.ndarray, np.ndarray], stamp_ns: np.ndarray) -> np.ndarray:
    """The samples' angle at `stamp_ns`, linear between them and along the nearest two
    outside them."""
    stamps, angles = samples
    at = np.clip(np.searchsorted(stamps, stamp_ns, side='right') - 1, 0, len(stamps) - 2)
    span = (stamps[at + 1] - stamps[at]).astype(float)
    fraction = (stamp_ns - stamps[at]).astype(float) / np.where(span > 0, span, 1.0)
    return angles[at] + fraction * (angles[at + 1] - angles[at])


def placed_scans(data: BagData, scans: LaserScans, every: int = 1
                 ) -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray, tuple[float, float]]]:
    """Every `every`-th scan with a return, placed: (the laser frame's origin and rotation
    in the world, the ranges, the pelvis's (x, y) then)."""
    if scans.frame_id != HEAD_HOKUYO_FRAME:
        return
    kinematics = RecordedKinematics(data)
    head = kinematics.body_id(HEAD_LINK)
    pelvis = kinematics.body_id(PELVIS_LINK)
    spindle = spindle_angles(scans)
    for row in range(0, len(scans.stamp_ns), max(1, every)):
        ranges = scans.ranges[row].astype(float)
        if not np.isfinite(ranges).any():
            continue
        # Sim time on the run's timeline; a run whose sim time went back (a
        # reset_simulation) is placed in its first epoch's.
        placed = kinematics.place(data.run_time_s(scans.stamp_ns[row] / NS_PER_S, 0))
        offset, rotation = frame_in_head(HEAD_HOKUYO_FRAME, float(spindle[row]))
        head_rotation = placed.xmat[head].reshape(3, 3)
        yield (placed.xpos[head] + head_rotation @ offset, head_rotation @ rotation, ranges,
               (float(placed.xpos[pelvis][0]), float(placed.xpos[pelvis][1])))


def scan_cloud(data: BagData, scans: LaserScans, every: int = 1) -> np.ndarray:
    """The points (x, y, z in the world, m) of every `every`-th scan's finite ranges."""
    angles = scans.angles()
    points = [scan_points(origin, rotation, angles, ranges)
              for origin, rotation, ranges, _ in placed_scans(data, scans, every)]
    return np.concatenate(points) if points else np.empty((0, 3))


def laser_height_map(data: BagData, scans: LaserScans) -> HeightMap:
    """The height map (sensors/height_map.py) of every scan of the run, each with the
    pelvis's (x, y) then for its self filter."""
    height_map = HeightMap()
    angles = scans.angles()
    for origin, rotation, ranges, pelvis_xy in placed_scans(data, scans):
        height_map.add_scan(origin, rotation, angles, ranges, pelvis_xy)
    return height_map


def map_error_lines(height_map: HeightMap, footsteps: list[tuple[float, float]]) -> list[str]:
    """The map's figures at the `footsteps` (x, y) a walk asked for: how many it saw, its
    heights there against the course's description (course_height_m)."""
    errors = np.array([height_map.height_m(x, y) - course_height_m(x, y) for x, y in footsteps])
    seen = errors[np.isfinite(errors)]
    lines = [f'laser map: {len(height_map.points)} points of {height_map.scans} scans; '
             f'{len(seen)} of {len(footsteps)} footsteps asked for on seen ground']
    if len(seen):
        size = np.abs(seen)
        lines.append(f'  its height there against the course\'s: p50 {np.median(size) * 100:.1f} '
                     f'cm, p95 {np.percentile(size, 95) * 100:.1f} cm, max '
                     f'{size.max() * 100:.1f} cm (signed median {np.median(seen) * 100:+.1f} cm)')
    return lines
