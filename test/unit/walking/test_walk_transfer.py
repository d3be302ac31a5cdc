"""A walking step's weight transfer, on one frozen estimate of the Stand pose (no physics):
both feet carry until the landed sole is flat and carries half the weight, or at most 0.1 s
(a sole touching heel first, 5 degrees, as the course's landings were, or 2, still rolling
onto the ground); only then does the other foot lift, and its swing takes the rest of the
step, so the step ends on time."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from support.standing import started_stand
from tutorial_atlas_control.balance import BalanceState
from tutorial_atlas_control.walking import straight_steps
from tutorial_atlas_control.walking.leg_tasks import foot_pose
from tutorial_atlas_control.walking.status_flags import STEPPING
from tutorial_atlas_control.walking.step_queue import StepQueue
from tutorial_atlas_control.walking.walk import WalkController, WalkGains, WalkOutput

DT_S = 0.001
LONGEST_S = WalkGains().transfer.longest_s


def _heel_first(rotation: np.ndarray, degrees: float) -> np.ndarray:
    """A sole's rotation pitched `degrees` toes up about its own y axis."""
    angle = -math.radians(degrees)
    pitch = np.array([[math.cos(angle), 0.0, math.sin(angle)], [0.0, 1.0, 0.0],
                      [-math.sin(angle), 0.0, math.cos(angle)]])
    return rotation @ pitch


def _first_step(tilt_deg: float) -> tuple[WalkController, BalanceState, np.ndarray,
                                          list[WalkOutput]]:
    """A walk of two steps ticked on one estimate of the Stand pose (its first step's stance
    sole pitched `tilt_deg` heel first) until its first step's foot lifts; the outputs of the
    step's ticks."""
    atlas, data, stand = started_stand()
    state, controller = stand.last_state, stand.controller
    assert state is not None and controller is not None
    queue = StepQueue(foot_pose(state, 0), foot_pose(state, 1))
    steps = straight_steps(2, 0.15)
    queue.offer(steps)
    stance = 1 - steps[0].foot_index
    rotations = state.sole_rotations.copy()
    rotations[stance] = _heel_first(rotations[stance], tilt_deg)
    state = dataclasses.replace(state, sole_rotations=rotations)
    # The sway's pressure centre on the far side of the feet's middle (pushing the capture
    # point over), then the capture point over the stance sole, where the sway takes it.
    swayed = dataclasses.replace(state, capture_point=state.sole_centres[stance][0:2].copy())
    walk = WalkController(controller, queue, state, 0.0)
    positions, velocities = data.qpos[atlas.qpos_adr], data.qvel[atlas.dof_adr]
    outputs: list[WalkOutput] = []
    for tick in range(2000):
        now = swayed if walk.phase == STEPPING else state
        output = walk.tick_torque(now, positions, velocities, tick * DT_S)
        if walk.phase == STEPPING:
            outputs.append(output)
            if not walk.transferring:
                break
    return walk, state, np.array(steps[0].duration_s), outputs


def test_a_flat_landed_sole_takes_half_the_weight_before_the_other_foot_lifts() -> None:
    walk, state, step_s, outputs = _first_step(0.0)
    *transfer, lifted = outputs
    assert transfer, 'the foot lifted at the step start, with the weight on the other'
    assert all(output.swing_foot is None for output in transfer)  # both feet carry
    assert lifted.swing_foot == walk.step.foot_index
    lift_off_s = len(transfer) * DT_S
    assert 0.0 < lift_off_s < LONGEST_S
    # The swing begins where the sole is and takes the rest of the step.
    assert walk.swing is not None
    np.testing.assert_allclose(walk.swing.start, state.sole_centres[walk.step.foot_index])
    assert walk.swing.duration_s == pytest.approx(float(step_s) - lift_off_s, abs=1e-9)


@pytest.mark.parametrize('tilt_deg', [2.0, 5.0])
def test_a_landed_sole_on_its_heels_edge_keeps_both_feet_carrying_the_longest(
        tilt_deg: float) -> None:
    """5 degrees: on its heel's edge; 2: within a put-down sole's 2.9 degrees, but still
    rolling onto the ground (the transfer's level_cos: 1 degree)."""
    walk, _, step_s, outputs = _first_step(tilt_deg)
    *transfer, lifted = outputs
    assert all(output.swing_foot is None for output in transfer)
    assert len(transfer) * DT_S == pytest.approx(LONGEST_S, abs=1.5 * DT_S)
    assert lifted.swing_foot is not None
    assert walk.swing is not None
    assert walk.swing.duration_s == pytest.approx(float(step_s) - LONGEST_S, abs=1.5 * DT_S)
