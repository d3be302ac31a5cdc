"""The compiled inverse statics (src/atlas_statics.c) agrees with the Python solver to 1e-9:
the contact wrenches and torques of every tick of a two-step walk, and of random states,
wrenches and constraints (either sole carrying, both, none; with and without torsion and
friction; the pressure centre on the whole sole or on a rectangle of it off its centre;
pulling and pushing wrenches)."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.balance.estimator import BalanceEstimator, BalanceState
from tutorial_atlas_control.balance.stand import WHOLE_BODY_ENV
from tutorial_atlas_control.balance.stand_pose import place_in_stand_pose
from tutorial_atlas_control.balance.whole_body import (
    ContactConstraint,
    WholeBodyLayer,
    WholeBodyOutput,
)
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.walking import straight_steps
from tutorial_atlas_control.walking.walk_trial import SETTLE_S, walk_trial

TOLERANCE = 1e-9
JOINTS = 28


@dataclasses.dataclass(frozen=True)
class FixedWrench:
    """A centroidal task asking for one given wrench."""

    force: tuple[float, float, float]
    moment: tuple[float, float, float]

    def wrench(self, state: BalanceState, mass_kg: float) -> tuple[Sequence[float],
                                                                    Sequence[float]]:
        return self.force, self.moment


def _difference(ours: WholeBodyOutput, theirs: WholeBodyOutput) -> float:
    return max(float(np.max(np.abs(ours.torque_nm - theirs.torque_nm))),
               float(np.max(np.abs(ours.contact_wrenches - theirs.contact_wrenches))))


def _rotation(rng: np.random.Generator) -> np.ndarray:
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def test_compiled_statics_agrees_with_python_on_random_cases(library) -> None:
    atlas = atlas_model.load_model()
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    base = BalanceEstimator(atlas).estimate(data.qpos, data.qvel)
    compiled = WholeBodyLayer(90.0, np.full(JOINTS, 200.0), compiled=True)
    python = WholeBodyLayer(90.0, np.full(JOINTS, 200.0), compiled=False)
    assert compiled.compiled and not python.compiled
    rng = np.random.default_rng(61)
    worst, clamped = 0.0, 0
    for case in range(400):
        state = dataclasses.replace(
            base, com=rng.normal(0.0, 0.3, 3) + [0.0, 0.0, 0.9],
            sole_centres=rng.normal(0.0, 0.15, (2, 3)),
            sole_rotations=np.array([_rotation(rng), _rotation(rng)]),
            bias_nm=rng.normal(0.0, 50.0, JOINTS),
            sole_jacobians=rng.normal(0.0, 0.5, (2, 6, JOINTS)))
        torsion = None if case % 3 == 0 else 0.01
        friction = None if case % 5 == 0 else float(rng.uniform(0.2, 1.0))
        carries = ((True, True), (True, False), (False, True), (False, False))[case % 4]
        centre = ((0.0, 0.0) if case % 2 == 0  # the sole's own, or a rectangle of it
                  else (float(rng.uniform(-0.08, 0.08)), float(rng.uniform(-0.04, 0.04))))
        contacts = tuple(ContactConstraint(c, 0.1, 0.05, torsion, friction, centre)
                         for c in carries)
        force = tuple(rng.normal(0.0, 200.0, 3) + [0.0, 0.0, 600.0 * (case % 7 != 0)])
        task = FixedWrench(force, tuple(rng.normal(0.0, 40.0, 3)))
        ours = compiled.solve(state, [task], contacts, (), np.zeros(JOINTS), np.zeros(JOINTS))
        theirs = python.solve(state, [task], contacts, (), np.zeros(JOINTS), np.zeros(JOINTS))
        worst = max(worst, _difference(ours, theirs))
        clamped += int(np.any(np.abs(theirs.contact_wrenches[:, 3:5]) > 0.0)
                       and any(carries))
    assert worst < TOLERANCE
    assert clamped > 100


def test_compiled_statics_agrees_with_python_through_a_walk(
        library, monkeypatch: pytest.MonkeyPatch) -> None:
    """Each tick's solve (its joint tasks left out: a swing servo keeps state) by both; the
    whole-body tick in Python, which calls the layer's solve (the compiled tick calls the C
    statics itself: test_compiled_whole_body.py)."""
    monkeypatch.setenv(WHOLE_BODY_ENV, 'python')
    solve = WholeBodyLayer.solve
    differences: list[float] = []
    carrying: set[tuple[bool, bool]] = set()

    def both(self: WholeBodyLayer, state: BalanceState, tasks, contacts, joint_tasks,
             positions: np.ndarray, velocities: np.ndarray) -> WholeBodyOutput:
        python = WholeBodyLayer(self.mass_kg, self.effort_limit_nm, self.solver,
                                compiled=False)
        ours = solve(self, state, tasks, contacts, (), positions, velocities)
        theirs = solve(python, state, tasks, contacts, (), positions, velocities)
        differences.append(_difference(ours, theirs))
        carrying.add((contacts[0].carries, contacts[1].carries))
        return solve(self, state, tasks, contacts, joint_tasks, positions, velocities)

    monkeypatch.setattr(WholeBodyLayer, 'solve', both)
    trial = walk_trial(straight_steps(2, 0.25), SETTLE_S + 0.6 + 2 * 0.63 + 0.2)
    assert not trial.fell and trial.steps == 2
    assert len(differences) > 3000
    assert max(differences) < TOLERANCE
    assert (True, True) in carrying and ((True, False) in carrying or (False, True) in carrying)
