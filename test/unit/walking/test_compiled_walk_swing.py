"""The walk's tick with a foot in the air as one C call (src/atlas_walk_swing.c: the capture
point's reference, the step adjustment, the law's pressure centre, the legs' one call)
agrees with the Python bit for bit (held to 1e-9): a pushed walk's every tick, its landings
moved by the adjustment; and, at states of a walk, random plans, landings and times (before
the step, in it, past its end; one step left or more), against the Python's pieces."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np
import pytest

from tutorial_atlas_control.balance import BalanceState, dcm_feedback_cop
from tutorial_atlas_control.walking.compiled_walk_swing import WALK_SWING_ENV, CompiledWalkSwing
from tutorial_atlas_control.walking.dcm_plan import DcmPlan
from tutorial_atlas_control.walking.walk import WalkController
from tutorial_atlas_control.walking.walk_behaviour import WalkBehaviour
from tutorial_atlas_control.walking.walk_trial import pushed_walk_trial

TOLERANCE = 1e-9
#: Random cases tried at every this many compiled swing ticks.
EVERY_TICKS = 60
Tick = tuple[np.ndarray, np.ndarray, np.ndarray, tuple[float, float]]
#: What a swinging tick changes in the walk and its queue.
SAVED = ('step', 'swing', '_plan', '_planned_step', '_last_cop')


def _recorded_walk(monkeypatch: pytest.MonkeyPatch, python: bool) -> tuple[np.ndarray, int]:
    """A pushed 6-step walk's torques, tick by tick, and how many landings the compiled
    call moved."""
    if python:
        monkeypatch.setenv(WALK_SWING_ENV, 'python')
    else:
        monkeypatch.delenv(WALK_SWING_ENV, raising=False)
    torques: list[np.ndarray] = []
    moved = [0]
    torque, tick = WalkBehaviour.torque, CompiledWalkSwing.tick

    def recorded(self: WalkBehaviour, data: object) -> np.ndarray:
        result = torque(self, data)
        torques.append(result.copy())
        return result

    def counted(self: CompiledWalkSwing, elapsed_s: float, time_s: float) -> tuple:
        result = tick(self, elapsed_s, time_s)
        moved[0] += result[3] is not None
        return result

    monkeypatch.setattr(WalkBehaviour, 'torque', recorded)
    monkeypatch.setattr(CompiledWalkSwing, 'tick', counted)
    trial, _ = pushed_walk_trial(3, steps=6, every_s=1.5)
    assert not trial.fell and trial.steps == 6
    return np.array(torques), moved[0]


def test_the_walk_swing_call_walks_a_pushed_walk_as_the_python_does(
        monkeypatch: pytest.MonkeyPatch) -> None:
    compiled, moved = _recorded_walk(monkeypatch, python=False)
    python, none_moved = _recorded_walk(monkeypatch, python=True)
    assert moved > 0 and none_moved == 0  # the pushes moved landings, in the call
    assert compiled.shape == python.shape
    worst = float(np.max(np.abs(compiled - python)))
    assert worst <= TOLERANCE, f'worst torque difference {worst:.3g} N m'


def _python_swing(walk: WalkController, state: BalanceState, positions: np.ndarray,
                  velocities: np.ndarray, time_s: float) -> Tick:
    """tick_torque's swinging tick in Python: its reference, _adjust, the law, the legs."""
    xi_ref, cop_ref = walk._capture_reference(state, time_s)
    walk._adjust(state, xi_ref, cop_ref, time_s)
    cop = dcm_feedback_cop(state.capture_point, xi_ref, walk.gains.dcm_gain, cop_ref)
    step, swing, lift_off = walk.step, walk.swing, walk._lift_off_s
    assert step is not None and swing is not None and lift_off is not None
    torque, cop, _ = walk.legs.swing_tick(state, positions, velocities, time_s, cop,
                                          (step.foot_index, swing,
                                           walk.phases.elapsed_s(time_s) - lift_off))
    return torque, cop, xi_ref, (step.x_m, step.y_m)


def _compiled_swing(walk: WalkController, state: BalanceState, positions: np.ndarray,
                    velocities: np.ndarray, time_s: float) -> Tick:
    kernel = walk._kernel
    assert kernel is not None
    output = walk._compiled_swing(kernel, state, positions, velocities, time_s)
    assert output is not None and walk.step is not None
    return output.torque_nm, output.desired_cop, output.capture_point_ref, (walk.step.x_m,
                                                                           walk.step.y_m)


def _perturbed(walk: WalkController, rng: np.random.Generator, case: int) -> None:
    """The walk's plan, landing as planned and so far moved to random ones."""
    plan, planned = walk._plan, walk._planned_step
    assert plan is not None and planned is not None
    stages = 1 if case % 3 == 0 else len(plan.cops)
    walk._plan = DcmPlan.plan(plan.cops[:stages] + rng.normal(0.0, 0.08, (stages, 2)),
                              plan.durations_s[:stages] * rng.uniform(0.7, 1.3, stages),
                              plan.ends[stages - 1] + rng.normal(0.0, 0.08, 2), plan.omega)
    walk._planned_step = dataclasses.replace(
        planned, x_m=planned.x_m + float(rng.uniform(-0.4, 0.4)),
        y_m=planned.y_m + float(rng.uniform(-0.3, 0.3)))
    walk.step = dataclasses.replace(walk._planned_step,
                                    x_m=walk._planned_step.x_m + float(rng.normal(0.0, 0.01)))


def _random_cases(walk: WalkController, state: BalanceState, positions: np.ndarray,
                  velocities: np.ndarray, time_s: float, rng: np.random.Generator) -> float:
    """The worst difference over random cases at this state; the walk left as it was."""
    saved = [getattr(walk, name) for name in SAVED]
    queue = (walk.queue._adjusted, walk.queue._preview)
    worst = 0.0
    for case in range(6):
        _perturbed(walk, rng, case)
        start = [getattr(walk, name) for name in SAVED]
        at = time_s + float(rng.uniform(-0.4, 0.5))
        theirs = _python_swing(walk, state, positions, velocities, at)
        for name, value in zip(SAVED, start, strict=True):
            setattr(walk, name, value)
        ours = _compiled_swing(walk, state, positions, velocities, at)
        worst = max([worst, *(float(np.max(np.abs(np.subtract(a, b))))
                              for a, b in zip(ours, theirs, strict=True))])
    for name, value in zip(SAVED, saved, strict=True):
        setattr(walk, name, value)
    walk.queue._adjusted, walk.queue._preview = queue
    return worst


def test_the_walk_swing_call_agrees_with_the_python_on_random_steps(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(WALK_SWING_ENV, raising=False)
    rng = np.random.default_rng(61)
    worst, ticks, tried = [0.0], [0], [0]
    real: Callable = WalkController._compiled_swing

    def with_cases(self: WalkController, kernel: CompiledWalkSwing, state: BalanceState,
                   positions: np.ndarray, velocities: np.ndarray, time_s: float) -> object:
        ticks[0] += 1
        if ticks[0] % EVERY_TICKS == 0:
            worst[0] = max(worst[0], _random_cases(self, state, positions, velocities, time_s,
                                                   rng))
            tried[0] += 1
        return real(self, kernel, state, positions, velocities, time_s)

    monkeypatch.setattr(WalkController, '_compiled_swing', with_cases)
    trial, _ = pushed_walk_trial(None, steps=4)
    assert not trial.fell and tried[0] >= 8
    assert worst[0] <= TOLERANCE, f'worst difference {worst[0]:.3g}'
