"""The height a walk walks at: 5 cm (walk_lowering_m) below the Stand it starts from, but a
Stand already lowered well below the Stand pose (its legs not reaching a foot that landed
turned: 13 cm on the VRC course after a goal) walks at its own height: lowered 5 cm more,
its pelvis was 0.70 m over the ground at the first swing and the stance leg gave way."""

from __future__ import annotations

import dataclasses

import pytest

from support.standing import started_stand
from tutorial_atlas_control.balance.stand import StandController
from tutorial_atlas_control.walking import straight_steps
from tutorial_atlas_control.walking.leg_tasks import foot_pose
from tutorial_atlas_control.walking.step_queue import StepQueue
from tutorial_atlas_control.walking.walk import (
    LOWEST_WALK_MARGIN_M,
    WalkController,
    WalkGains,
)

LOWERING_M = WalkGains().walk_lowering_m


def _walk_from(lowered_m: float, standing: bool = True) -> WalkController:
    """A walk of two steps from a Stand `lowered_m` below the Stand pose's CoM height."""
    atlas, _, stand = started_stand()
    state, held = stand.last_state, stand.controller
    assert state is not None and held is not None
    standing_m = stand.ground_under_m(state) + stand.com_height_m
    reference = dataclasses.replace(held.reference, com_height_m=standing_m - lowered_m)
    controller = StandController(stand.estimator.mass_kg, atlas.effort_limit_nm, reference,
                                 stand.estimator.sole_half_size_m, stand.gains)
    queue = StepQueue(foot_pose(state, 0), foot_pose(state, 1))
    queue.offer(straight_steps(2, 0.15))
    return WalkController(controller, queue, state, 0.0,
                          standing_height_m=standing_m if standing else None)


@pytest.mark.parametrize('lowered_m', [0.0, 0.01])
def test_a_walk_from_the_stand_pose_walks_its_lowering_below(lowered_m: float) -> None:
    walk = _walk_from(lowered_m)
    assert walk.walk_height_m == walk.stand_height_m - LOWERING_M


def test_a_walk_from_a_lowered_stand_walks_at_its_height() -> None:
    walk = _walk_from(0.13)
    assert walk.walk_height_m == walk.stand_height_m
    # Partly lowered: down to the lowest a walk goes.
    partly = _walk_from(LOWERING_M)
    assert partly.walk_height_m == pytest.approx(
        partly.stand_height_m - LOWEST_WALK_MARGIN_M, abs=1e-12)
    # Without the Stand pose's height given: lowered from where it starts, as before.
    assert _walk_from(0.13, standing=False).walk_height_m == pytest.approx(
        walk.stand_height_m - LOWERING_M, abs=1e-12)
