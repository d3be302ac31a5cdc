"""The divergence check as the law kernel's one call (atlas_step_unsound) finds what the
Python check finds, in the same order: each of MuJoCo's unstable-step warnings (its counter
cleared), a state not finite in qpos or qvel, several at once, and nothing on a sound step."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.sim.divergence import DIVERGENCE_WARNINGS, DivergenceCheck
from tutorial_atlas_control.sim.simulator import AtlasSimulator, PhysicsDivergenceError

CONFIG = Path(__file__).resolve().parents[3] / 'config' / 'atlas_controller.yaml'
NAN, INF = float('nan'), float('inf')


@pytest.fixture(scope='module')
def sim() -> AtlasSimulator:
    sim = AtlasSimulator(atlas_model.load_model(), load_gains_yaml(CONFIG))
    assert sim.law.kernel is not None, 'the compiled library did not load'
    for _ in range(5):
        sim.step()
    return sim


def _finding(check: DivergenceCheck, sim: AtlasSimulator) -> tuple[str | None, list[int]]:
    """What `check` raises (None: nothing) and the warning counters after it."""
    try:
        check.check(1_234_000_000)
        message = None
    except PhysicsDivergenceError as err:
        message = str(err)
    return message, sim.data.warning.number.tolist()


def _unsound_cases(sim: AtlasSimulator) -> list[Callable[[], None]]:
    """Each way of setting the data's state or counters before a check."""
    data, atlas = sim.data, sim.atlas

    def warned(*warnings: int) -> Callable[[], None]:
        def set_counters() -> None:
            for warning in warnings:
                data.warning.number[warning] = 3
        return set_counters

    def state(array: str, index: int, value: float) -> Callable[[], None]:
        def set_value() -> None:
            getattr(data, array)[index] = value
        return set_value

    every = [w for w, _ in DIVERGENCE_WARNINGS]
    return [lambda: None, *(warned(w) for w in every), warned(every[2], every[0]),
            warned(*every[1:]), state('qpos', atlas.qpos_adr[5], NAN),
            state('qvel', atlas.dof_adr[27], -INF), state('qpos', 2, INF),
            state('qvel', len(data.qvel) - 1, NAN), warned(int(every[0]) - 1),
            lambda: (warned(every[1])(), state('qvel', 0, NAN)())]


def test_the_divergence_call_finds_what_the_python_check_finds(sim: AtlasSimulator) -> None:
    data = sim.data
    compiled = DivergenceCheck(data, sim.law.state_is_finite, sim.law.kernel)
    python = DivergenceCheck(data, sim.law.state_is_finite)
    qpos, qvel, counts = data.qpos.copy(), data.qvel.copy(), data.warning.number.copy()
    findings = []
    for case in _unsound_cases(sim):
        found = []
        for check in (compiled, python):
            data.qpos[:], data.qvel[:], data.warning.number[:] = qpos, qvel, counts
            case()
            found.append(_finding(check, sim))
        assert found[0] == found[1]
        findings.append(found[0][0])
    data.qpos[:], data.qvel[:], data.warning.number[:] = qpos, qvel, counts
    assert findings[0] is None and findings[-2] is None  # sound; a warning not checked
    assert sum(message is not None for message in findings) == len(findings) - 2
    assert 'at t=1.234 s (non-finite state)' in str(findings[-4])
