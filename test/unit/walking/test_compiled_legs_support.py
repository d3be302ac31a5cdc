"""Walk's tick of the legs with no foot swinging as one C call (src/atlas_legs.c's support
tick: the pressure centre kept in the carrying soles' shrunk hull, the whole body, each foot
that is not flat down put back on its pose, the effort limits) agrees with LegTasks.torque
then finish called in pieces bit for bit (held to 1e-9): a pushed walk's every tick against
the pieces' walk, and at its ticks with both feet meant down, random poses for the feet
(raised, lowered, turned, on tilted surfaces) and random pressure centres."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pytest

from tutorial_atlas_control.balance import JOINTS_IN_CALL, BalanceState, joints_of
from tutorial_atlas_control.walking.footsteps import Footstep
from tutorial_atlas_control.walking.leg_tasks import LEGS_ENV, LegTasks
from tutorial_atlas_control.walking.walk_behaviour import WalkBehaviour
from tutorial_atlas_control.walking.walk_trial import pushed_walk_trial

TOLERANCE = 1e-9
#: Random cases tried at every this many ticks with no foot swinging.
EVERY_TICKS = 25
SUPPORT = LegTasks.support_torque
Tick = tuple[np.ndarray, np.ndarray, tuple[bool, bool]]


def _walk_torques(monkeypatch: pytest.MonkeyPatch, pieces: bool) -> np.ndarray:
    if pieces:
        monkeypatch.setenv(LEGS_ENV, 'python')
    else:
        monkeypatch.delenv(LEGS_ENV, raising=False)
    torques: list[np.ndarray] = []
    torque = WalkBehaviour.torque

    def recorded(self: WalkBehaviour, data: object) -> np.ndarray:
        result = torque(self, data)
        torques.append(result.copy())
        return result

    monkeypatch.setattr(WalkBehaviour, 'torque', recorded)
    trial, _ = pushed_walk_trial(5, steps=4, every_s=1.2)
    assert not trial.fell and trial.steps == 4
    return np.array(torques)


def test_the_support_call_walks_a_pushed_walk_as_the_pieces_do(
        monkeypatch: pytest.MonkeyPatch) -> None:
    compiled = _walk_torques(monkeypatch, pieces=False)
    pieces = _walk_torques(monkeypatch, pieces=True)
    assert compiled.shape == pieces.shape
    worst = float(np.max(np.abs(compiled - pieces)))
    assert worst <= TOLERANCE, f'worst torque difference {worst:.3g} N m'


def _by_pieces(legs: LegTasks, state: BalanceState, positions: np.ndarray,
               velocities: np.ndarray, time_s: float, cop: np.ndarray,
               feet: Sequence[Footstep]) -> Tick:
    torque, kept, contact = legs.torque(state, positions, velocities, time_s, cop, None)
    return legs.finish(state, velocities, torque, contact, None, feet), kept, contact


def _random_feet(state: BalanceState, rng: np.random.Generator) -> tuple[Footstep, Footstep]:
    """Poses near where the soles are: raised or lowered up to 2 cm, moved, turned, some on
    a tilted surface (up to 0.15 rad)."""
    feet = []
    for foot in (0, 1):
        centre = state.sole_centres[foot]
        tilt = float(rng.uniform(0.0, 0.15)) if rng.random() < 0.5 else 0.0
        heading = float(rng.uniform(-math.pi, math.pi))
        normal = (math.sin(tilt) * math.cos(heading), math.sin(tilt) * math.sin(heading),
                  math.cos(tilt))
        feet.append(Footstep(0, foot, float(centre[0] + rng.normal(0.0, 0.03)),
                             float(centre[1] + rng.normal(0.0, 0.03)),
                             float(rng.uniform(-0.5, 0.5)),
                             z_m=float(centre[2] + rng.uniform(-0.02, 0.02)), normal=normal))
    return feet[0], feet[1]


def test_the_support_call_agrees_with_the_pieces_on_random_feet(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(LEGS_ENV, raising=False)
    rng = np.random.default_rng(62)
    walked: list[float] = []
    tried: list[float] = []
    put_down = [0]
    finish = LegTasks.finish

    def counted(self: LegTasks, state: BalanceState, velocities: np.ndarray,
                torque: np.ndarray, contact: tuple[bool, bool], swing: object,
                feet: Sequence[Footstep]) -> np.ndarray:
        put_down[0] += sum(not contact[foot] or not self.flat_down(state, foot, feet[foot])
                           for foot in (0, 1)) if swing is None else 0
        return finish(self, state, velocities, torque, contact, swing, feet)

    def both(self: LegTasks, state: BalanceState, positions: np.ndarray,
             velocities: np.ndarray, time_s: float, cop: np.ndarray,
             feet: Sequence[Footstep]) -> Tick:
        ours = SUPPORT(self, state, positions, velocities, time_s, cop, feet)  # C reads them
        if positions is JOINTS_IN_CALL:  # the pieces need them as arrays
            positions, velocities = joints_of(state)
        assert ours[2] == _by_pieces(self, state, positions, velocities, time_s, cop, feet)[2]
        walked.append(_difference(ours, _by_pieces(self, state, positions, velocities,
                                                   time_s, cop, feet)))
        if len(walked) % EVERY_TICKS == 0:
            for _ in range(4):
                poses = _random_feet(state, rng)
                far = cop + rng.normal(0.0, 0.1, 2)
                mine = SUPPORT(self, state, positions, velocities, time_s, far, poses)
                tried.append(_difference(mine, _by_pieces(self, state, positions, velocities,
                                                          time_s, far, poses)))
        return ours

    monkeypatch.setattr(LegTasks, 'support_torque', both)
    monkeypatch.setattr(LegTasks, 'finish', counted)
    trial, _ = pushed_walk_trial(None, steps=2)
    assert not trial.fell
    assert len(walked) > 800 and len(tried) > 100 and put_down[0] > 50
    assert max(walked) <= TOLERANCE, f'walk: {max(walked):.3g}'
    assert max(tried) <= TOLERANCE, f'random feet: {max(tried):.3g}'


def _difference(ours: Tick, theirs: Tick) -> float:
    assert ours[2] == theirs[2]
    return max(float(np.max(np.abs(ours[0] - theirs[0]))),
               float(np.max(np.abs(ours[1] - theirs[1]))))

