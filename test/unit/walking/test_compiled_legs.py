"""Walk's single-support tick of the legs as one C call (src/atlas_legs.c) agrees to 1e-9
with the same tick by LegTasks.torque and finish in Python (every part's Python: whole body,
statics, swing servo) and by the compiled pieces called from Python: every swing tick of a
two-step walk, and at states of that walk, random pressure centres, paths and times (before,
inside and after a path, either foot swinging, far outside the stance sole); every such tick
again with the stance sole taken as across facets (its wrench's pressure centre kept near the
one asked: walking/sole_support.py), where the torques differ from the plane's. So does the
pressure centre kept in the carrying soles' hull with no foot swinging (one C call): every
such tick of the walk, and random pressure centres on one sole or both."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.balance import JOINTS_IN_CALL, BalanceState, joints_of
from tutorial_atlas_control.balance.stand_behaviour import StandBehaviour
from tutorial_atlas_control.balance.stand_pose import place_in_stand_pose
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.walking import sole_support, straight_steps
from tutorial_atlas_control.walking.compiled_walk_swing import WALK_SWING_ENV
from tutorial_atlas_control.walking.footsteps import Footstep
from tutorial_atlas_control.walking.leg_tasks import LEGS_ENV, SWING_ENV, LegGains, LegTasks
from tutorial_atlas_control.walking.sole_support import SHIFT_M
from tutorial_atlas_control.walking.swing import SwingPath
from tutorial_atlas_control.walking.walk_trial import SETTLE_S, walk_trial

TOLERANCE = 1e-9
#: Random cases tried at every this many swing ticks.
EVERY_TICKS = 40
SWING_TICK = LegTasks.swing_tick
TORQUE = LegTasks.torque
STANCE_RULE = sole_support.stance_rule
#: Across facets (faked): the stance sole bears on its heel's rear 3 cm, across its width.
HEEL_SPAN = (-0.13, -0.10, -0.06, 0.06)
Tick = tuple[np.ndarray, np.ndarray, tuple[bool, bool]]


def _set_aside(legs: LegTasks, python: bool) -> Callable[[], None]:
    """The one call set aside (and, `python`, every compiled part: the Python reference);
    returns what puts them back."""
    stand = legs.stand
    saved = (legs._legs_kernel, legs._kernel, stand._kernel)
    legs._legs_kernel = None
    if python:
        legs._kernel = stand._kernel = None

    def restore() -> None:
        legs._legs_kernel, legs._kernel, stand._kernel = saved
    return restore


def _by(legs: LegTasks, python: bool, *args: object) -> Tick:
    restore = _set_aside(legs, python)
    try:
        return SWING_TICK(legs, *args)
    finally:
        restore()


def _difference(ours: Tick, theirs: Tick) -> float:
    assert ours[2] == theirs[2]
    return max(float(np.max(np.abs(ours[0] - theirs[0]))),
               float(np.max(np.abs(ours[1] - theirs[1]))))


def _compare(legs: LegTasks, *args: object) -> tuple[Tick, float, float]:
    """The one call's tick, and its differences from the pieces' and from Python's."""
    assert legs.compiled_swing_tick
    ours = SWING_TICK(legs, *args)
    return ours, _difference(ours, _by(legs, False, *args)), _difference(
        ours, _by(legs, True, *args))


def _random_cases(legs: LegTasks, state: BalanceState, positions: np.ndarray,
                  velocities: np.ndarray, time_s: float,
                  rng: np.random.Generator) -> list[float]:
    differences = []
    for case in range(4):
        foot = case % 2
        centre = state.sole_centres[foot]
        path = SwingPath(centre.copy(), centre + rng.normal(0.0, 0.2, 3),
                         math.pi - 0.1, -math.pi + float(rng.uniform(0.0, 0.3)),
                         float(rng.uniform(0.4, 0.8)))
        elapsed = float(rng.uniform(-0.1, 1.3)) * path.duration_s
        cop = state.sole_centres[1 - foot][0:2] + rng.normal(0.0, 0.15, 2)
        _, pieces, python = _compare(legs, state, positions, velocities,
                                     time_s + float(rng.uniform(0.0, 1.0)), cop,
                                     (foot, path, elapsed))
        differences += [pieces, python]
    return differences


def test_the_one_call_agrees_with_the_pieces_and_python_through_a_walk(
        library, monkeypatch: pytest.MonkeyPatch) -> None:
    for name in (LEGS_ENV, SWING_ENV):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv(WALK_SWING_ENV, 'python')  # the walk's swinging tick calls swing_tick
    walked: list[float] = []
    tried: list[float] = []
    largest: list[float] = []
    rng = np.random.default_rng(63)
    across: list[float] = []  # the ticks again across facets: their differences
    moved_by_rule: list[float] = []  # how much the rule changed those ticks' torques
    facets = [False]

    def stance_rule(state: BalanceState, stance: int, near_cop_m: float | None
                    ) -> tuple[float, sole_support.Span]:
        return (SHIFT_M, HEEL_SPAN) if facets[0] else STANCE_RULE(state, stance, near_cop_m)

    def both(self: LegTasks, state: BalanceState, positions: np.ndarray,
             velocities: np.ndarray, time_s: float, cop: np.ndarray,
             swing: tuple[int, SwingPath, float]) -> Tick:
        if positions is JOINTS_IN_CALL:  # the pieces and the Python need them as arrays
            positions, velocities = joints_of(state)
        ours, pieces, python = _compare(self, state, positions, velocities, time_s, cop, swing)
        walked.extend((pieces, python))
        facets[0] = True
        try:
            on_facets, *differences = _compare(self, state, positions, velocities, time_s,
                                               cop, swing)
        finally:
            facets[0] = False
        across.extend(differences)
        moved_by_rule.append(float(np.max(np.abs(on_facets[0] - ours[0]))))
        largest.append(float(np.max(np.abs(ours[0][4:16]))))
        if len(walked) % (2 * EVERY_TICKS) == 0:
            tried.extend(_random_cases(self, state, positions, velocities, time_s, rng))
        return ours

    def both_feet(self: LegTasks, state: BalanceState, positions: np.ndarray,
                  velocities: np.ndarray, time_s: float, cop: np.ndarray,
                  swing_foot: int | None) -> Tick:
        if positions is JOINTS_IN_CALL:
            positions, velocities = joints_of(state)
        ours = TORQUE(self, state, positions, velocities, time_s, cop, swing_foot)
        if swing_foot is not None:  # the pieces of a swinging tick, compared above
            return ours
        for python in (False, True):
            restore = _set_aside(self, python)
            try:
                theirs = TORQUE(self, state, positions, velocities, time_s, cop, None)
            finally:
                restore()
            supported.append(_difference(ours, theirs))
        for case in range(2 if len(supported) % 50 == 0 else 0):
            carrying = ((True, True), (True, False), (False, True))[case + len(supported) % 2]
            far = state.sole_centres[:, 0:2].mean(axis=0) + rng.normal(0.0, 0.2, 2)
            ours_far = self._support_clamp(state, carrying, far)
            restore = _set_aside(self, True)
            try:
                tried.append(float(np.max(np.abs(
                    ours_far - self._support_clamp(state, carrying, far)))))
            finally:
                restore()
        return ours

    def support_by_pieces(self: LegTasks, state: BalanceState, positions: np.ndarray,
                          velocities: np.ndarray, time_s: float, cop: np.ndarray,
                          feet: Sequence[Footstep]) -> Tick:
        if positions is JOINTS_IN_CALL:
            positions, velocities = joints_of(state)
        torque, kept, contact = self.torque(state, positions, velocities, time_s, cop, None)
        return self.finish(state, velocities, torque, contact, None, feet), kept, contact

    supported: list[float] = []
    monkeypatch.setattr(LegTasks, 'swing_tick', both)
    monkeypatch.setattr(sole_support, 'stance_rule', stance_rule)
    monkeypatch.setattr(LegTasks, 'torque', both_feet)
    monkeypatch.setattr(LegTasks, 'support_torque', support_by_pieces)  # its own test's
    trial = walk_trial(straight_steps(2, 0.25), SETTLE_S + 0.6 + 2 * 0.63 + 0.2)
    assert not trial.fell and trial.steps == 2
    assert len(walked) > 1500 and len(tried) > 200 and len(supported) > 1000
    assert max(supported) < TOLERANCE
    assert max(largest) > 20.0  # the legs' torques, not zeros compared
    assert max(walked) < TOLERANCE
    assert max(across) < TOLERANCE
    assert max(moved_by_rule) > 20.0  # across facets, other torques: the rule compared
    assert max(tried) < TOLERANCE


def test_the_one_call_is_chosen_by_its_switch_and_the_parts_it_runs(
        library, monkeypatch: pytest.MonkeyPatch) -> None:
    """TAC_LEGS=python, the swing servo in Python, or the Stand's whole body in Python each
    leave the swinging tick to the pieces."""
    atlas = atlas_model.load_model()
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    behaviour = StandBehaviour(atlas)
    behaviour.start(data)
    controller = behaviour.controller
    assert controller is not None and controller.compiled
    for name in (LEGS_ENV, SWING_ENV):
        monkeypatch.delenv(name, raising=False)
    assert LegTasks(controller, LegGains(), 0.0).compiled_swing_tick
    assert not LegTasks(controller, LegGains(), 0.0, compiled=False).compiled_swing_tick
    monkeypatch.setenv(SWING_ENV, 'python')
    assert not LegTasks(controller, LegGains(), 0.0).compiled_swing_tick
    monkeypatch.delenv(SWING_ENV)
    monkeypatch.setenv(LEGS_ENV, 'python')
    legs = LegTasks(controller, LegGains(), 0.0)
    assert legs.compiled and not legs.compiled_swing_tick
