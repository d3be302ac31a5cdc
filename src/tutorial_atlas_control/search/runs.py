"""One sweep run: a trajectory, gains, a timing scale and a push, played offline and measured.

A RunSpec carries everything a worker needs (waypoints and gains as numbers, not file
names), so a worker machine needs only the package, never the user's files. The run is the
offline player's (offline/player.py: the same schedule, commands and simulator as a live
run); its bag goes to a temporary file that is deleted, and the figures come from a step
hook (RunProbe) rather than from reading the bag back.
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.offline import (
    CommandLatency,
    OfflineRunError,
    write_offline_bag,
)
from tutorial_atlas_control.sim import AtlasSimulator, Gains, GroundUnderFeet, wrench_input
from tutorial_atlas_control.trajectories import Waypoint
from tutorial_atlas_control.units import NS_PER_S

__all__ = ['Push', 'RunSpec', 'SweepError', 'TABLE_COLUMNS', 'run_one']

#: The probe samples tracking and feet every this many 1 ms steps (falls: every step).
SAMPLE_EVERY_STEPS = 10
#: Sim time (s) from spawn to User mode and the first command, as `make demo`.
START_AFTER_S = 1.5


class SweepError(AtlasControlError):
    """A sweep or search input is refused (file, name, objective, scheduler, output)."""


@dataclass(frozen=True)
class Push:
    """A world-frame force (N) on the pelvis, `at_s` after the first command, for `duration_s`."""

    at_s: float
    force_n: tuple[float, float, float]
    duration_s: float

    def label(self) -> str:
        fx, fy, fz = self.force_n
        return f'{self.at_s:g}:{fx:g},{fy:g},{fz:g}:{self.duration_s:g}'


@dataclass(frozen=True)
class RunSpec:
    """One row's inputs. `waypoints` are (duration_s, 28 positions) before time scaling;
    `gains` are (p, i, d, i_clamp) rows of 28 before gain scaling; `latency_steps` (lo, hi)
    delays each command by lo..hi steps drawn from `seed` (CommandLatency), (0, 0) none."""

    index: int
    trajectory: str
    name: str
    gains_label: str
    waypoints: tuple[tuple[float, tuple[float, ...]], ...]
    gains: tuple[tuple[float, ...], ...]
    gain_scale: float = 1.0
    time_scale: float = 1.0
    push: Push | None = None
    seed: int = 0
    settle_s: float = 3.0
    latency_steps: tuple[int, int] = (0, 0)

    def latency(self) -> CommandLatency | None:
        lo, hi = self.latency_steps
        return CommandLatency(lo, hi, self.seed) if hi > 0 else None

    def scaled_waypoints(self) -> list[Waypoint]:
        return [Waypoint(duration_s * self.time_scale, np.array(positions))
                for duration_s, positions in self.waypoints]

    def scaled_gains(self) -> Gains:
        p, i, d, i_clamp = (np.array(row) for row in self.gains)
        s = self.gain_scale
        return Gains(p * s, i * s, d * s, i_clamp)


def spec_waypoints(waypoints: list[Waypoint]) -> tuple[tuple[float, tuple[float, ...]], ...]:
    """Waypoints as plain tuples (picklable, hashable, compared exactly)."""
    return tuple((float(w.duration_s), tuple(float(x) for x in w.positions)) for w in waypoints)


def spec_gains(gains: Gains) -> tuple[tuple[float, ...], ...]:
    return tuple(tuple(float(x) for x in row) for row in (gains.p, gains.i, gains.d,
                                                          gains.i_clamp))


#: The table's columns, in order: inputs, then outcome. No wall-clock field (determinism).
TABLE_COLUMNS: tuple[str, ...] = (
    'index', 'trajectory', 'name', 'gains', 'gain_scale', 'time_scale', 'push', 'latency_ms',
    'seed', 'played_s', 'fell', 'fall_time_s', 'stood_after_s', 'pelvis_dx_m', 'pelvis_dy_m',
    'pelvis_z_min_m', 'pelvis_z_end_m', 'r_foot_dx_m', 'r_foot_dy_m', 'r_foot_dz_end_m',
    'r_foot_lift_max_m', 'l_foot_dx_m', 'l_foot_dy_m', 'l_foot_dz_end_m', 'l_foot_lift_max_m',
    'tracking_rms_rad', 'error')


class RunProbe:
    """Step hook: applies the push and keeps the figures of one run (sim time in ns)."""

    def __init__(self, first_command_ns: int, trajectory_end_ns: int, push: Push | None) -> None:
        self.first_ns = first_command_ns
        self.end_ns = trajectory_end_ns
        self.push = push
        self.push_on_ns = (first_command_ns + int(round(push.at_s * NS_PER_S))
                           if push else None)
        self.push_off_ns = (self.push_on_ns + int(round(push.duration_s * NS_PER_S))
                            if push and self.push_on_ns is not None else None)
        self.pushing = False
        self.steps = 0
        self.fall_ns: int | None = None
        self.z_min_m = math.inf
        self.start: dict[str, np.ndarray] | None = None
        self.lift_max_m = 0.0
        self.l_lift_max_m = 0.0
        self.sq_error = 0.0
        self.error_count = 0
        self.last: dict[str, np.ndarray] = {}
        self._feet: tuple[int, int] | None = None
        self._ground: GroundUnderFeet | None = None  # the fall criterion's, once sim is known

    def _poses(self, sim: AtlasSimulator) -> dict[str, np.ndarray]:
        if self._feet is None:
            model = sim.atlas.model
            self._feet = (model.body('r_foot').id, model.body('l_foot').id)
        r, l_ = self._feet
        adr = sim.atlas.free_qpos_adr
        return {'pelvis': sim.data.qpos[adr:adr + 3].copy(), 'r_foot': sim.data.xpos[r].copy(),
                'l_foot': sim.data.xpos[l_].copy()}

    def __call__(self, sim: AtlasSimulator) -> None:
        now_ns = sim.sim_time_ns
        if now_ns < self.first_ns:
            return
        if self.push_on_ns is not None and self.push is not None:
            if not self.pushing and self.push_on_ns <= now_ns < (self.push_off_ns or 0):
                sim.apply_input(wrench_input(self.push.force_n, (0.0, 0.0, 0.0)))
                self.pushing = True
            elif self.pushing and now_ns >= (self.push_off_ns or 0):
                sim.apply_input(wrench_input((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)))
                self.pushing = False
        z_m = float(sim.data.qpos[sim.atlas.free_qpos_adr + 2])
        self.z_min_m = min(self.z_min_m, z_m)
        if self._ground is None:
            self._ground = GroundUnderFeet(sim.atlas, sim.data)
        if self.fall_ns is None and self._ground.fallen(z_m):
            self.fall_ns = now_ns
        if self.start is None:
            self.start = self._poses(sim)
        self.steps += 1
        if self.steps % SAMPLE_EVERY_STEPS:
            return
        self.last = poses = self._poses(sim)
        self.lift_max_m = max(self.lift_max_m, float(poses['r_foot'][2] - self.start['r_foot'][2]))
        self.l_lift_max_m = max(self.l_lift_max_m,
                                float(poses['l_foot'][2] - self.start['l_foot'][2]))
        if now_ns <= self.end_ns:
            error = sim.joint_positions() - sim.commands.law_command.position
            self.sq_error += float(error @ error)
            self.error_count += NUM_JOINTS

    def row(self, run_end_ns: int) -> dict[str, Any]:
        start = self.start or {}
        last = self.last or start
        def delta(body: str, axis: int) -> float:
            return float(last[body][axis] - start[body][axis]) if start else math.nan
        fall_s = None if self.fall_ns is None else (self.fall_ns - self.first_ns) / NS_PER_S
        stood_until_ns = run_end_ns if self.fall_ns is None else self.fall_ns
        return {
            'fell': self.fall_ns is not None,
            'fall_time_s': fall_s,
            'stood_after_s': max(0.0, (stood_until_ns - self.end_ns) / NS_PER_S),
            'pelvis_dx_m': delta('pelvis', 0), 'pelvis_dy_m': delta('pelvis', 1),
            'pelvis_z_min_m': self.z_min_m,
            'pelvis_z_end_m': float(last['pelvis'][2]) if last else math.nan,
            'r_foot_dx_m': delta('r_foot', 0), 'r_foot_dy_m': delta('r_foot', 1),
            'r_foot_dz_end_m': delta('r_foot', 2), 'r_foot_lift_max_m': self.lift_max_m,
            'l_foot_dx_m': delta('l_foot', 0), 'l_foot_dy_m': delta('l_foot', 1),
            'l_foot_dz_end_m': delta('l_foot', 2), 'l_foot_lift_max_m': self.l_lift_max_m,
            'tracking_rms_rad': (math.sqrt(self.sq_error / self.error_count)
                                 if self.error_count else math.nan),
        }


def input_columns(spec: RunSpec) -> dict[str, Any]:
    return {'index': spec.index, 'trajectory': spec.trajectory, 'name': spec.name,
            'gains': spec.gains_label, 'gain_scale': spec.gain_scale,
            'time_scale': spec.time_scale, 'push': spec.push.label() if spec.push else '',
            'latency_ms': (f'{spec.latency_steps[0]}:{spec.latency_steps[1]}'
                           if spec.latency_steps[1] > 0 else ''),
            'seed': spec.seed,
            'played_s': round(sum(d for d, _ in spec.waypoints) * spec.time_scale, 9)}


def run_one(spec: RunSpec) -> dict[str, Any]:
    """Play `spec` offline and return its table row (a diverged run: fell, error set)."""
    waypoints = spec.scaled_waypoints()
    first_ns = int(round(START_AFTER_S * NS_PER_S))
    end_ns = first_ns + int(round(sum(w.duration_s for w in waypoints) * NS_PER_S))
    probe = RunProbe(first_ns, end_ns, spec.push)
    error = ''
    with tempfile.TemporaryDirectory(prefix='tac_sweep_') as scratch:
        bag = Path(scratch) / 'run.bag'
        try:
            run = write_offline_bag(bag, spec.trajectory, spec.name, waypoints,
                                    spec.scaled_gains(), spec.settle_s, START_AFTER_S,
                                    on_step=probe, latency=spec.latency())
            run_end_ns = int(round(run.sim_time_s * NS_PER_S))
        except OfflineRunError as err:
            error = str(err)
            run_end_ns = probe.fall_ns or first_ns
    row = {**input_columns(spec), **probe.row(run_end_ns), 'error': error}
    if error:
        row['fell'] = True
        if row['fall_time_s'] is None:
            row['fall_time_s'] = (run_end_ns - first_ns) / NS_PER_S
    return row

