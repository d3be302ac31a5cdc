"""Step onto a VRC cinder block and off again, offline (offline/block_step.py): a client
streaming STEP through the AtlasSimInterface puts the left foot onto a loose 5 kg block 0.203
m high (lying flat, hollow: the sole lands on its walls' rims; on its side: one solid wall on
top) and back down where it stood; the robot still stands after, each sole settled within
2 cm of its goal's height (on the block's top, on the floor), 3 cm of its x, y and 0.1 rad of
its yaw, the block moved less than 1 cm. The deterministic start and one perturbed start
(walking/start_noise.py); docs/vrc.md has the 8-seed figures and the command measuring them.
Planted once: with the swing along the ordinary path (no step-over), the toe kicks the block
away and the sole comes down on the floor (its height 17 cm off), and this test fails.
"""

from __future__ import annotations

import pytest

from tutorial_atlas_control.offline.block_step import CinderBlock, block_step_trial

#: Offline (no ROS, no claim about time): run at the lowest priority beside the serial tests.
pytestmark = pytest.mark.offline

HEIGHT_WITHIN_M = 0.02
LANDING_WITHIN_M = 0.03
YAW_WITHIN_RAD = 0.1
BLOCK_MOVES_LESS_M = 0.01


@pytest.mark.parametrize(('on_side', 'seed'), [(False, None), (False, 1), (True, None)],
                         ids=['flat, deterministic', 'flat, seed 1', 'on its side'])
def test_a_foot_steps_onto_the_block_and_back_and_the_robot_stands(
        on_side: bool, seed: int | None) -> None:
    block = CinderBlock(on_side=on_side)
    run = block_step_trial(block, seed, 'back')
    landings = [(s.goal.step_index, round(s.goal.z_m, 3), [round(v, 3) for v in s.landed])
                for s in run.steps]
    assert run.stood, (f'fell or stopped: {len(run.steps)} steps, pelvis down to '
                       f'{run.lowest_clearance_m:.3f} m over the ground; landings {landings}')
    assert [s.goal.z_m for s in run.steps] == [block.top_m, 0.0]
    for step in run.steps:
        assert step.height_error_m < HEIGHT_WITHIN_M, landings
        assert step.horizontal_error_m < LANDING_WITHIN_M, landings
        assert step.yaw_error_rad < YAW_WITHIN_RAD, landings
    assert run.block_moved_m < BLOCK_MOVES_LESS_M
