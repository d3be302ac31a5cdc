"""search/objectives.py's steps_forward (steps in a row): its cost is
0 only when every goal holds, grows with each shortfall, and any fall costs more than any run
that stands, whatever its shortfalls."""

from __future__ import annotations

from typing import Any

import pytest

from tutorial_atlas_control.search.objectives import parse_objective
from tutorial_atlas_control.search.runs import SweepError

STEPS = 'steps_forward:r=0.45,l=0.3,stand=5,z=0.8'


def _row(**changes: Any) -> dict[str, Any]:
    """A run that meets STEPS: both feet lifted and put down far enough forward, stood 5 s."""
    row: dict[str, Any] = {
        'fell': False, 'fall_time_s': None, 'played_s': 12.0, 'stood_after_s': 5.0,
        'pelvis_z_end_m': 0.9, 'r_foot_dx_m': 0.5, 'r_foot_dz_end_m': 0.002,
        'r_foot_lift_max_m': 0.06, 'l_foot_dx_m': 0.35, 'l_foot_dz_end_m': -0.001,
        'l_foot_lift_max_m': 0.05}
    row.update(changes)
    return row


def test_steps_forward_costs_nothing_only_when_every_goal_holds() -> None:
    objective = parse_objective(STEPS)
    assert objective.settle_s == 5.0
    assert objective.cost(_row(r_foot_dz_end_m=0.0, l_foot_dz_end_m=0.0)) == 0.0
    short = {'r_foot_dx_m': 0.44, 'l_foot_dx_m': 0.29, 'r_foot_lift_max_m': 0.02,
             'l_foot_lift_max_m': 0.02, 'r_foot_dz_end_m': 0.01, 'l_foot_dz_end_m': -0.01,
             'pelvis_z_end_m': 0.79, 'stood_after_s': 4.9}
    for key, value in short.items():
        assert objective.cost({**_row(r_foot_dz_end_m=0.0, l_foot_dz_end_m=0.0),
                               key: value}) > 0.05, key


def test_steps_forward_weighs_a_centimetre_as_a_tenth_of_a_second() -> None:
    objective = parse_objective(STEPS)
    base = _row(r_foot_dz_end_m=0.0, l_foot_dz_end_m=0.0)
    assert objective.cost({**base, 'l_foot_dx_m': 0.2}) == pytest.approx(1.0)
    assert objective.cost({**base, 'r_foot_dx_m': 0.35, 'stood_after_s': 4.5}) == \
        pytest.approx(1.5)


def test_a_fall_costs_more_than_any_run_that_stands() -> None:
    objective = parse_objective(STEPS)
    worst_standing = _row(stood_after_s=0.0, pelvis_z_end_m=-1.0, r_foot_dx_m=-2.0,
                          l_foot_dx_m=-2.0, r_foot_lift_max_m=0.0, l_foot_lift_max_m=0.0,
                          r_foot_dz_end_m=3.0, l_foot_dz_end_m=-3.0)
    latest_fall = _row(fell=True, fall_time_s=16.99, stood_after_s=4.99)
    assert objective.cost(latest_fall) > objective.cost(worst_standing)
    early_fall = _row(fell=True, fall_time_s=3.0, stood_after_s=0.0)
    assert objective.cost(early_fall) > objective.cost(latest_fall)


def test_steps_forward_refuses_an_unknown_key() -> None:
    with pytest.raises(SweepError, match="'dx=0.2' is not KEY=VALUE with KEY one of l, lift, "
                                         'r, stand, z'):
        parse_objective('steps_forward:dx=0.2')
