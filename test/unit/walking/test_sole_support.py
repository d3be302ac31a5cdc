"""A lone stance sole across facets (walking/sole_support.py), on the Atlas model placed in
DRCSim's Stand pose with its contacts given: on one plane (the floor, or up on one edge of
it, or beside a bend with the other plane a few millimetres off) the Stand's constraint as
it was; across two facets the wrench's pressure centre stays within SHIFT_M of the one
asked or of the corners the sole bears on, however much moment the pelvis task asks for,
where on a plane that moment takes it to the sole's edge."""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.balance.estimator import BalanceState, SoleContacts
from tutorial_atlas_control.balance.stand_behaviour import StandBehaviour
from tutorial_atlas_control.balance.stand_pose import place_in_stand_pose
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.walking.leg_tasks import LegGains, LegTasks
from tutorial_atlas_control.walking.sole_support import (
    NO_SPAN,
    SHIFT_M,
    across_facets,
    bearing_span,
)

LEFT, RIGHT = 0, 1
UP = (0.0, 0.0, 1.0)
#: A facet 8 degrees off the floor, falling to the sole's right.
FACET = (0.0, -math.sin(math.radians(8.0)), math.cos(math.radians(8.0)))
#: A wall's side, 89 degrees from up, facing the sole's left.
SIDE = (0.0, -math.sin(math.radians(89.0)), math.cos(math.radians(89.0)))
CORNERS = [(x, y) for x in (-0.13, 0.13) for y in (-0.0624, 0.0624)]


@pytest.fixture(scope='module')
def standing() -> tuple[StandBehaviour, BalanceState]:
    atlas = atlas_model.load_model()
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    behaviour = StandBehaviour(atlas)
    behaviour.start(data)
    return behaviour, behaviour.estimator.estimate(data.qpos, data.qvel)


def _touching(state: BalanceState, normals: list[tuple[float, float, float]],
              pitch_rad: float = 0.0, gaps: tuple[float, ...] = (-0.0005,) * 4
              ) -> BalanceState:
    """`state` with the right sole's corners touching surfaces of `normals` (one each) at
    `gaps` (m), the left sole's the floor, and the pelvis pitched `pitch_rad` forward."""
    rows = []
    for sole, faces, gap in ((LEFT, [UP] * 4, (-0.0005,) * 4), (RIGHT, normals, gaps)):
        centre, rotation = state.sole_centres[sole], state.sole_rotations[sole]
        rows.append(SoleContacts(
            np.array([centre + rotation[:, 0] * x + rotation[:, 1] * y for x, y in CORNERS]),
            np.array(faces), np.array(gap), np.zeros(4, dtype=int)))
    cos, sin = math.cos(pitch_rad), math.sin(pitch_rad)
    pitched = np.array([[cos, 0.0, sin], [0.0, 1.0, 0.0], [-sin, 0.0, cos]])
    return dataclasses.replace(state, contacts_of=lambda: (rows[0], rows[1]),
                               pelvis_rotation=pitched @ state.pelvis_rotation)


def _stance_shift(behaviour: StandBehaviour, state: BalanceState) -> np.ndarray:
    """How far (m; along, across the sole) the right stance sole's wrench's pressure centre
    is from the one asked (its centre) while the left foot swings."""
    assert behaviour.controller is not None
    legs = LegTasks(behaviour.controller, LegGains(near_cop_m=SHIFT_M), 0.0)
    centre, rotation = state.sole_centres[RIGHT], state.sole_rotations[RIGHT]
    captured = {}
    whole_body = behaviour.controller.whole_body

    def kept(*args: object, **kwargs: object) -> object:
        captured['out'] = output = whole_body(*args, **kwargs)  # type: ignore[arg-type]
        return output

    behaviour.controller.whole_body = kept  # type: ignore[method-assign]
    try:
        legs.torque(state, np.zeros(28), np.zeros(28), 0.0, centre[0:2].copy(), LEFT)
    finally:
        del behaviour.controller.whole_body
    wrench = captured['out'].contact_wrenches[RIGHT]
    force, moment = rotation.T @ wrench[0:3], rotation.T @ wrench[3:6]
    return np.array([-moment[1], moment[0]]) / force[2]


def test_a_sole_on_one_plane_is_on_one_plane(
        standing: tuple[StandBehaviour, BalanceState]) -> None:
    _, state = standing
    assert not across_facets(_touching(state, [UP] * 4), RIGHT)
    tilted = (0.0, math.sin(0.03), math.cos(0.03))  # 1.7 degrees: one plane, rounded
    assert not across_facets(_touching(state, [UP, tilted, UP, tilted]), RIGHT)
    assert across_facets(_touching(state, [UP, FACET, UP, FACET]), RIGHT)
    # beside a bend: the other plane within the estimator's reach, 5 mm off, bears nothing
    assert not across_facets(_touching(state, [UP, FACET, UP, FACET],
                                       gaps=(-0.0005, 0.005, -0.0005, 0.005)), RIGHT)
    # beside a wall (a heightfield prism's side, a block's): it bears nothing either
    assert not across_facets(_touching(state, [UP, UP, UP, SIDE]), RIGHT)


#: The corners' gaps (m; CORNERS' order: heel right, heel left, toe right, toe left) of a
#: sole bearing on its heel (the toe 5 mm up), on its toe, and on all four.
ON_HEEL = (-0.0005, -0.0005, 0.005, 0.005)
ON_TOE = (0.005, 0.005, -0.0005, -0.0005)
ON_ALL = (-0.0005,) * 4


def test_the_pelvis_moment_moves_a_stance_pressure_centre_across_facets_little(
        standing: tuple[StandBehaviour, BalanceState]) -> None:
    """The pelvis pitched 2 degrees (the pelvis task asks for about 100 N m, the pressure
    centre toward the toe): on the floor the stance sole's pressure centre goes 10 cm from
    the one asked; across facets bearing on its heel it stays within SHIFT_M of it."""
    behaviour, state = standing
    pitch = math.radians(2.0)
    on_floor = _stance_shift(behaviour, _touching(state, [UP] * 4, pitch))
    assert float(on_floor[0]) > 0.05
    across = _stance_shift(behaviour, _touching(state, [UP, FACET, UP, FACET], pitch,
                                                ON_HEEL))
    assert float(np.max(np.abs(across))) <= SHIFT_M + 1e-6
    assert float(np.max(np.abs(across))) > 0.5 * SHIFT_M  # still moved, as far as it may


def test_a_stance_sole_across_facets_keeps_where_it_bears(
        standing: tuple[StandBehaviour, BalanceState]) -> None:
    """Bearing on its toe, or on all four corners across a bend (the pit's curved ramps),
    the same moment takes the pressure centre as far toward the toe as on the floor."""
    behaviour, state = standing
    pitch = math.radians(2.0)
    on_floor = _stance_shift(behaviour, _touching(state, [UP] * 4, pitch))
    for gaps in (ON_TOE, ON_ALL):
        across = _stance_shift(behaviour, _touching(state, [UP, FACET, UP, FACET], pitch,
                                                    gaps))
        assert float(across[0]) == pytest.approx(float(on_floor[0]), abs=0.005)


def test_the_bearing_span_is_the_box_of_the_pressed_corners(
        standing: tuple[StandBehaviour, BalanceState]) -> None:
    _, state = standing
    heel = bearing_span(_touching(state, [UP, FACET, UP, FACET], gaps=ON_HEEL), RIGHT)
    assert heel == pytest.approx((-0.13, -0.13, -0.0624, 0.0624), abs=1e-9)
    assert bearing_span(_touching(state, [UP] * 4, gaps=(0.005,) * 4), RIGHT) == NO_SPAN
    beside_wall = bearing_span(_touching(state, [UP, UP, SIDE, SIDE]), RIGHT)
    assert beside_wall == pytest.approx((-0.13, -0.13, -0.0624, 0.0624), abs=1e-9)
