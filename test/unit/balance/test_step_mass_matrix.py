"""A stepped estimate copies the step's mass matrix into its scratch data (atlas_estimate_stepped)
and says so by its flag, so that Walk's legs skip mj_crb: at every tick of a pushed Stand the
scratch's mass matrix is mj_crb's at the estimate's state bit for bit, the flag set; an
estimate on its own passes clears it (the legs then run mj_crb)."""

from __future__ import annotations

import ctypes

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control import native
from tutorial_atlas_control.balance import StandBehaviour
from tutorial_atlas_control.balance.push_trial import (
    Push,
    apply_pushes,
    push_events,
    standing_simulator,
)

pytestmark = pytest.mark.skipif(native.load_library() is None,
                                reason='the compiled estimate is not built')


def _flag(estimator: object) -> int:
    source = estimator._mass_matrix_source  # type: ignore[attr-defined]
    return ctypes.c_long.from_address(source[4]).value


def test_a_stepped_estimate_holds_the_steps_mass_matrix_and_says_so() -> None:
    sim = standing_simulator()
    stand = StandBehaviour(sim.atlas)
    sim.install_stand(stand)
    estimator = stand.estimator
    torque = stand.torque
    checked = [0]

    def checking(data: mujoco.MjData) -> np.ndarray:
        result = torque(data)
        copied = estimator.scratch.M.copy()
        assert _flag(estimator) == 1
        mujoco.mj_crb(estimator.model, estimator.scratch)
        assert copied.tobytes() == estimator.scratch.M.tobytes(), data.time
        checked[0] += 1
        return result

    stand.torque = checking  # type: ignore[method-assign]
    events = push_events([Push(0.3, (150.0, -60.0, 0.0), 0.1)], sim.dt_s)
    for tick in range(800):
        apply_pushes(sim, events, tick)
        sim.step()
    assert checked[0] >= 790
    estimator.estimate(sim.data.qpos, sim.data.qvel)
    assert _flag(estimator) == 0
