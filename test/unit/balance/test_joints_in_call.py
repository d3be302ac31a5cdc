"""The compiled whole body reads a compiled estimate's joints itself (JOINTS_IN_CALL: from the
estimate's scratch qpos and qvel at the joints' addresses) with the very numbers of the copies
its callers made before: every tick's torque of a pushed Stand and of a pushed walk equal to
those of the same runs with the joints gathered in Python (joints_of) and copied in; a state
of the Python estimator refuses JOINTS_IN_CALL."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.balance import (
    JOINTS_IN_CALL,
    BalanceError,
    BalanceEstimator,
    StandController,
    joints_of,
)
from tutorial_atlas_control.balance.compiled_whole_body import CompiledWholeBody
from tutorial_atlas_control.balance.push_trial import Push, stand_trial
from tutorial_atlas_control.balance.stand import StandReference
from tutorial_atlas_control.balance.stand_behaviour import StandBehaviour
from tutorial_atlas_control.balance.stand_pose import place_in_stand_pose
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.walking.walk_behaviour import WalkBehaviour
from tutorial_atlas_control.walking.walk_trial import pushed_walk_trial

LOAD = CompiledWholeBody.load


def _runs(monkeypatch: pytest.MonkeyPatch, in_python: bool) -> tuple[np.ndarray, np.ndarray, int]:
    """Every Stand tick's torque of a pushed Stand, every Walk tick's of a pushed walk, and
    how many loads were given JOINTS_IN_CALL (read by C, or gathered by joints_of)."""
    asked = [0]

    def load(self: CompiledWholeBody, state: object, contacts: object, positions: np.ndarray,
             velocities: np.ndarray, *rest: object) -> None:
        if positions is JOINTS_IN_CALL:
            asked[0] += 1
            if in_python:
                positions, velocities = joints_of(state)  # type: ignore[arg-type]
        LOAD(self, state, contacts, positions, velocities, *rest)  # type: ignore[arg-type]

    torques: list[list[np.ndarray]] = [[], []]
    for kind, behaviour in enumerate((StandBehaviour, WalkBehaviour)):
        torque = behaviour.torque

        def recorded(self: object, data: mujoco.MjData, torque=torque, kind=kind) -> np.ndarray:
            result = torque(self, data)
            torques[kind].append(result.copy())
            return result

        monkeypatch.setattr(behaviour, 'torque', recorded)
    monkeypatch.setattr(CompiledWholeBody, 'load', load)
    assert stand_trial(1.5, [Push(0.3, (0.0, 450.0, 0.0), 0.1)]).stood
    stand_ticks = len(torques[0])
    trial, _ = pushed_walk_trial(3, steps=3, every_s=1.0)
    assert not trial.fell and trial.steps == 3
    return np.array(torques[0][:stand_ticks]), np.array(torques[1]), asked[0]


def test_the_joints_read_in_the_call_are_the_copies(monkeypatch: pytest.MonkeyPatch) -> None:
    stand, walk, asked = _runs(monkeypatch, in_python=False)
    with monkeypatch.context() as inner:
        python_stand, python_walk, python_asked = _runs(inner, in_python=True)
    assert asked == python_asked and asked > len(stand) + len(walk) // 2
    assert stand.tobytes() == python_stand.tobytes()
    assert walk.tobytes() == python_walk.tobytes()


def test_a_python_estimates_state_refuses_joints_in_call() -> None:
    atlas = atlas_model.load_model()
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    estimator = BalanceEstimator(atlas, compiled=False)
    state = estimator.estimate(data.qpos, data.qvel)
    controller = StandController(estimator.mass_kg, atlas.effort_limit_nm,
                                 StandReference.from_state(state), estimator.sole_half_size_m,
                                 compiled=True)
    with pytest.raises(BalanceError, match='JOINTS_IN_CALL for a state not of the compiled'):
        controller.tick(state, JOINTS_IN_CALL, JOINTS_IN_CALL)
