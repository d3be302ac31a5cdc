"""The compiled whole-body tick (src/atlas_whole_body.c) agrees with StandController's Python
to 1e-9: every tick of a pushed Stand (its pressure centre clamped into the support polygon)
and every whole-body solve of a two-step walk (single support with torsion, Walk's own joint
gains and moving reference), and random states: standing, one sole, none, a pressure centre
far outside the polygon, a region shrunk to a point, user joint gains, moving references."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control import native
from tutorial_atlas_control.balance import JOINTS_IN_CALL, joints_of, support
from tutorial_atlas_control.balance.estimator import BalanceEstimator, BalanceState, _within
from tutorial_atlas_control.balance.push_trial import (
    Push,
    apply_pushes,
    push_events,
    stand_trial,
    standing_simulator,
)
from tutorial_atlas_control.balance.stand import (
    WHOLE_BODY_ENV,
    StandController,
    StandGains,
    StandOutput,
    StandReference,
    pelvis_frame,
)
from tutorial_atlas_control.balance.stand_behaviour import StandBehaviour
from tutorial_atlas_control.balance.stand_pose import place_in_stand_pose
from tutorial_atlas_control.balance.whole_body import QP, STATICS_ENV
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.walking import straight_steps
from tutorial_atlas_control.walking.leg_tasks import LEGS_ENV
from tutorial_atlas_control.walking.walk_trial import SETTLE_S, walk_trial

TOLERANCE = 1e-9
JOINTS = 28
SOLE_HALF_SIZE_M = (0.13, 0.0624435)
TICK = StandController.tick
WHOLE_BODY = StandController.whole_body


def _difference(ours: StandOutput, theirs: StandOutput) -> float:
    return max(float(np.max(np.abs(np.asarray(mine) - np.asarray(reference))))
               for mine, reference in zip(dataclasses.astuple(ours),
                                          dataclasses.astuple(theirs), strict=True))


def _in_python(controller: StandController, method, *args: object) -> StandOutput:
    """`method(controller, ...)` by the Python reference (the same controller, its kernel
    set aside)."""
    kernel = controller._kernel
    controller._kernel = None
    try:
        return method(controller, *args)
    finally:
        controller._kernel = kernel


def _outside(state: BalanceState, controller: StandController) -> bool:
    """Whether the capture-point law's pressure centre lies outside the shrunk polygon."""
    region = controller.support_region(state)
    if region is None or len(region.vertices) < 3:
        return False
    reference = controller.reference.capture_point
    law = reference + (1.0 + controller.gains.capture_gain) * (state.capture_point - reference)
    return support.signed_distance(np.array(region.vertices), law) < -1e-6


def test_compiled_stand_tick_agrees_with_python_through_a_push(
        library, monkeypatch: pytest.MonkeyPatch) -> None:
    """Each tick of a Stand pushed hard enough that the law's pressure centre leaves the
    polygon (and is clamped), compared with the Python tick on the same state."""
    monkeypatch.delenv(WHOLE_BODY_ENV, raising=False)
    differences: list[float] = []
    clamped = 0

    def both(self: StandController, state: BalanceState, positions: np.ndarray,
             velocities: np.ndarray) -> StandOutput:
        nonlocal clamped
        assert self.compiled
        ours = TICK(self, state, positions, velocities)  # JOINTS_IN_CALL: read by C
        theirs = _in_python(self, TICK, state, *_joints(state, positions, velocities))
        differences.append(_difference(ours, theirs))
        clamped += _outside(state, self)
        return ours

    monkeypatch.setattr(StandController, 'tick', both)
    result = stand_trial(1.5, [Push(0.3, (0.0, 450.0, 0.0), 0.1)])
    assert result.stood
    assert len(differences) == 1500
    assert max(differences) < TOLERANCE
    assert clamped > 20


def _joints(state: BalanceState, positions: np.ndarray,
            velocities: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The joints a Python path needs: JOINTS_IN_CALL's (the state's, as Python reads them)."""
    return joints_of(state) if positions is JOINTS_IN_CALL else (positions, velocities)


def test_compiled_whole_body_agrees_with_python_through_a_walk(
        library, monkeypatch: pytest.MonkeyPatch) -> None:
    """Walk's whole-body solves (one sole with its yaw moment limited, Walk's joint gains,
    its moving reference) by both."""
    differences: list[float] = []
    torsions: set[float | None] = set()

    def both(self: StandController, *args: object) -> StandOutput:
        assert self.compiled
        ours = WHOLE_BODY(self, *args)
        state, cop, contact, positions, velocities, *rest = args
        theirs = _in_python(self, WHOLE_BODY, state, cop, contact,
                            *_joints(state, positions, velocities), *rest)  # type: ignore[arg-type]
        differences.append(_difference(ours, theirs))
        torsions.add(args[6] if len(args) > 6 else None)
        return ours

    monkeypatch.setenv(LEGS_ENV, 'python')  # the pieces, not the one call around them
    monkeypatch.setattr(StandController, 'whole_body', both)
    trial = walk_trial(straight_steps(2, 0.25), SETTLE_S + 0.6 + 2 * 0.63 + 0.2)
    assert not trial.fell and trial.steps == 2
    assert len(differences) > 1000
    assert max(differences) < TOLERANCE
    assert None in torsions and len(torsions) == 2


def _moved(base: BalanceState, rng: np.random.Generator, case: int) -> BalanceState:
    """`base` with its motion, pelvis frame and capture point moved; every third case on
    one sole or none."""
    contact = ((True, True), (True, False), (False, False))[case % 3]
    polygon = (base.support_polygon, base.support_polygon * [1.0, 0.5], np.zeros((0, 2)))[
        case % 3]
    return dataclasses.replace(
        base, com=base.com + rng.normal(0.0, 0.03, 3),
        com_velocity=rng.normal(0.0, 0.3, 3),
        pelvis_rotation=pelvis_frame(float(rng.normal(0.0, 0.3)), float(rng.normal(0.0, 0.1))),
        pelvis_angular_velocity=rng.normal(0.0, 0.5, 3),
        capture_point=base.com[:2] + rng.normal(0.0, 0.15, 2),
        omega=float(base.omega + rng.normal(0.0, 0.1)), in_contact=contact,
        polygon_of=lambda: polygon)


def test_compiled_stand_agrees_with_python_on_random_states(library) -> None:
    atlas = atlas_model.load_model()
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    estimator = BalanceEstimator(atlas)
    base = estimator.estimate(data.qpos, data.qvel)
    rng = np.random.default_rng(61)
    worst, outside, points = 0.0, 0, 0
    for case in range(120):
        reference = dataclasses.replace(
            StandReference.from_state(base), com_height_rate_m_s=float(rng.normal(0.0, 0.1)),
            pelvis_angular_velocity=rng.normal(0.0, 0.2, 3),
            posture_rate_rad_s=rng.normal(0.0, 0.2, JOINTS))
        margin = 0.2 if case % 7 == 0 else 0.015  # a margin swallowing the polygon: a point
        gains = StandGains(cop_margin_m=margin, capture_gain=float(rng.uniform(0.0, 2.0)))
        controllers = [StandController(estimator.mass_kg, atlas.effort_limit_nm, reference,
                                       SOLE_HALF_SIZE_M, gains, compiled=compiled)
                       for compiled in (True, False)]
        assert controllers[0].compiled and not controllers[1].compiled
        state = _moved(base, rng, case)
        positions = data.qpos[atlas.qpos_adr] + rng.normal(0.0, 0.05, JOINTS)
        velocities = rng.normal(0.0, 0.5, JOINTS)
        ours, theirs = (c.tick(state, positions, velocities) for c in controllers)
        worst = max(worst, _difference(ours, theirs))
        outside += _outside(state, controllers[1])
        region = controllers[1].support_region(state)
        points += region is not None and len(region.vertices) == 1
        user = (rng.uniform(0.0, 500.0, JOINTS), rng.uniform(0.0, 5.0, JOINTS))
        cop = rng.normal(0.0, 0.2, 2)
        args = (state, cop, state.in_contact, positions, velocities, user,
                0.015 if case % 2 else None)
        ours, theirs = (c.whole_body(*args) for c in controllers)
        worst = max(worst, _difference(ours, theirs))
    assert worst < TOLERANCE
    assert outside > 20 and points > 5


def test_a_moved_reference_is_written_over_the_compiled_copy_and_taken_back(library) -> None:
    """Walk's legs move the reference's heading, height and rate every tick (`moved`), which
    the C call writes over its copy of the reference; a call without `moved` (Stand's tick,
    or whole_body after a walk) must see the reference's own values again, and a new
    reference must replace the moved one. Each call of a mixed sequence against Python's
    (stand.moved_reference)."""
    atlas = atlas_model.load_model()
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    estimator = BalanceEstimator(atlas)
    base = estimator.estimate(data.qpos, data.qvel)
    rng = np.random.default_rng(62)
    references = [dataclasses.replace(StandReference.from_state(base),
                                      com_height_m=float(base.com[2] + rng.normal(0.0, 0.03)))
                  for _ in range(2)]
    controllers = [StandController(estimator.mass_kg, atlas.effort_limit_nm, references[0],
                                   SOLE_HALF_SIZE_M, compiled=compiled)
                   for compiled in (True, False)]
    worst, moved, kinds = 0.0, None, set()
    for case in range(200):
        state = _moved(base, rng, case)
        positions = data.qpos[atlas.qpos_adr] + rng.normal(0.0, 0.05, JOINTS)
        velocities = rng.normal(0.0, 0.5, JOINTS)
        kind = int(rng.integers(4))  # tick; whole_body: new moved, the same moved, none
        kinds.add(kind)
        if kind == 0:
            ours, theirs = (c.tick(state, positions, velocities) for c in controllers)
        else:
            if kind == 1 or moved is None:
                moved = (float(rng.normal(0.0, 0.5)), float(base.com[2] + rng.normal(0.0, 0.05)),
                         float(rng.normal(0.0, 0.1)))
            reference, cop = references[case % 7 == 0], rng.normal(0.0, 0.1, 2)
            ours, theirs = (c.whole_body(state, cop, state.in_contact,
                                         positions, velocities, None, 0.015, reference,
                                         None if kind == 3 else moved)
                            for c in controllers)
        worst = max(worst, _difference(ours, theirs))
    assert kinds == {0, 1, 2, 3}
    assert worst < TOLERANCE


def _pushed_stand_qpos(seconds: float) -> np.ndarray:
    """The robot's qpos after `seconds` of compiled Stand, pushed sideways at 0.2 s."""
    sim = standing_simulator()
    stand = StandBehaviour(sim.atlas)
    sim.install_stand(stand)
    events = push_events([Push(0.2, (0.0, 450.0, 0.0), 0.1)], sim.dt_s)
    for step in range(round(seconds / sim.dt_s)):
        apply_pushes(sim, events, step)
        sim.step()
    assert stand.controller is not None and stand.controller.compiled
    return sim.data.qpos.copy()


def test_compiled_stand_and_walk_runs_are_deterministic(
        library, monkeypatch: pytest.MonkeyPatch) -> None:
    """Two offline runs of the compiled Stand end in the same state, bit for bit; two
    walks end with the pelvis at the same bits, their landings and torque jumps the same."""
    monkeypatch.delenv(WHOLE_BODY_ENV, raising=False)
    first, second = _pushed_stand_qpos(0.6), _pushed_stand_qpos(0.6)
    assert first.tobytes() == second.tobytes()
    walks = [walk_trial(straight_steps(2, 0.25), SETTLE_S + 0.6 + 2 * 0.63 + 0.2)
             for _ in range(2)]
    assert walks[0].steps == 2
    assert walks[0].pelvis_end.tobytes() == walks[1].pelvis_end.tobytes()
    assert walks[0].landings == walks[1].landings
    assert walks[0].leg_torque_jump_nm == walks[1].leg_torque_jump_nm


@pytest.mark.parametrize(('variable', 'gains', 'compiled'), [
    (None, StandGains(), True), (WHOLE_BODY_ENV, StandGains(), False),
    (STATICS_ENV, StandGains(), False), (None, StandGains(solver=QP), False)])
def test_the_python_tick_is_chosen_by_its_switches_and_the_qp(
        library, monkeypatch: pytest.MonkeyPatch, variable: str | None, gains: StandGains,
        compiled: bool) -> None:
    """TAC_WHOLE_BODY=python, TAC_STATICS=python (the C tick calls the C statics) and the
    QP solver (Python only) each choose the Python tick."""
    for name in (WHOLE_BODY_ENV, STATICS_ENV):
        monkeypatch.delenv(name, raising=False)
    if variable is not None:
        monkeypatch.setenv(variable, 'python')
    reference = StandReference(np.zeros(2), 0.85, np.eye(3))
    controller = StandController(90.0, np.full(JOINTS, 100.0), reference, SOLE_HALF_SIZE_M,
                                 gains)
    assert controller.compiled is compiled


def test_the_polygon_cache_s_moved_test_answers_as_numpy_s() -> None:
    """The estimator keeps its support polygon while the soles moved less than a tolerance:
    its plain-float test answers as float(np.max(np.abs(d))) < tolerance, NaN and inf too."""
    rng = np.random.default_rng(61)
    answers = set()
    for case in range(4000):
        difference = rng.normal(0.0, 5e-4, (2, 3) if case % 2 else (2, 3, 3))
        if case % 5 == 0:
            difference.flat[rng.integers(difference.size)] = (np.nan, np.inf, -np.inf,
                                                              5e-4, -5e-4)[case % 25 // 5]
        expected = float(np.max(np.abs(difference))) < 5e-4
        assert _within(difference, 5e-4) is expected
        answers.add(expected)
    assert answers == {True, False}


def test_without_the_library_the_python_tick_runs_after_one_warning(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setattr(native, '_library', None)
    monkeypatch.setattr(native, '_warned', False)
    monkeypatch.setenv(native.LIBRARY_ENV, str(tmp_path / 'missing.so'))
    reference = StandReference(np.zeros(2), 0.85, np.eye(3))
    with pytest.warns(RuntimeWarning, match='statics and whole-body tick$') as caught:
        controllers = [StandController(90.0, np.full(JOINTS, 100.0), reference,
                                       SOLE_HALF_SIZE_M) for _ in range(2)]
    assert len(caught) == 1
    assert not any(controller.compiled for controller in controllers)
