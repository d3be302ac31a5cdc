"""The compiled whole-body tick reads a compiled estimate's state from the estimate's row in
place, and any other state (made by dataclasses.replace, or by the Python estimator) by
copying its fields: both give the Python tick's torques, and one controller switching
between them never reads a row that is not the state's."""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.balance.estimator import BalanceEstimator, BalanceState
from tutorial_atlas_control.balance.stand import (
    WHOLE_BODY_ENV,
    StandController,
    StandOutput,
    StandReference,
)
from tutorial_atlas_control.balance.stand_pose import place_in_stand_pose
from tutorial_atlas_control.sim import model as atlas_model

SOLE_HALF_SIZE_M = (0.13, 0.0624435)
#: The compiled tick against the Python one (test_compiled_whole_body.py's bound).
TOLERANCE = 1e-9


def _outputs_equal(ours: StandOutput, theirs: StandOutput) -> bool:
    return all(np.array_equal(np.asarray(mine), np.asarray(reference))
               for mine, reference in zip(dataclasses.astuple(ours),
                                          dataclasses.astuple(theirs), strict=True))


def _difference(ours: StandOutput, theirs: StandOutput) -> float:
    return max(float(np.max(np.abs(np.asarray(mine) - np.asarray(reference))))
               for mine, reference in zip(dataclasses.astuple(ours),
                                          dataclasses.astuple(theirs), strict=True))


def _python_tick(controller: StandController, state: BalanceState, positions: np.ndarray,
                 velocities: np.ndarray) -> StandOutput:
    kernel, controller._kernel = controller._kernel, None
    try:
        return controller.tick(state, positions, velocities)
    finally:
        controller._kernel = kernel


def test_states_read_in_place_and_copied_give_the_python_torques(
        library, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(WHOLE_BODY_ENV, raising=False)
    atlas = atlas_model.load_model()
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    estimator = BalanceEstimator(atlas, compiled=True)
    assert estimator.compiled
    rng = np.random.default_rng(8)
    base = estimator.estimate(data.qpos, data.qvel)
    controller = StandController(estimator.mass_kg, atlas.effort_limit_nm,
                                 StandReference.from_state(base), SOLE_HALF_SIZE_M)
    assert controller.compiled
    positions = data.qpos[atlas.qpos_adr]
    for case in range(12):
        qvel = data.qvel.copy()
        qvel[:] = rng.normal(0.0, 0.2, len(qvel))
        in_place = estimator.estimate(data.qpos, qvel)
        assert in_place.row_address is not None
        # The same numbers in a state of its own (no row): copied, the same bits.
        copied = dataclasses.replace(in_place)
        assert copied.row_address is None
        velocities = qvel[atlas.dof_adr]
        by_row = controller.tick(in_place, positions, velocities)
        by_copy = controller.tick(copied, positions, velocities)
        assert _outputs_equal(by_row, by_copy)
        python = _python_tick(controller, in_place, positions, velocities)
        assert _difference(by_row, python) < TOLERANCE
        # Changed numbers right after a row was read: the state's own, not the last row's.
        moved = dataclasses.replace(in_place, com=in_place.com + rng.normal(0.0, 0.02, 3),
                                    capture_point=in_place.capture_point + 0.01 * case)
        ours = controller.tick(moved, positions, velocities)
        assert _difference(ours, _python_tick(controller, moved, positions, velocities)) \
            < TOLERANCE
        assert not np.array_equal(ours.torque_nm, by_row.torque_nm)
