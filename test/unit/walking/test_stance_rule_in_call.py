"""The walk's swinging tick as one C call reads the stance-sole rule (sole_support.stance_rule:
how near the lone stance sole's pressure centre stays to the one asked or its bearing box,
when the sole lies across facets) from the estimate's row itself, and its torques, pressure
centre and capture-point reference are those of the call with the rule loaded by Python's
stance_rule, bit for bit: at every 20th swinging tick of a pushed walk, with the stance
sole's summary in the row replaced by random ones (across facets or not, 1.0, -0.0, NaN,
boxes with infinities), then put back."""

from __future__ import annotations

import ctypes

import numpy as np
import pytest

from tutorial_atlas_control.balance import BalanceState
from tutorial_atlas_control.balance.compiled_estimator import BEARING_AT, BEARING_SIZE
from tutorial_atlas_control.walking import sole_support
from tutorial_atlas_control.walking.compiled_walk_swing import WALK_SWING_ENV, CompiledWalkSwing
from tutorial_atlas_control.walking.leg_tasks import LegTasks
from tutorial_atlas_control.walking.walk_trial import pushed_walk_trial

#: Swinging ticks between two checked ones, and random summaries tried at each.
EVERY_TICKS, CASES = 20, 6
ACROSS = (0.0, 1.0, -0.0, np.nan, 2.5)


def _summary(rng: np.random.Generator) -> list[float]:
    """A random bearing summary: across facets or not, then a box (along, across; m)."""
    box = sorted(rng.uniform(-0.12, 0.12, 2)) + sorted(rng.uniform(-0.07, 0.07, 2))
    if rng.random() < 0.2:
        box = [np.inf, -np.inf, np.inf, -np.inf]
    return [float(ACROSS[int(rng.integers(0, len(ACROSS)))]), *map(float, box)]


def test_the_rule_read_in_the_call_is_pythons(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(WALK_SWING_ENV, raising=False)
    rng = np.random.default_rng(61)
    states: list[BalanceState] = []
    load, tick = LegTasks.load_swing_tick, CompiledWalkSwing.tick
    checked = {'ticks': 0, 'across': 0, 'one plane': 0}

    def loading(self: LegTasks, state: BalanceState, *args: object) -> object:
        states[:] = [state]
        return load(self, state, *args)

    def both_ways(self: CompiledWalkSwing, elapsed_s: float, time_s: float) -> tuple:
        checked['ticks'] += 1
        if not self.rule_in_call or checked['ticks'] % EVERY_TICKS:
            return tick(self, elapsed_s, time_s)
        legs = self._legs._call
        row = self._legs._whole_body._call.row
        summary = np.ctypeslib.as_array((ctypes.c_double * BEARING_SIZE).from_address(
            row + 8 * (BEARING_AT + BEARING_SIZE * legs.stance)))
        kept = summary.copy()
        for _ in range(CASES):
            summary[:] = _summary(rng)
            in_call = [np.array(part, copy=True) for part in tick(self, elapsed_s, time_s)[:3]]
            near, span = sole_support.stance_rule(states[0], legs.stance,
                                                  self._tasks.gains.near_cop_m)
            legs.near_m, legs.bearing[:] = near, span
            self._call.rule_in_call = 0
            loaded = tick(self, elapsed_s, time_s)[:3]
            self._call.rule_in_call = 1
            for ours, theirs in zip(in_call, loaded, strict=True):
                assert ours.tobytes() == theirs.tobytes(), (time_s, summary.tolist())
            checked['across' if near > 0.0 else 'one plane'] += 1
        summary[:] = kept
        return tick(self, elapsed_s, time_s)

    monkeypatch.setattr(LegTasks, 'load_swing_tick', loading)
    monkeypatch.setattr(CompiledWalkSwing, 'tick', both_ways)
    trial, _ = pushed_walk_trial(5, steps=4, every_s=1.5)
    assert not trial.fell and trial.steps == 4
    assert checked['across'] > 100 and checked['one plane'] > 100
