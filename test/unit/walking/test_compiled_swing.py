"""The compiled swing servo (src/atlas_swing.c) agrees with LegTasks' Python to 1e-9: every
swing tick of a two-step walk, and at states of that walk, random targets and paths (joint
or world damping, with and without an acceleration fed forward, before, inside and after a
path's time, turns across the heading's wrap, soles upright and tilted onto slopes)."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.balance import BalanceState
from tutorial_atlas_control.balance.stand_behaviour import StandBehaviour
from tutorial_atlas_control.balance.stand_pose import place_in_stand_pose
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.walking import straight_steps
from tutorial_atlas_control.walking.leg_tasks import LEGS_ENV, SWING_ENV, LegGains, LegTasks
from tutorial_atlas_control.walking.swing import SwingPath
from tutorial_atlas_control.walking.walk_trial import SETTLE_S, walk_trial

TOLERANCE = 1e-9
#: Random cases tried at every this many swing ticks.
EVERY_TICKS = 25
#: The methods compared (the test replaces LegTasks.swing_torque while a walk runs).
METHODS = {'foot_servo': LegTasks.foot_servo, 'swing_torque': LegTasks.swing_torque}


def _compiled(legs: LegTasks, method: str, *args: object, **kwargs: object) -> np.ndarray:
    assert legs.compiled
    return METHODS[method](legs, *args, **kwargs)


def _in_python(legs: LegTasks, method: str, *args: object, **kwargs: object) -> np.ndarray:
    """`legs.method(...)` by the Python reference (the same LegTasks, its kernel set aside)."""
    kernel = legs._kernel
    legs._kernel = None
    try:
        return METHODS[method](legs, *args, **kwargs)
    finally:
        legs._kernel = kernel


def _random_cases(legs: LegTasks, state: BalanceState, velocities: np.ndarray,
                  rng: np.random.Generator) -> list[float]:
    """The differences of random servo targets and swing paths at `state`."""
    differences = []
    for case in range(8):
        foot = case % 2
        centre = state.sole_centres[foot]
        position = centre + rng.normal(0.0, 0.05, 3)
        yaw = float(rng.uniform(-math.pi, math.pi))
        acceleration = None if case % 4 < 2 else rng.normal(0.0, 3.0, 3)
        args = (state, velocities, foot, position, rng.normal(0.0, 0.5, 3), yaw,
                float(rng.normal(0.0, 0.5)), acceleration, float(rng.normal(0.0, 2.0)))
        world = bool(case % 3)
        tilted = case % 2 == 1  # half the cases on a slope of up to about 20 degrees
        tilt = tuple(rng.normal(0.0, 0.2, 2).tolist()) if tilted else (0.0, 0.0)
        ours = _compiled(legs, 'foot_servo', *args, world=world, tilt=tilt)
        differences.append(float(np.max(np.abs(
            ours - _in_python(legs, 'foot_servo', *args, world=world, tilt=tilt)))))
        # A path ending across the heading's wrap, at a time before, in or after it, from
        # one surface's tilt to another's.
        end_tilt = tuple(rng.normal(0.0, 0.2, 2).tolist()) if tilted else (0.0, 0.0)
        path = SwingPath(centre.copy(), centre + rng.normal(0.0, 0.2, 3),
                         math.pi - 0.1, -math.pi + float(rng.uniform(0.0, 0.3)),
                         float(rng.uniform(0.4, 0.8)), start_tilt=tilt, end_tilt=end_tilt)
        elapsed = float(rng.uniform(-0.1, 1.3)) * path.duration_s
        ours = _compiled(legs, 'swing_torque', state, velocities, foot, path, elapsed)
        differences.append(float(np.max(np.abs(
            ours - _in_python(legs, 'swing_torque', state, velocities, foot, path,
                              elapsed)))))
    return differences


def test_compiled_swing_agrees_with_python_through_a_walk(
        library, monkeypatch: pytest.MonkeyPatch) -> None:
    walked: list[float] = []
    tried: list[float] = []
    largest: list[float] = []
    rng = np.random.default_rng(61)

    def both(self: LegTasks, state: BalanceState, velocities: np.ndarray, foot: int,
             swing: SwingPath, elapsed_s: float) -> np.ndarray:
        ours = _compiled(self, 'swing_torque', state, velocities, foot, swing, elapsed_s)
        theirs = _in_python(self, 'swing_torque', state, velocities, foot, swing, elapsed_s)
        walked.append(float(np.max(np.abs(ours - theirs))))
        largest.append(float(np.max(np.abs(theirs))))
        if len(walked) % EVERY_TICKS == 0:
            tried.extend(_random_cases(self, state, velocities, rng))
        return ours

    monkeypatch.setenv(LEGS_ENV, 'python')  # the pieces, not the one call around them
    monkeypatch.setattr(LegTasks, 'swing_torque', both)
    trial = walk_trial(straight_steps(2, 0.25), SETTLE_S + 0.6 + 2 * 0.63 + 0.2)
    assert not trial.fell and trial.steps == 2
    assert len(walked) > 1000 and len(tried) > 500
    assert max(largest) > 5.0  # the swing leg's torques, not zeros compared
    assert max(walked) < TOLERANCE
    assert max(tried) < TOLERANCE


def test_the_python_swing_is_chosen_by_the_environment(
        library, monkeypatch: pytest.MonkeyPatch) -> None:
    atlas = atlas_model.load_model()
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    behaviour = StandBehaviour(atlas)
    behaviour.start(data)
    assert behaviour.controller is not None
    monkeypatch.delenv(SWING_ENV, raising=False)
    assert LegTasks(behaviour.controller, LegGains(), 0.0).compiled
    monkeypatch.setenv(SWING_ENV, 'python')
    assert not LegTasks(behaviour.controller, LegGains(), 0.0).compiled
    assert LegTasks(behaviour.controller, LegGains(), 0.0, compiled=True).compiled
