"""A walking trial's leg torque jumps (walk_trial.WalkingStand: each leg joint's mean
|change| per 1 ms tick, the largest) are summed a block of ticks at a time: the same figure,
bit for bit, as adding each tick's changes in place, across block boundaries."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.walking.leg_tasks import LEG_JOINTS

#: The module (the package exports a function of its name).
walk_trial = importlib.import_module('tutorial_atlas_control.walking.walk_trial')


def _in_place(torques: np.ndarray) -> float:
    """The figure as the trial made it tick by tick: the changes added in place."""
    sums = np.zeros(LEG_JOINTS.stop - LEG_JOINTS.start)
    for last, now in zip(torques[:-1, LEG_JOINTS], torques[1:, LEG_JOINTS]):
        np.add(sums, np.abs(now - last), out=sums)
    return float(np.max(sums)) / (len(torques) - 1)


@pytest.mark.parametrize('ticks', [1, 2, 7, 8, 9, 30])
def test_the_torque_jumps_summed_by_blocks_are_those_summed_tick_by_tick(
        monkeypatch: pytest.MonkeyPatch, ticks: int) -> None:
    monkeypatch.setattr(walk_trial, 'JUMP_BLOCK_TICKS', 7)
    stand = walk_trial.WalkingStand(atlas_model.load_model(), [], 1.0)
    torques = np.random.default_rng(ticks).normal(0.0, 80.0, (ticks, 28))
    for torque in torques:
        stand._note_jump(torque)
    stand.note_jumps()
    expected = _in_place(torques) if ticks > 1 else 0.0
    assert stand.trial.leg_torque_jump_nm == expected
    assert ticks < 2 or expected > 10.0  # changes of normal(0, 80) torques, not zeros
