"""`make demo TRAJ=step_and_stand RTF=0.5` live (half real time: a busy machine's late
commands matter half as much; at real_time_factor 0 traj_yaml.py falls behind sim time and the
robot falls): run_demo.py finds trajectories/Stepping.yaml, starts atlas.launch with its
companion gains (config/stepping_gains.yaml), and the bag shows the robot stepping with those
gains and standing after. The step's goals are judged from the recorded bag (every 1 kHz state,
nothing lost to a slow subscriber): the right foot, placed by forward kinematics from the
pelvis pose and the joint states, lifts, lands further forward and bears weight, and the pelvis
stays high until the recording ends (the demo's 3 s after the last command)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tutorial_atlas_control.bags.analysis import analyze_bag, first_applied_command_s
from tutorial_atlas_control.bags.feet import foot_displacement
from tutorial_atlas_control.bags.reader import BagData
from tutorial_atlas_control.bags.records import open_bag
from tutorial_atlas_control.bags.typestore import JOINT_COMMANDS_TYPE, load_typestore
from tutorial_atlas_control.joints import JOINT_NAMES, bare_joint_name, joint_index
from tutorial_atlas_control.sim.controller import load_gains_yaml

#: Timing or memory claims: run alone, after make test's parallel part.
pytestmark = pytest.mark.serial

REPO = Path(__file__).resolve().parents[2]
RUN_DEMO = REPO / 'scripts' / 'run_demo.py'
STEPPING_GAINS = REPO / 'config' / 'stepping_gains.yaml'
TUTORIAL_GAINS = REPO / 'config' / 'atlas_controller.yaml'
#: Wall-clock guard against a hung run (s), as conftest's DEMO_TIMEOUT_S.
DEMO_TIMEOUT_S = 900
#: The step: the right foot ends at least this much further forward (m), the issue's goal.
#: Stepping.yaml reports 0.264 m offline, 0.238 m or more with commands 0-20 ms late.
FORWARD_M = 0.15
#: Lifted, not slid: the foot's highest point above where it stood (m).
LIFTED_M = 0.03
#: Put down: the foot's height at the end against where it started (m; it may rest on an
#: edge, 7-9 mm up offline), and the force through its ankle (standing: about 425 N a foot;
#: the lifted foot's own weight: 16 N).
DOWN_WITHIN_M = 0.02
BEARING_N = 150.0
PELVIS_ABOVE_M = 0.8
#: Right-foot positions are sampled this often (s) for its highest point.
FOOT_SAMPLE_S = 0.01


def right_foot_heights(data: BagData, start_s: float, end_s: float) -> np.ndarray:
    """The right foot's height (m) every FOOT_SAMPLE_S from `start_s` to `end_s`, by forward
    kinematics of the recorded pelvis pose and joint states."""
    import mujoco

    from tutorial_atlas_control.sim import body_position_in_pose, load_model

    atlas = load_model()
    foot = atlas.model.body('r_foot').id
    kinematics = mujoco.MjData(atlas.model)
    pelvis, states = data.pelvis, data.joint_states
    assert pelvis is not None and states is not None
    columns = [(c, i) for c, name in enumerate(states.names)
               if (i := joint_index(name)) is not None]
    heights = []
    for at_s in np.arange(start_s, end_s, FOOT_SAMPLE_S):
        pose = int(np.searchsorted(pelvis.t_s, at_s, side='right')) - 1
        row = int(np.searchsorted(states.t_s, at_s, side='right')) - 1
        angles = np.zeros(len(JOINT_NAMES))
        for column, index in columns:
            angles[index] = states.position[row, column]
        heights.append(body_position_in_pose(
            atlas, kinematics, foot, pelvis.position_m[pose],
            pelvis.orientation_xyzw[pose, [3, 0, 1, 2]], angles)[2])
    return np.array(heights)


def last_force_n(bag: Path, topic: str) -> float:
    """The magnitude of the last recorded WrenchStamped force on `topic` (N)."""
    records = open_bag(bag)
    try:
        connections = [c for c in records.connections if c.topic == topic]
        typestore = load_typestore(records.connections)
        _times, raws = records.raw_messages(connections)
        force = typestore.deserialize_ros1(raws[-1], connections[0].msgtype).wrench.force
    finally:
        records.close()
    return float(np.linalg.norm([force.x, force.y, force.z]))


def commanded_kp(bag: Path) -> np.ndarray:
    """kp_position of every /atlas/joint_commands message, (messages, 28), tutorial order."""
    records = open_bag(bag)
    try:
        connections = [c for c in records.connections if c.topic == '/atlas/joint_commands']
        typestore = load_typestore(records.connections)
        _times, raws = records.raw_messages(connections)
        rows = []
        for raw in raws:
            message = typestore.deserialize_ros1(raw, JOINT_COMMANDS_TYPE)
            by_name = dict(zip(map(bare_joint_name, message.name), message.kp_position))
            rows.append([by_name[name] for name in JOINT_NAMES])
    finally:
        records.close()
    return np.array(rows)


def test_step_and_stand_demo_uses_its_gains_and_stands(tmp_path: Path) -> None:
    pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')
    env = dict(os.environ, ROS_LOG_DIR=str(tmp_path / 'ros_log'))
    result = subprocess.run(
        [sys.executable, str(RUN_DEMO), 'step_and_stand', '--bag-dir', str(tmp_path),
         '--video-fps', '0', '--real-time-factor', '0.5'],
        env=env, capture_output=True, text=True, timeout=DEMO_TIMEOUT_S, check=False)
    assert result.returncode == 0, result.stdout + result.stderr
    assert (f'demo: gains {STEPPING_GAINS} (the companion of Stepping.yaml)'
            in result.stdout.splitlines()), result.stdout
    assert 'right foot moved ' in result.stdout
    bag, = tmp_path.glob('atlas_*.bag')

    kp = commanded_kp(bag)
    stepping, tutorial = load_gains_yaml(STEPPING_GAINS).p, load_gains_yaml(TUTORIAL_GAINS).p
    assert len(kp) > 100
    assert not np.array_equal(stepping, tutorial), 'the test would not tell the gains apart'
    np.testing.assert_array_equal(kp, np.broadcast_to(stepping, kp.shape))

    analysis = analyze_bag(bag)
    data = analysis.data
    assert analysis.fell is False, analysis.min_pelvis_height_m
    moved = foot_displacement(data)
    assert moved is not None
    assert data.commands is not None and data.pelvis is not None
    first_s, last_command_s = first_applied_command_s(data), float(data.commands.t_s[-1])
    assert first_s is not None
    heights = right_foot_heights(data, first_s, last_command_s)
    lift_m = float(heights.max() - heights[0])
    standing = data.pelvis.position_m[data.pelvis.t_s >= first_s, 2]
    bearing_n = last_force_n(bag, '/atlas/r_foot_contact')
    print(f'step_and_stand live: right foot lifted {lift_m:.3f} m, landed '
          f'{moved.displacement_m[0]:.3f} m forward ({moved.displacement_m[2]:+.4f} m up, '
          f'bearing {bearing_n:.0f} N); lowest pelvis {standing.min():.3f} m until '
          f'{data.pelvis.t_s[-1] - last_command_s:.2f} s after the last command')
    assert lift_m > LIFTED_M, 'the right foot lifted'
    assert moved.displacement_m[0] >= FORWARD_M, moved
    assert abs(moved.displacement_m[2]) < DOWN_WITHIN_M, 'the right foot is down at the end'
    assert bearing_n > BEARING_N, 'the right foot bears weight at the end'
    assert standing.min() > PELVIS_ABOVE_M, 'the robot stood'
