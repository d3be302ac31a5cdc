"""One tick in its order: inputs, the step (behaviour and physics), the state, the
interface's end of step; a diverged physics recovered (state published), given up (nothing
after) or, without recovery, raised. The node's loop wires its parts in that order: the
AtlasSimInterface's state is built before its end_step, never after."""

from __future__ import annotations

from pathlib import Path

import pytest

from support.stepping_fakes import ALL_TOPICS, LAUNCH_RATES_HZ, FakeLog, FakeOutbox, stops_after
from tutorial_atlas_control import topics
from tutorial_atlas_control.asi import AtlasSimInterface
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.sim.controller_statistics import CommandAgeStatistics
from tutorial_atlas_control.sim.simulator import AtlasSimulator, PhysicsDivergenceError
from tutorial_atlas_control.stepping.inbox import CommandInbox
from tutorial_atlas_control.stepping.loop import LoopSettings, SteppingLoop
from tutorial_atlas_control.stepping.outputs import LoopOutputs
from tutorial_atlas_control.stepping.tick import Tick

CONFIG = Path(__file__).resolve().parents[3] / 'config' / 'atlas_controller.yaml'
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


def test_the_loop_builds_the_interface_state_before_its_end_of_step(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The node's loop: the controller, the step, the state (the AtlasSimInterface's among
    it), then the interface's end_step, once per step."""
    calls: list[str] = []
    state, end_step = AtlasSimInterface.state, AtlasSimInterface.end_step
    monkeypatch.setattr(AtlasSimInterface, 'state',
                        lambda self: (calls.append('state'), state(self))[1])
    monkeypatch.setattr(AtlasSimInterface, 'end_step',
                        lambda self: (calls.append('end_step'), end_step(self))[1])

    class Controller:
        def __init__(self, inbox: CommandInbox) -> None:
            self.inbox = inbox

        def before_step(self) -> None:
            calls.append('inputs')
            self.inbox.apply_pending()

    sim = AtlasSimulator(atlas_model.load_model(), load_gains_yaml(CONFIG))
    step = sim.step
    monkeypatch.setattr(sim, 'step', lambda: (calls.append('step'), step())[1])
    outlets = {topic: topic for topic in (*ALL_TOPICS, topics.ASI_STATE)}
    loop = SteppingLoop(sim, LoopOutputs(FakeOutbox({topics.ASI_STATE}), outlets, FakeLog(),
                                         lambda _text: None),
                        LoopSettings(LAUNCH_RATES_HZ), CommandAgeStatistics(sim.dt_s),
                        controller=Controller)
    loop.run(stops_after(3))
    assert calls == ['state'] + ONE_TICK * 3  # the state before the first step, then ticks
