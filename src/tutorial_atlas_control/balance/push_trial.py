"""Offline trials of the Stand controller on the simulator: stand, get pushed, and say
whether the robot stayed up without a step. Deterministic (the simulator is), so tests
assert exact outcomes and the bench can search the largest push survived.

The controller runs as the simulator's Stand behaviour (StandBehaviour installed, the
Stand mode, its torque as f_out), the path the node steps; pushes are the simulator's
/atlas/apply_pelvis_force input (a force on the pelvis, held from one input to the next).
"""

from __future__ import annotations

import copy
import functools
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from tutorial_atlas_control.balance.stand import StandGains
from tutorial_atlas_control.balance.stand_behaviour import StandBehaviour
from tutorial_atlas_control.balance.stand_pose import place_in_stand_pose
from tutorial_atlas_control.sim import (
    DEFAULT_GAINS_FILE,
    AtlasModel,
    AtlasSimulator,
    Gains,
    GroundUnderFeet,
    load_gains_yaml,
    load_model,
    standing,
    wrench_input,
)

Vector = tuple[float, float, float]

#: The pushes of the robustness figures last this long (s), as the issue's bench does.
PUSH_DURATION_S = 0.2
#: A sole that moved more than this (m) in the horizontal plane has stepped or slid.
FOOT_TRAVEL_LIMIT_M = 0.02


@dataclass(frozen=True)
class Push:
    """A constant force (N, world) on the pelvis from `start_s` for `duration_s`."""

    start_s: float
    force_n: Vector
    duration_s: float = PUSH_DURATION_S

    @property
    def impulse_ns(self) -> float:
        return float(np.linalg.norm(self.force_n)) * self.duration_s


@dataclass(frozen=True)
class TrialResult:
    """What became of the robot: `stood` = sim/fall.py's `standing` throughout (the pelvis
    at least STANDING_PELVIS_M above the ground under the feet) and neither sole moved more
    than FOOT_TRAVEL_LIMIT_M; `lowest_pelvis_m` is the pelvis's lowest above that ground."""

    stood: bool
    lowest_pelvis_m: float
    foot_travel_m: float
    steps: int
    controller_cpu_s: float  # process time spent estimating and controlling

    @property
    def cost_per_step_us(self) -> float:
        return self.controller_cpu_s / max(self.steps, 1) * 1e6


@functools.cache
def _standing_parts() -> tuple[AtlasModel, Gains]:
    """The model and the parameter gains as compiled and parsed once a process: the
    offline trials' own copies are made from them."""
    return load_model(), load_gains_yaml(DEFAULT_GAINS_FILE)


def standing_simulator() -> AtlasSimulator:
    """A simulator (the parameter gains, no pin) whose robot stands on the ground in the
    Stand pose: where the offline trials start. Its model and gains are deep copies of ones
    compiled and parsed once a process (a simulator writes into its model: the joints'
    damping): a sweep's trial spent 25-30 ms of CPU on the MJCF's compile and the gains' YAML
    (4-5 µs of a 6-step walk's offline step), its copies take 4 ms. The MjModel is copied
    once, by AtlasSimulator itself (a model of its own): copying it here too cost 3.4 ms a
    trial, half a µs of a 6-step walk's step."""
    atlas, gains = _standing_parts()
    own_atlas = copy.deepcopy(atlas, {id(atlas.model): atlas.model})  # all but its MjModel
    sim = AtlasSimulator(own_atlas, copy.deepcopy(gains), time_to_unpin_s=0.0)
    place_in_stand_pose(sim.atlas, sim.data)
    return sim


def push_events(pushes: Sequence[Push], dt_s: float) -> list[tuple[int, Vector]]:
    """The pelvis force to set at each tick where it changes, (tick, force (N)) in order:
    each push's force at its start, none at its end."""
    return sorted([(round(p.start_s / dt_s), p.force_n) for p in pushes]
                  + [(round((p.start_s + p.duration_s) / dt_s), (0.0, 0.0, 0.0))
                     for p in pushes], key=lambda event: event[0])


def apply_pushes(sim: AtlasSimulator, events: list[tuple[int, Vector]], tick: int) -> None:
    """Set the pelvis force of the `events` (push_events) due at `tick`, taking them off the
    list: the simulator's /atlas/apply_pelvis_force input, as a live push."""
    while events and events[0][0] == tick:
        sim.apply_input(wrench_input(events.pop(0)[1], (0.0, 0.0, 0.0)))


def stand_trial(duration_s: float, pushes: Sequence[Push] = (),
                gains: StandGains | None = None) -> TrialResult:
    """Place the robot in the Stand pose on the ground and run Stand for `duration_s`
    (s) with `pushes`; stop early once the pelvis is below the standing height."""
    sim = standing_simulator()
    stand = TimedStand(sim.atlas, gains)
    sim.install_stand(stand)  # the simulator starts in Stand: it takes over at once
    assert stand.last_state is not None
    feet_start = stand.last_state.sole_centres[:, :2].copy()
    events = push_events(pushes, sim.dt_s)
    lowest, travel = np.inf, 0.0
    ground = GroundUnderFeet(sim.atlas, sim.data)
    steps = round(duration_s / sim.dt_s)
    for step in range(steps):
        apply_pushes(sim, events, step)
        sim.step()
        lowest = min(lowest, ground.clearance_m())
        travel = max(travel, float(np.max(np.linalg.norm(
            stand.last_state.sole_centres[:, :2] - feet_start, axis=1))))
        if not standing(lowest):
            return TrialResult(False, lowest, travel, step + 1, stand.spent_s)
    return TrialResult(travel <= FOOT_TRAVEL_LIMIT_M, lowest, travel, steps, stand.spent_s)


class TimedStand(StandBehaviour):
    """StandBehaviour adding up the time its steps take on `clock` (process time for the
    trials' CPU figure; the bench gives a wall clock)."""

    def __init__(self, atlas: AtlasModel, gains: StandGains | None = None,
                 clock: Callable[[], float] = time.process_time) -> None:
        super().__init__(atlas, gains)
        self.clock = clock
        self.spent_s = 0.0

    def torque(self, data: mujoco.MjData) -> np.ndarray:
        started = self.clock()
        torque = super().torque(data)
        self.spent_s += self.clock() - started
        return torque


def push_survived(direction_xy: tuple[float, float], impulse_ns: float,
                  gains: StandGains | None = None, settle_s: float = 1.0,
                  after_s: float = 2.5) -> TrialResult:
    """A PUSH_DURATION_S push of `impulse_ns` (N s) along the unit `direction_xy` after
    `settle_s` of standing; the robot must still stand `after_s` later."""
    force = impulse_ns / PUSH_DURATION_S
    push = Push(settle_s, (force * direction_xy[0], force * direction_xy[1], 0.0))
    return stand_trial(settle_s + PUSH_DURATION_S + after_s, [push], gains)
