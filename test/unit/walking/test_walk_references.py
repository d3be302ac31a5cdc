"""Walk's capture-point reference with both feet down in plain floats (the sway's
capture_point_after, the catch's midpoint of the soles): at every tick of a pushed walk
the very bits of numpy's arithmetic it replaced (capture_point_after on arrays, the soles'
centres' mean)."""

from __future__ import annotations

import numpy as np
import pytest

from tutorial_atlas_control.balance import BalanceState, capture_point_after
from tutorial_atlas_control.walking import walk as walk_module
from tutorial_atlas_control.walking.walk import WalkController
from tutorial_atlas_control.walking.walk_trial import pushed_walk_trial


def _same_bits(first: np.ndarray, second: np.ndarray) -> bool:
    return first.tobytes() == np.asarray(second, dtype=np.float64).tobytes()


def _numpy_reference(walk: WalkController, state: BalanceState,
                     time_s: float) -> tuple[np.ndarray, np.ndarray]:
    """_capture_reference as it was computed on arrays."""
    elapsed = walk.phases.elapsed_s(time_s)
    if walk.phases.phase is walk_module.WALK_PHASES[0]:
        start = np.array(walk._sway_xy[0:2])  # the capture point as the sway began
        return (capture_point_after(start, walk._sway_cop, state.omega,
                                    min(elapsed, walk.gains.sway_s)), walk._sway_cop)
    if walk._plan is not None and walk.phases.phase is walk_module.WALK_PHASES[1]:
        return walk._plan.reference(0, elapsed)
    middle = state.sole_centres[:, :2].mean(axis=0)
    return middle, middle


def test_the_walks_reference_in_floats_is_numpys_bit_for_bit(
        monkeypatch: pytest.MonkeyPatch) -> None:
    reference = WalkController._capture_reference
    seen = {'sway': 0, 'swing': 0, 'catch': 0}

    def checked(self: WalkController, state: BalanceState,
                time_s: float) -> tuple[np.ndarray, np.ndarray]:
        xi_ref, cop_ref = reference(self, state, time_s)
        xi_numpy, cop_numpy = _numpy_reference(self, state, time_s)
        assert _same_bits(xi_ref, xi_numpy) and _same_bits(cop_ref, cop_numpy), time_s
        assert _same_bits(walk_module._feet_middle(state),
                          state.sole_centres[:, :2].mean(axis=0))
        seen[self.phases.phase.name] += 1
        return xi_ref, cop_ref

    monkeypatch.setattr(WalkController, '_capture_reference', checked)
    trial, _ = pushed_walk_trial(3, steps=2, every_s=1.0)
    assert not trial.fell and trial.steps == 2
    assert seen['sway'] > 500 and seen['catch'] > 500 and seen['swing'] > 0
