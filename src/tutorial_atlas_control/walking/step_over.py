"""A static step's swing over terrain higher than its line: up, across, down.

swing.SwingPath lifts the sole SWING_HEIGHT_M over the straight line between its ends,
moving it forward all the while: stepping up a 0.2 m cinder block, the toe reaches the
block's edge still below its top and kicks it away (measured: the block pushed 16 cm and
turned 0.48 rad, the foot back on the floor). StepOverPath, for Step (quasi-static: time is
not short), first lifts the sole straight up to `apex_m`, then moves it across and turns
it at that height, then lowers it straight down onto its end: while it moves over the
ground, every point of the flat sole, toe and heel, is at `apex_m`. Each of the three
moves is a quintic in its share of the swing's phase, at rest at both of its ends, so the
path is at rest at the corners and its acceleration continuous.

`clear_apex_m` is where the apex goes: `clearance_m` above the highest of the ends and of
the terrain under the sole's sweep (sampled by the caller, e.g. with sim/ground.py's rays),
and `needs_step_over` says when the ordinary path will not do: the terrain between the ends
(or the end) rises more than `tolerance_m` over the lower end, which the swing's bump would
not clear with margin.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from tutorial_atlas_control.walking.errors import WalkingError
from tutorial_atlas_control.walking.footsteps import wrap_angle
from tutorial_atlas_control.walking.swing import quintic

__all__ = ['STEP_OVER_CLEARANCE_M', 'StepOverPath', 'clear_apex_m', 'needs_step_over',
           'sweep_points', 'terrain_top_m']

#: How high over the highest terrain under its sweep the sole moves across (m).
STEP_OVER_CLEARANCE_M = 0.06
#: Terrain rising less than this (m) above the lower of the ends is left to the ordinary
#: swing (its 0.08 m bump): a flat step's path is not changed.
STEP_OVER_TOLERANCE_M = 0.02
#: The share of the swing's phase the lift takes, and the descent (the crossing the rest).
RISE_SHARE = 1.0 / 3.0


def needs_step_over(start_z_m: float, end_z_m: float, terrain_top_m: float,
                    tolerance_m: float = STEP_OVER_TOLERANCE_M) -> bool:
    """Whether a swing from `start_z_m` to `end_z_m` over terrain whose top under the
    sole's sweep is `terrain_top_m` must step over (rather than along SwingPath)."""
    lower = min(start_z_m, end_z_m)
    return max(start_z_m, end_z_m, terrain_top_m) - lower > tolerance_m


def clear_apex_m(start_z_m: float, end_z_m: float, terrain_top_m: float,
                 clearance_m: float = STEP_OVER_CLEARANCE_M) -> float:
    """The height (m) the sole crosses at: `clearance_m` over the highest of its ends and
    the terrain under its sweep."""
    return max(start_z_m, end_z_m, terrain_top_m) + clearance_m


def sweep_points(start: np.ndarray, end: np.ndarray, start_yaw_rad: float, end_yaw_rad: float,
                 half_size_m: tuple[float, float], spacing_m: float = 0.02) -> np.ndarray:
    """World (x, y) points (n, 2) covering the sole's rectangle (`half_size_m`: along and
    across it, about its centre) as it moves straight from `start` to `end` ((x, y, ...)),
    turning from one yaw to the other: a 3 x 3 grid (corners, edges' middles, centre) at
    every `spacing_m` of the way, and at both ends."""
    start, end = np.asarray(start, dtype=float)[:2], np.asarray(end, dtype=float)[:2]
    count = max(int(np.ceil(float(np.linalg.norm(end - start)) / spacing_m)), 1) + 1
    half_length, half_width = half_size_m
    grid = np.array([(a * half_length, b * half_width)
                     for a in (-1.0, 0.0, 1.0) for b in (-1.0, 0.0, 1.0)])
    turn = wrap_angle(end_yaw_rad - start_yaw_rad)
    points = []
    for s in np.linspace(0.0, 1.0, count):
        yaw = start_yaw_rad + s * turn
        c, sn = np.cos(yaw), np.sin(yaw)
        rotation = np.array([[c, -sn], [sn, c]])
        points.append(start + s * (end - start) + grid @ rotation.T)
    return np.concatenate(points)


def terrain_top_m(points: np.ndarray, height_m: Callable[[float, float], float]) -> float:
    """The highest ground (m) under `points` ((n, 2), world) by `height_m(x, y)` (-inf over
    no ground is ignored; -inf when nothing is found)."""
    heights = [height_m(x, y) for x, y in np.asarray(points, dtype=float).tolist()]
    return max([h for h in heights if np.isfinite(h)], default=-np.inf)


@dataclass(frozen=True)
class StepOverPath:
    """A foot moved from `start` to `end` ((x, y, z) m and yaw rad, world) in `duration_s`:
    up to `apex_m`, across (turning), down. SwingPath's interface (at, acceleration)."""

    start: np.ndarray   # (3,)
    end: np.ndarray     # (3,)
    start_yaw_rad: float
    end_yaw_rad: float
    duration_s: float
    apex_m: float

    def __post_init__(self) -> None:
        if not self.duration_s > 0.0:
            raise WalkingError(f'swing duration {self.duration_s} s is not positive')
        if self.apex_m < max(float(self.start[2]), float(self.end[2])):
            raise WalkingError(f'step-over apex {self.apex_m} m is below an end of the swing')

    @property
    def descent_s(self) -> float:
        """When the sole begins to come down (s after lift-off): from then on a touch is
        its landing (its servo lags the path: a foot held to the path's end pressed on
        the block and unloaded the stance sole, which turned)."""
        return (1.0 - RISE_SHARE) * self.duration_s

    def _profiles(self, s: float) -> tuple[tuple[float, float, float], tuple[float, float, float],
                                           float, float]:
        """(the crossing's quintic, the vertical's quintic: value, d/ds, d2/ds2 in the
        swing's phase; the vertical's from and to heights)."""
        share = RISE_SHARE
        across = _stretched(s, share, 1.0 - share)
        if s < 0.5:
            return across, _stretched(s, 0.0, share), float(self.start[2]), self.apex_m
        return across, _stretched(s, 1.0 - share, 1.0), self.apex_m, float(self.end[2])

    def at(self, t_s: float) -> tuple[np.ndarray, np.ndarray, float, float]:
        """(position (3,), velocity (3,), yaw, yaw rate) of the sole at `t_s` after lift-off;
        held at the ends outside [0, duration]."""
        s = min(max(t_s / self.duration_s, 0.0), 1.0)
        across, vertical, low, high = self._profiles(s)
        delta = self.end - self.start
        position = self.start + across[0] * delta
        position[2] = low + vertical[0] * (high - low)
        velocity = across[1] * delta / self.duration_s
        velocity[2] = vertical[1] * (high - low) / self.duration_s
        turn = wrap_angle(self.end_yaw_rad - self.start_yaw_rad)
        yaw = wrap_angle(self.start_yaw_rad + across[0] * turn)
        return position, velocity, yaw, across[1] * turn / self.duration_s

    def acceleration(self, t_s: float) -> tuple[np.ndarray, float]:
        """(acceleration (3,), yaw acceleration) of the sole at `t_s` after lift-off; zero
        outside (0, duration)."""
        s = t_s / self.duration_s
        if not 0.0 < s < 1.0:
            return np.zeros(3), 0.0
        per_s2 = 1.0 / (self.duration_s * self.duration_s)
        across, vertical, low, high = self._profiles(s)
        acceleration = across[2] * per_s2 * (self.end - self.start)
        acceleration[2] = vertical[2] * per_s2 * (high - low)
        turn = wrap_angle(self.end_yaw_rad - self.start_yaw_rad)
        return acceleration, across[2] * per_s2 * turn


def _stretched(s: float, begin: float, end: float) -> tuple[float, float, float]:
    """swing.quintic over [begin, end] of the phase (0 before, 1 after), its derivatives in
    s."""
    width = end - begin
    value, rate, curve = quintic((s - begin) / width)
    if not begin < s < end:
        rate = curve = 0.0
    return value, rate / width, curve / (width * width)
