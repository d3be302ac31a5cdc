"""/joint_trajectory as DRCSim's clients sent it: positions past a joint's limits clamped
(one warning naming the joints and by how much), DRCSim 2.5.2's running time_from_start,
and DRCSim's animate-joints tutorial played through the simulator, joint by joint, in time.
What cannot be played is still refused whole, in one line."""

from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np
import pytest

from support.joint_animation import (
    FRAME_ID,
    SINE_AMPLITUDE_RAD,
    TUTORIAL_DT_NS,
    TUTORIAL_ORDER,
    TUTORIAL_POINTS,
    tutorial_positions,
    tutorial_sines,
)
from tutorial_atlas_control.joints import JOINT_INDEX, JOINT_NAMES
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.sim.joint_trajectory import TrajectoryMessage, trajectory_input
from tutorial_atlas_control.sim.simulator import AtlasSimulator
from tutorial_atlas_control.sim.vrc import InputError, TrajectoryInput, input_from_dict
from tutorial_atlas_control.units import NS_PER_S

CONFIG = Path(__file__).resolve().parents[3] / 'config' / 'atlas_controller.yaml'


@pytest.fixture(scope='module')
def atlas() -> atlas_model.AtlasModel:
    return atlas_model.load_model()


def tutorial_message() -> TrajectoryMessage:
    """As the tutorial's client sent it: atlas:: names, frame atlas::pelvis, every point's
    time_from_start 0.01 s."""
    return TrajectoryMessage(FRAME_ID, 0, tuple('atlas::' + n for n in TUTORIAL_ORDER),
                             [tuple(row) for row in tutorial_positions()],
                             [TUTORIAL_DT_NS] * TUTORIAL_POINTS)


def limits_in_order(atlas: atlas_model.AtlasModel) -> tuple[np.ndarray, np.ndarray]:
    columns = [JOINT_INDEX[name] for name in TUTORIAL_ORDER]
    return atlas.lower_rad[columns], atlas.upper_rad[columns]


def test_the_tutorial_is_accepted_clamped_and_timed_as_drcsim_did(atlas) -> None:
    item = trajectory_input(tutorial_message(), atlas.lower_rad, atlas.upper_rad)
    assert [JOINT_NAMES[i] for i in item.joints] == list(TUTORIAL_ORDER)
    assert item.reference_link == ''  # the pelvis, the model's root
    assert item.times_ns == tuple(k * TUTORIAL_DT_NS for k in range(TUTORIAL_POINTS))
    lower, upper = limits_in_order(atlas)
    sent = np.array(tutorial_message().positions)
    played = np.array(item.positions_rad)
    assert (played >= lower).all() and (played <= upper).all()
    np.testing.assert_array_equal(played, np.clip(sent, lower, upper))
    warning, info = item.notes
    assert warning.level == logging.WARNING and info.level == logging.INFO
    assert info.text == (
        'time_from_start does not increase (point 1: 0.01 s after 0.01 s), read as DRCSim '
        "2.5.2 read it: each point's time_from_start added to the previous point's time; "
        'the 1500 points play over 14.99 s')
    # Every joint whose range [lower, upper] does not hold ±0.5 rad, and by how much.
    crossing = [name for name, low, high in zip(TUTORIAL_ORDER, lower, upper)
                if low > -SINE_AMPLITUDE_RAD or high < SINE_AMPLITUDE_RAD]
    assert len(crossing) == 14
    named = [part.split(' by up to ')[0] for part in warning.text.split(': ', 1)[1].split('; ')]
    assert named == crossing
    ely = TUTORIAL_ORDER.index('l_arm_ely')
    below = np.count_nonzero(sent[:, ely] < 0.0)  # its lower limit, 0
    assert 900 < below < 1100  # the fast sine is negative for 2 of its 3 half-periods
    assert f'l_arm_ely by up to 0.5 rad beyond [0, 3.14159] ({below} of 1500 points)' \
        in warning.text
    assert 'l_leg_mhx by up to 0.03 rad beyond [-0.47, 0.495]' in warning.text
    assert '\n' not in warning.text and '\n' not in info.text


def test_the_tutorial_plays_through_the_simulator_following_the_clamped_sines(atlas) -> None:
    """Physics off, the joints follow the clamped sines point by point (exactly, at each
    point's time) and in time (sample and hold between points)."""
    sim = AtlasSimulator(atlas, load_gains_yaml(CONFIG))
    for _ in range(1500):  # unpinned after 1 s, standing
        sim.step()
    item = trajectory_input(tutorial_message(), atlas.lower_rad, atlas.upper_rad)
    start_ns = sim.sim_time_ns
    sim.apply_input(item)
    columns = [JOINT_INDEX[name] for name in TUTORIAL_ORDER]
    seen, times_s = [], []
    while sim.playing:
        times_s.append((sim.sim_time_ns - start_ns) / NS_PER_S)
        sim.step()
        seen.append(sim.joint_positions()[columns])
    seen_rad, t_s = np.array(seen), np.array(times_s)
    # Point k is due k × 10 ms after the start; one step per ms: played at step 10 k.
    assert len(seen_rad) == (TUTORIAL_POINTS - 1) * 10 + 1
    np.testing.assert_array_equal(seen_rad[::10], np.array(item.positions_rad))
    lower, upper = limits_in_order(atlas)
    wanted = np.clip(tutorial_sines(t_s), lower, upper)
    error = seen_rad - wanted
    max_rad, rms_rad = np.abs(error).max(axis=0), np.sqrt((error ** 2).mean(axis=0))
    for name, worst, rms in zip(TUTORIAL_ORDER, max_rad, rms_rad):
        print(f'figures: {name}: max {worst * 1e3:.3f} mrad, RMS {rms * 1e3:.3f} mrad')
    # Held 9 ms at most: the fast sine moves 0.5 × 2 × 2π × 0.05 rad/s × 9 ms = 2.8 mrad.
    assert max_rad.max() < 2.9e-3 and rms_rad.max() < 1.7e-3
    assert (seen_rad >= lower).all() and (seen_rad <= upper).all()
    assert not sim.joint_velocities().any()


def test_the_played_input_replays_from_its_logged_dict(atlas) -> None:
    """/atlas/sim_inputs logs what was played: clamped positions and the running times."""
    item = trajectory_input(tutorial_message(), atlas.lower_rad, atlas.upper_rad)
    again = input_from_dict(item.to_dict())
    assert isinstance(again, TrajectoryInput) and again == item and not again.notes


def test_strictly_increasing_times_keep_their_definition_and_say_nothing(atlas) -> None:
    item = trajectory_input(TrajectoryMessage('', 0, ('l_arm_shx',), ((0.1,), (0.2,), (0.3,)),
                                              (5, 10_000_000, 25_000_000)),
                            atlas.lower_rad, atlas.upper_rad)
    assert item.times_ns == (5, 10_000_000, 25_000_000) and item.notes == ()


@pytest.mark.parametrize(('times_ns', 'running_ns', 'stall'), [
    ((0, 0, 0), (0, 0, 0), 'point 1: 0 s after 0 s'),
    ((10, 10, 20), (0, 10, 20), 'point 1: 1e-08 s after 1e-08 s'),
    ((500_000_000, 100_000_000, 200_000_000), (0, 500_000_000, 600_000_000),
     'point 1: 0.1 s after 0.5 s'),
])
def test_times_that_do_not_increase_run_on_from_the_previous_point(
        atlas, times_ns, running_ns, stall) -> None:
    item = trajectory_input(TrajectoryMessage('', 0, ('l_arm_shx',), ((0.1,), (0.2,), (0.3,)),
                                              times_ns), atlas.lower_rad, atlas.upper_rad)
    assert item.times_ns == running_ns
    (note,) = item.notes
    assert note.level == logging.INFO and f'({stall})' in note.text


def test_a_position_past_one_limit_is_clamped_with_the_amount(atlas) -> None:
    item = trajectory_input(TrajectoryMessage('', 0, ('l_arm_shx', 'l_leg_kny'),
                                              ((5.0, 0.5), (0.0, -0.25)), (0, 1)),
                            atlas.lower_rad, atlas.upper_rad)
    upper = atlas.upper_rad[JOINT_INDEX['l_arm_shx']]
    assert item.positions_rad == ((upper, 0.5), (0.0, 0.0))
    (note,) = item.notes
    assert note.text == (
        "positions outside their joints' limits, clamped to the limits: l_arm_shx by up to "
        f'{5.0 - upper:.3g} rad beyond [-1.39626, 1.74533] (1 of 2 points); l_leg_kny by up to '
        '0.25 rad beyond [0, 2.45] (1 of 2 points)')


@pytest.mark.parametrize(('args', 'message'), [
    (('', 0, ('l_arm_shx', 'hand'), ((0, 0),), (0,)), "^unknown joint name 'hand'$"),
    (('', 0, ('l_arm_shx', 'atlas::l_arm_shx'), ((0, 0),), (0,)),
     "^joint 'atlas::l_arm_shx' named twice$"),
    (('', 0, ('l_arm_shx',), ((0,),), (-1,)), '^point 0 time_from_start -1e-09 s is negative$'),
    (('', 0, ('l_arm_shx',), ((0,), (0.1,), (0.2,)), (0, 10, -1_000_000_000)),
     '^point 2 time_from_start -1 s is negative$'),
    (('', 0, ('l_arm_shx',), ((0,), (0.1,)), (0,)), '^1 times for 2 points$'),
    (('', 0, ('l_arm_shx',), ((0, 1),), (0,)), '^point 0 has 2 positions for 1 joint names$'),
    (('', 0, ('l_arm_shx',), ((math.nan,),), (0,)), r'^point 0 position is not finite \(nan\)$'),
    (('', 0, ('l_arm_shx',), ((0.0,), (-math.inf,)), (0, 1)),
     r'^point 1 position is not finite \(-inf\)$'),
    (('', 0, ('l_arm_shx',), ((5e3,),), (0,)), '^point 0 position 5000 exceeds 1000$'),
    (('', 0, ('l_arm_shx',), (), ()), '^the trajectory has no points$'),
    (('', 0, (), ((),), (0,)), '^joint_names is empty$'),
    (('l_hoof', 0, ('l_arm_shx',), ((0,),), (0,)),
     "^header.frame_id 'l_hoof' is neither world, map nor a link of the robot$"),
])
def test_what_cannot_be_played_is_refused_in_one_line(atlas, args, message) -> None:
    with pytest.raises(InputError, match=message):
        trajectory_input(TrajectoryMessage(*args), atlas.lower_rad, atlas.upper_rad,
                         ('pelvis', 'l_foot'))


def test_ignored_trajectory_fields_are_still_checked(atlas) -> None:
    def check(**fields: list[float]) -> None:
        trajectory_input(TrajectoryMessage('', 0, ('l_arm_shx', 'r_arm_shx'), ((0, 0),), (0,),
                                           [fields]), atlas.lower_rad, atlas.upper_rad)
    check(velocities=[], accelerations=[1.0, 2.0], effort=[])
    with pytest.raises(InputError, match='^point 0 has 1 velocities for 2 joint names$'):
        check(velocities=[1.0])
    with pytest.raises(InputError, match=r'^point 0 effort is not finite \(nan\)$'):
        check(effort=[0.0, math.nan])


def test_a_ros_message_reads_as_its_fields() -> None:
    genpy = pytest.importorskip('genpy')
    msgs = pytest.importorskip('trajectory_msgs.msg', reason='needs python3-trajectory-msgs')
    msg = msgs.JointTrajectory(joint_names=['atlas::l_arm_shx'], points=[
        msgs.JointTrajectoryPoint(positions=[0.25], velocities=[1.0],
                                  time_from_start=genpy.Duration(0, 10_000_000))])
    msg.header.frame_id, msg.header.stamp = 'atlas::pelvis', genpy.Time(3, 5)
    message = TrajectoryMessage.from_ros(msg)
    assert message == TrajectoryMessage(
        'atlas::pelvis', 3_000_000_005, ['atlas::l_arm_shx'], [[0.25]], [10_000_000],
        [{'velocities': [1.0], 'accelerations': [], 'effort': []}])
