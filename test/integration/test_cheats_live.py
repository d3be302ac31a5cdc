"""VRCPlugin's topics and /gazebo/reset_models against a running, recording atlas.launch.

Bad input on every new topic is refused with one line naming the topic, nothing is applied
(no /atlas/sim_inputs, the pose unchanged) and the simulator keeps stepping; good input is
applied (set_pose within 1 mm, a held pelvis push topples the robot); reset_models resets;
and the recorded bag, inputs and all, replays offline bit for bit and shows the inputs on
analyze_bag's timeline.

Run with `python3 -m pytest test/integration/test_cheats_live.py -q -s` after `source
env.sh` (needs roslaunch and the workspace's messages; skipped otherwise). Wall time
about 20 s (18 s measured on a quiet machine, 24 s beside the other tests).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')
pytest.importorskip('trajectory_msgs.msg', reason='needs python3-trajectory-msgs')
if shutil.which('roslaunch') is None:
    pytest.skip('roslaunch is not on PATH (source env.sh)', allow_module_level=True)

from support.bag_checks import count
from support.launch import EXIT_TIMEOUT_S, TestLaunch
from tutorial_atlas_control import topics
from tutorial_atlas_control.bags.analysis import analyze_bag
from tutorial_atlas_control.bags.reader import read_bag
from tutorial_atlas_control.offline.replay import replay_bag

pytestmark = pytest.mark.filterwarnings('ignore::DeprecationWarning')

#: (topic, type, bad message as rostopic pub YAML, what the refusal says).
BAD_INPUTS = (
    (topics.MODE, 'std_msgs/String', "{data: flying}",
     "refused /atlas/mode: unknown mode 'flying'; valid modes: harnessed, pinned, "
     'pinned_with_gravity, nominal, feet, no_gravity, bdi_stand; nothing applied'),
    # An all-zero quaternion is upright (Gazebo's reading); a near-zero one is refused.
    (topics.SET_POSE, 'geometry_msgs/Pose', '{position: {z: 1.0}, orientation: {w: 1.0e-12}}',
     'refused /atlas/set_pose: orientation is a zero quaternion (set w = 1 for upright); '
     'nothing applied'),
    (topics.CMD_VEL, 'geometry_msgs/Twist', '{linear: {x: .nan}}',
     'refused /atlas/cmd_vel: linear velocity is not finite (nan); nothing applied'),
    (topics.APPLY_PELVIS_FORCE, 'geometry_msgs/Wrench', '{force: {x: 1.0e+9}}',
     'refused /atlas/apply_pelvis_force: force 1e+09 exceeds 100000; nothing applied'),
    (topics.JOINT_TRAJECTORY, 'trajectory_msgs/JointTrajectory',
     '{joint_names: [l_arm_shx, l_wing], points: [{positions: [0, 0]}]}',
     "refused /joint_trajectory: unknown joint name 'l_wing'; nothing applied"),
    (topics.JOINT_TRAJECTORY, 'trajectory_msgs/JointTrajectory',
     '{joint_names: [l_arm_shx], points: [{positions: [0], time_from_start: {secs: 1}}, '
     '{positions: [0.1], time_from_start: {secs: -1}}]}',
     'refused /joint_trajectory: point 1 time_from_start -1 s is negative; nothing applied'),
)
GOOD_INPUTS = (
    (topics.MODE, 'std_msgs/String', '{data: pinned}'),
    (topics.SET_POSE, 'geometry_msgs/Pose',
     '{position: {x: 0.5, y: -0.25, z: 1.0}, orientation: {w: 1.0}}'),
    (topics.JOINT_TRAJECTORY, 'trajectory_msgs/JointTrajectory',
     '{joint_names: [l_arm_shx, atlas::r_arm_shx], points: ['
     '{positions: [-0.5, 0.5]}, {positions: [-1.0, 1.0], time_from_start: {nsecs: 200000000}}]}'),
    # As DRCSim's animate-joints tutorial: past a limit, every point 0.1 s after the last.
    (topics.JOINT_TRAJECTORY, 'trajectory_msgs/JointTrajectory',
     "{header: {frame_id: 'atlas::pelvis'}, joint_names: [atlas::l_arm_ely, atlas::l_arm_shx], "
     'points: [{positions: [-0.5, 0.2], time_from_start: {nsecs: 100000000}}, '
     '{positions: [0.5, 0.4], time_from_start: {nsecs: 100000000}}]}'),
    (topics.CMD_VEL, 'geometry_msgs/Twist', '{linear: {x: 0.2}, angular: {z: 0.3}}'),
    (topics.CMD_VEL, 'geometry_msgs/Twist', '{}'),
    (topics.MODE, 'std_msgs/String', '{data: nominal}'),
)
#: What the simulator says about the tutorial-like trajectory: once each, and it plays.
DRCSIM_ERA_LINES = (
    "/joint_trajectory: positions outside their joints' limits, clamped to the limits: "
    'l_arm_ely by up to 0.5 rad beyond [0, 3.14159] (1 of 2 points)',
    '/joint_trajectory: time_from_start does not increase (point 1: 0.1 s after 0.1 s), read '
    "as DRCSim 2.5.2 read it: each point's time_from_start added to the previous point's "
    'time; the 2 points play over 0.1 s',
)
#: The start of the simulator's line for each input it applies.
APPLIED = 'applied at t='
#: DRCSim-era push: 300 N forward on the pelvis, held about 0.5 s of sim time, then zero.
PUSH = '{force: {x: 300.0}}'


def apply(launch: TestLaunch, topic: str, msg_type: str, yaml_text: str) -> None:
    """Publish a good input and wait for the simulator's line saying it applied it: inputs
    on different topics travel over different connections, so only this keeps their order
    (the line comes for the first input of a kind in a second: not for a repeat)."""
    applied = launch.output().count(APPLIED)
    launch.publish(topic, msg_type, yaml_text)
    launch.wait(lambda: launch.output().count(APPLIED) > applied, 30.0,
                f'{topic} {yaml_text} was not applied')


def pelvis_position(launch: TestLaunch) -> tuple[float, float, float]:
    position = launch.next_message('/ground_truth_odom')['pose']['pose']['position']
    return float(position['x']), float(position['y']), float(position['z'])


def test_cheats_live_refusals_effects_reset_models_and_exact_replay(tmp_path: Path) -> None:
    with TestLaunch(tmp_path) as launch:
        launch.wait_ready()
        launch.wait(lambda: '/atlas_sim' in launch.subscribers(topics.JOINT_TRAJECTORY),
                    120.0, 'the simulator did not subscribe to /joint_trajectory')
        launch.wait_sim_until(1.5)
        before = pelvis_position(launch)
        for topic, msg_type, yaml_text, refusal in BAD_INPUTS:
            launch.publish(topic, msg_type, yaml_text)
            launch.wait(lambda refusal=refusal: refusal in launch.output(), 30.0,
                        f'no refusal line {refusal!r}')
        launch.publish(topics.CONFIGURATION, 'sensor_msgs/JointState',
                       '{name: [l_arm_shx], position: [1.0]}')
        launch.wait(lambda: '/atlas/configuration is not implemented' in launch.output(),
                    30.0, 'no not-implemented line for /atlas/configuration')
        after = pelvis_position(launch)
        # Standing, the robot sways by about a centimetre; a teleport or push moves it metres.
        assert after[2] > 0.9 and max(abs(a - b) for a, b in zip(before, after)) < 0.05
        assert APPLIED not in launch.output(), 'a refused input was applied'

        for topic, msg_type, yaml_text in GOOD_INPUTS[:2]:
            apply(launch, topic, msg_type, yaml_text)
        launch.wait_sim_s(0.5)
        x, y, z = pelvis_position(launch)  # pinned there: the teleport stays put
        assert abs(x - 0.5) < 1e-3 and abs(y + 0.25) < 1e-3 and abs(z - 1.0) < 1e-3
        for topic, msg_type, yaml_text in GOOD_INPUTS[2:]:
            launch.publish(topic, msg_type, yaml_text)
            launch.wait_sim_s(0.3)
        for line in DRCSIM_ERA_LINES:
            launch.wait(lambda line=line: line in launch.output(), 30.0, f'no line {line!r}')

        launch.run('rosservice', 'call', topics.RESET_MODELS_SERVICE)
        launch.wait(lambda: 'reset_world: robot back to its initial pose' in launch.output(),
                    30.0, '/gazebo/reset_models did not reset the world')
        launch.wait_sim_s(1.5)  # unpinned, standing
        launch.publish(topics.APPLY_PELVIS_FORCE, 'geometry_msgs/Wrench', PUSH)
        launch.wait_sim_s(0.5)
        launch.publish(topics.APPLY_PELVIS_FORCE, 'geometry_msgs/Wrench', '{}')
        launch.wait_sim_s(3.0)
        assert pelvis_position(launch)[2] < 0.5, 'the 300 N push toppled the robot'
        launch.interrupt(EXIT_TIMEOUT_S)
        bag = launch.bag()
        for line in DRCSIM_ERA_LINES:
            assert launch.output().count(line) == 1, f'not once: {line!r}'

    applied = len(GOOD_INPUTS) + 2  # and the push and its release, after the reset
    assert count(bag, topics.SIM_INPUTS) == applied
    for topic in (topics.MODE, topics.SET_POSE, topics.CMD_VEL, topics.APPLY_PELVIS_FORCE,
                  topics.JOINT_TRAJECTORY):
        assert count(bag, topic) > 0, f'{topic} is recorded'
    result = replay_bag(bag)
    print(f'figures: replay after reset_models with a 300 N push: '
          f'{result.recorded_steps} steps, max joint deviation {result.joint_position.max_abs}')
    assert result.resets_in_bag == 1
    assert result.joint_position.max_abs == 0.0 and result.pelvis_position.max_abs == 0.0
    assert result.reproduced
    timeline = [text for _, text in analyze_bag(bag).input_timeline]
    assert timeline[0] == '/atlas/mode mode=pinned'
    assert timeline[-2].startswith('/atlas/apply_pelvis_force force=[300.0, 0.0, 0.0]')
    assert read_bag(bag).sim_inputs
