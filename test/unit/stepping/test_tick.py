"""One tick in its order: inputs, the step (behaviour and physics), the state, the
interface's end of step; a diverged physics recovered (state published), given up (nothing
after) or, without recovery, raised."""

from __future__ import annotations

import pytest

from tutorial_atlas_control.sim.simulator import PhysicsDivergenceError
from tutorial_atlas_control.stepping.tick import Tick

ONE_TICK = ['inputs', 'step', 'state', 'end_step']


class FakeSim:
    """Steps by noting it; its first `diverging` steps diverge."""

    def __init__(self, calls: list[str], diverging: int = 0) -> None:
        self.calls, self.diverging = calls, diverging

    def step(self) -> None:
        self.calls.append('step')
        if self.diverging:
            self.diverging -= 1
            raise PhysicsDivergenceError('physics diverged at t=0.001 s')


class FakeController:
    def __init__(self, calls: list[str]) -> None:
        self.calls = calls

    def before_step(self) -> None:
        self.calls.append('inputs')


def make_tick(calls: list[str], diverging: int = 0, recover: object = None) -> Tick:
    return Tick(FakeSim(calls, diverging), FakeController(calls),  # type: ignore[arg-type]
                lambda: calls.append('state'), lambda: calls.append('end_step'),
                recover)  # type: ignore[arg-type]


def test_a_tick_takes_inputs_steps_publishes_and_ends_the_step_in_that_order() -> None:
    calls: list[str] = []
    tick = make_tick(calls)
    assert tick() and tick()
    assert calls == ONE_TICK * 2


def test_without_an_end_of_step_the_tick_stops_at_the_state() -> None:
    calls: list[str] = []
    tick = Tick(FakeSim(calls), FakeController(calls),  # type: ignore[arg-type]
                lambda: calls.append('state'))
    assert tick()
    assert calls == ['inputs', 'step', 'state']


def test_a_recovered_divergence_publishes_the_reset_state_and_ends_the_step() -> None:
    calls: list[str] = []
    errors: list[str] = []
    tick = make_tick(calls, diverging=1,
                     recover=lambda err: (errors.append(str(err)), calls.append('recover'))
                     and True)
    assert tick()
    assert calls == ['inputs', 'step', 'recover', 'state', 'end_step']
    assert errors == ['physics diverged at t=0.001 s']


def test_a_divergence_given_up_ends_the_tick_with_nothing_after() -> None:
    calls: list[str] = []
    tick = make_tick(calls, diverging=1, recover=lambda _err: False)
    assert not tick()
    assert calls == ['inputs', 'step']


def test_without_recovery_a_divergence_propagates() -> None:
    calls: list[str] = []
    tick = make_tick(calls, diverging=1)
    with pytest.raises(PhysicsDivergenceError):
        tick()
    assert calls == ['inputs', 'step']
