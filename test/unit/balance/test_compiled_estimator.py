"""The compiled estimate (src/atlas_estimator.c) agrees with the Python reference to 1e-9 on
every field of BalanceState, tick by tick through a walking trial: standing, single support,
touchdowns, a swing foot in the air, and the robot lifted clear of the ground; and with the
pendulum's ground moved (a walk on a slope), omega that of the CoM's height over it."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from tutorial_atlas_control import native
from tutorial_atlas_control.balance import compiled_estimator
from tutorial_atlas_control.balance.estimator import BalanceEstimator, BalanceState
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.walking import straight_steps
from tutorial_atlas_control.walking.leg_tasks import LEG_JOINTS
from tutorial_atlas_control.walking.walk_trial import SETTLE_S, walk_trial

TOLERANCE = 1e-9
#: Arrays of BalanceState compared number by number (the rest: in_contact, omega, contacts).
ARRAY_FIELDS = [f.name for f in dataclasses.fields(BalanceState)
                if f.name not in ('in_contact', 'omega', 'joint_inertia', 'polygon_of',
                                  'contacts_of')]


@pytest.fixture(scope='module')
def atlas() -> atlas_model.AtlasModel:
    return atlas_model.load_model()


@pytest.fixture(scope='module')
def every_walking_tick() -> list[tuple[np.ndarray, np.ndarray]]:
    """(qpos, qvel) of every estimate of a two-step walk (Python estimator)."""
    recorded: list[tuple[np.ndarray, np.ndarray]] = []
    estimate = BalanceEstimator.estimate

    def recording(self: BalanceEstimator, qpos: np.ndarray, qvel: np.ndarray) -> BalanceState:
        recorded.append((qpos.copy(), qvel.copy()))
        return estimate(self, qpos, qvel)

    with pytest.MonkeyPatch.context() as patch:
        patch.setenv('TAC_ESTIMATOR', 'python')
        patch.setattr(BalanceEstimator, 'estimate', recording)
        trial = walk_trial(straight_steps(2, 0.25), SETTLE_S + 0.6 + 2 * 0.63 + 0.2)
    assert not trial.fell and trial.steps == 2
    return recorded


@pytest.fixture(scope='module')
def walking_ticks(atlas: atlas_model.AtlasModel,
                  every_walking_tick: list[tuple[np.ndarray, np.ndarray]]
                  ) -> list[tuple[np.ndarray, np.ndarray]]:
    """Every third estimate of the walk, and its last tick lifted 0.1 m: no sole touches."""
    recorded = every_walking_tick
    lifted = recorded[-1][0].copy()
    lifted[atlas.free_qpos_adr + 2] += 0.1
    return [*recorded[::3], (lifted, recorded[-1][1])]


def _worst(compiled: BalanceState, python: BalanceState) -> float:
    """The largest difference between two states' numbers; their contact flags, contact
    counts and surfaces must be equal."""
    assert compiled.in_contact == python.in_contact
    worst = abs(compiled.omega - python.omega)
    for name in ARRAY_FIELDS:
        ours, theirs = getattr(compiled, name), getattr(python, name)
        assert ours.shape == theirs.shape, name
        worst = max(worst, float(np.max(np.abs(ours - theirs))))
    for ours, theirs in zip(compiled.sole_contacts, python.sole_contacts, strict=True):
        assert ours.surface_geoms.tolist() == theirs.surface_geoms.tolist()
        for name in ('points', 'normals', 'distances_m'):
            difference = np.abs(getattr(ours, name) - getattr(theirs, name))
            worst = max(worst, float(np.max(difference, initial=0.0)))
    polygons = compiled.support_polygon, python.support_polygon
    assert polygons[0].shape == polygons[1].shape
    worst = max(worst, float(np.max(np.abs(polygons[0] - polygons[1]), initial=0.0)))
    inertia = compiled.joint_inertia(LEG_JOINTS), python.joint_inertia(LEG_JOINTS)
    return max(worst, float(np.max(np.abs(inertia[0] - inertia[1]))))


def _compare(atlas: atlas_model.AtlasModel,
             ticks: list[tuple[np.ndarray, np.ndarray]],
             ground_m: float = 0.0) -> tuple[float, set]:
    """The worst difference over `ticks` with the pendulum's ground at `ground_m`, and the
    contact cases they covered."""
    compiled, python = BalanceEstimator(atlas, compiled=True), BalanceEstimator(atlas,
                                                                                compiled=False)
    assert compiled.compiled and not python.compiled
    compiled.ground_m = python.ground_m = ground_m
    worst, cases, previous = 0.0, set(), None
    for qpos, qvel in ticks:
        ours, theirs = compiled.estimate(qpos, qvel), python.estimate(qpos, qvel)
        worst = max(worst, _worst(ours, theirs))
        cases.add(theirs.in_contact)
        if previous is not None and sum(theirs.in_contact) > sum(previous):
            cases.add('touchdown')
        previous = theirs.in_contact
    return worst, cases


def test_compiled_estimate_agrees_with_python_through_a_walk(
        library, atlas: atlas_model.AtlasModel,
        walking_ticks: list[tuple[np.ndarray, np.ndarray]]) -> None:
    worst, cases = _compare(atlas, walking_ticks)
    assert worst < TOLERANCE
    assert {(True, True), (False, False), 'touchdown'} <= cases
    assert (True, False) in cases or (False, True) in cases


def test_the_pendulum_over_a_moved_ground_agrees_and_is_its_height_over_it(
        library, atlas: atlas_model.AtlasModel,
        walking_ticks: list[tuple[np.ndarray, np.ndarray]]) -> None:
    worst, _ = _compare(atlas, walking_ticks[::10], ground_m=-0.4)
    assert worst < TOLERANCE
    for compiled in (True, False):
        estimator = BalanceEstimator(atlas, compiled=compiled)
        qpos, qvel = walking_ticks[0]
        level = estimator.estimate(qpos, qvel)
        estimator.ground_m = -0.4  # the feet 0.4 m down a slope: the CoM 0.4 m higher over them
        lowered = estimator.estimate(qpos, qvel)
        assert lowered.omega == pytest.approx(9.81 ** 0.5 / (level.com[2] + 0.4) ** 0.5,
                                              rel=1e-3)
        assert lowered.omega < 0.85 * level.omega


def test_contact_rows_beyond_the_flat_output_are_fetched_whole(
        library, atlas: atlas_model.AtlasModel,
        walking_ticks: list[tuple[np.ndarray, np.ndarray]],
        monkeypatch: pytest.MonkeyPatch) -> None:
    """With room for one row in the flat output, standing's eight come by the second call."""
    monkeypatch.setattr(compiled_estimator, 'CONTACT_CAPACITY', 1)
    standing = walking_ticks[:50]
    worst, cases = _compare(atlas, standing)
    assert worst < TOLERANCE and cases == {(True, True)}


def test_python_estimator_chosen_by_the_environment(
        library, atlas: atlas_model.AtlasModel, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv('TAC_ESTIMATOR', 'python')
    assert not BalanceEstimator(atlas).compiled
    monkeypatch.delenv('TAC_ESTIMATOR')
    assert BalanceEstimator(atlas).compiled


def test_one_mujoco_in_the_process(library, atlas: atlas_model.AtlasModel) -> None:
    """The library's MuJoCo is the bindings' (a second copy would own other globals: its
    own plugin table, warning counters and allocator)."""
    BalanceEstimator(atlas, compiled=True)
    with open('/proc/self/maps', encoding='utf-8') as maps:
        loaded = {line.split()[-1] for line in maps if 'libmujoco.so' in line}
    assert len(loaded) == 1, loaded


def test_without_the_library_the_python_estimate_runs_after_one_warning(
        atlas: atlas_model.AtlasModel, monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setattr(native, '_library', None)
    monkeypatch.setattr(native, '_warned', False)
    monkeypatch.setenv(native.LIBRARY_ENV, str(tmp_path / 'missing.so'))
    with pytest.warns(RuntimeWarning, match='statics and whole-body tick$') as caught:
        estimators = [BalanceEstimator(atlas) for _ in range(2)]
    assert len(caught) == 1
    assert not any(estimator.compiled for estimator in estimators)


def _polygons(estimator: BalanceEstimator, ticks: list[tuple[np.ndarray, np.ndarray]],
              asked: list[int]) -> list[tuple[bytes, tuple[int, ...], bool]]:
    """Each asked tick's support polygon (its bytes and shape) and whether it is the very
    array handed over before it; every tick is estimated, only `asked` ones asked."""
    found, last = [], None
    asked_ticks = set(asked)
    for index, (qpos, qvel) in enumerate(ticks):
        state = estimator.estimate(qpos, qvel)
        if index in asked_ticks:
            polygon = state.support_polygon
            found.append((polygon.tobytes(), polygon.shape, polygon is last))
            last = polygon
    return found


@pytest.mark.parametrize('stride', [1, 7])
def test_compiled_support_polygon_is_python_s_bit_for_bit(
        library, atlas: atlas_model.AtlasModel,
        every_walking_tick: list[tuple[np.ndarray, np.ndarray]], stride: int) -> None:
    """The same vertices in the same order, kept and remade at the same ticks, through a
    walk whose feet move past the tolerance: asked every tick, and every seventh only
    (the cache's reference then moves only at asked ticks, in both)."""
    asked = list(range(0, len(every_walking_tick), stride))
    compiled = _polygons(BalanceEstimator(atlas, compiled=True), every_walking_tick, asked)
    python = _polygons(BalanceEstimator(atlas, compiled=False), every_walking_tick, asked)
    assert compiled == python
    remade = sum(not kept for _, _, kept in python)
    assert 10 < remade < len(asked) - 10
    assert {shape for _, shape, _ in python} >= {(4, 2), (6, 2)}


@pytest.mark.parametrize('later', [1, 700])
def test_a_state_asked_after_a_later_one_gets_python_s_polygon(
        library, atlas: atlas_model.AtlasModel,
        every_walking_tick: list[tuple[np.ndarray, np.ndarray]], later: int) -> None:
    """Two estimates (a tick apart: the feet still; a step apart: moved), the later's
    polygon asked first: the earlier one's is then tested against the later's, as in
    Python (the same array while the feet stayed)."""
    early, late = every_walking_tick[0], every_walking_tick[later]
    found = []
    for compiled in (True, False):
        estimator = BalanceEstimator(atlas, compiled=compiled)
        first, second = estimator.estimate(*early), estimator.estimate(*late)
        polygons = second.support_polygon, first.support_polygon
        found.append([p.tobytes() for p in polygons] + [polygons[1] is polygons[0]])
    assert found[0] == found[1]
    assert found[0][2] == (later == 1)
