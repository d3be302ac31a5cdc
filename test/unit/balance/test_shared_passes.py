"""A behaviour's step on shared passes (sim/shared_passes.py): mj_step1, the behaviour's
torque with the compiled estimate reading the step's own kinematics, centre of mass and
bias forces, mj_step2. Against mj_step whole with the estimate's own passes
(TAC_SHARED_PASSES=own) the robot moves bit for bit the same: a pushed Stand, a pushed walk,
a Stand pushed in the VRC course's mud (its drag computed between the halves too), every
tick's qpos and qvel; the shared path served every estimate of those ticks; runs repeat
exactly; outside the step the estimate computes its own passes."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import mujoco
import numpy as np
import pytest

from support.vrc_world import WORLD_PATH
from tutorial_atlas_control import native
from tutorial_atlas_control.balance import StandBehaviour
from tutorial_atlas_control.balance.compiled_estimator import CompiledEstimate
from tutorial_atlas_control.balance.push_trial import (
    Push,
    apply_pushes,
    push_events,
    standing_simulator,
)
from tutorial_atlas_control.course import parse_start
from tutorial_atlas_control.sim import SHARED_PASSES_ENV, load_model, passes_current
from tutorial_atlas_control.sim.controller import DEFAULT_GAINS_FILE, load_gains_yaml
from tutorial_atlas_control.sim.simulator import AtlasSimulator
from tutorial_atlas_control.walking import straight_steps
from tutorial_atlas_control.walking.walk_trial import SETTLE_S, WalkingStand

pytestmark = pytest.mark.skipif(native.load_library() is None,
                                reason='the compiled estimate is not built')

#: A start in the middle of the course's mud box (x y z yaw).
IN_MUD = '0.5 -16.6 0 1.5708'
#: A run: a simulator with its behaviour installed, and its pushes.
Setup = Callable[[], tuple[AtlasSimulator, list[Push]]]


@pytest.fixture
def stepped_calls(monkeypatch: pytest.MonkeyPatch) -> Iterator[list[int]]:
    """How many estimates read the step's passes (CompiledEstimate.run_stepped's calls)."""
    calls = [0]
    run_stepped = CompiledEstimate.run_stepped

    def counting(self: CompiledEstimate, address: int) -> object:
        calls[0] += 1
        return run_stepped(self, address)

    monkeypatch.setattr(CompiledEstimate, 'run_stepped', counting)
    yield calls


def _pushed_stand() -> tuple[AtlasSimulator, list[Push]]:
    sim = standing_simulator()
    sim.install_stand(StandBehaviour(sim.atlas))
    return sim, [Push(0.3, (160.0, 70.0, 0.0), 0.1)]


def _pushed_walk() -> tuple[AtlasSimulator, list[Push]]:
    sim = standing_simulator()
    sim.install_stand(WalkingStand(sim.atlas, straight_steps(3, 0.25), SETTLE_S))
    return sim, [Push(SETTLE_S + 0.9, (0.0, 120.0, 0.0), 0.1)]


def _stand_in_mud() -> tuple[AtlasSimulator, list[Push]]:
    sim = AtlasSimulator(load_model(WORLD_PATH), load_gains_yaml(DEFAULT_GAINS_FILE),
                         time_to_unpin_s=0.0, start=parse_start(IN_MUD))
    assert sim.mud is not None
    sim.install_stand(StandBehaviour(sim.atlas))
    return sim, [Push(0.2, (-120.0, 0.0, 0.0), 0.1)]


def _run(setup: Setup, ticks: int, monkeypatch: pytest.MonkeyPatch, shared: bool
         ) -> np.ndarray:
    """Every tick's (qpos, qvel), stepped with shared passes or with mj_step whole; in a
    world with mud, its drag acted on all but the first ticks (at rest: none)."""
    monkeypatch.setenv(SHARED_PASSES_ENV, '' if shared else 'own')
    sim, pushes = setup()
    assert sim.shares_passes is shared
    events = push_events(pushes, sim.dt_s)
    nq = sim.model.nq
    states = np.empty((ticks, nq + sim.model.nv))
    dragged = 0
    for tick in range(ticks):
        apply_pushes(sim, events, tick)
        sim.step()
        states[tick, :nq] = sim.data.qpos
        states[tick, nq:] = sim.data.qvel
        dragged += sim.mud is not None and bool(np.any(sim.mud.xfrc))
    assert sim.mud is None or dragged > ticks - 5
    return states


@pytest.mark.parametrize(('setup', 'ticks'), [
    (_pushed_stand, 1500), (_pushed_walk, round((SETTLE_S + 0.6 + 3 * 0.63 + 0.3) * 1000)),
    (_stand_in_mud, 800)], ids=['pushed_stand', 'pushed_walk', 'stand_in_mud'])
def test_the_shared_step_moves_the_robot_bit_for_bit_as_mj_step_whole(
        setup: Setup, ticks: int, monkeypatch: pytest.MonkeyPatch,
        stepped_calls: list[int]) -> None:
    own = _run(setup, ticks, monkeypatch, shared=False)
    assert stepped_calls[0] == 0
    shared = _run(setup, ticks, monkeypatch, shared=True)
    assert stepped_calls[0] >= ticks  # every tick's estimate read the step's passes
    assert float(np.max(np.abs(shared - own))) == 0.0
    assert np.isfinite(shared).all()


def test_a_shared_run_repeats_exactly(monkeypatch: pytest.MonkeyPatch) -> None:
    first = _run(_pushed_stand, 600, monkeypatch, shared=True)
    np.testing.assert_array_equal(_run(_pushed_stand, 600, monkeypatch, shared=True), first)


def test_outside_the_step_the_estimate_runs_its_own_passes(
        monkeypatch: pytest.MonkeyPatch, stepped_calls: list[int]) -> None:
    """Between steps MjData's poses are the last step's start's: never read as current."""
    monkeypatch.delenv(SHARED_PASSES_ENV, raising=False)
    sim, _ = _pushed_stand()
    for _ in range(50):
        sim.step()
    estimator = sim.behaviours.acting.estimator  # type: ignore[union-attr]
    assert not passes_current(sim.data)
    stepped_calls[0] = 0
    between = estimator.estimate_stepped(sim.data)
    assert stepped_calls[0] == 0
    own = estimator.estimate(sim.data.qpos, sim.data.qvel)
    np.testing.assert_array_equal(between.com, own.com)
    mujoco.mj_kinematics(sim.model, sim.data)  # the poses now at the present state
    np.testing.assert_array_equal(sim.data.xpos[sim.atlas.pelvis_body_id],
                                  own.pelvis_position)
