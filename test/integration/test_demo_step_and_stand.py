"""`make demo TRAJ=step_and_stand RTF=0.5` live (half real time, as the step's rostest: a busy
machine's late commands matter half as much; at real_time_factor 0 traj_yaml.py falls behind
sim time and the robot falls): run_demo.py finds trajectories/Stepping.yaml, starts
atlas.launch with its companion gains (config/stepping_gains.yaml), and the bag shows the
robot stepping with those gains and not falling."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tutorial_atlas_control.bags.analysis import analyze_bag
from tutorial_atlas_control.bags.feet import foot_displacement
from tutorial_atlas_control.bags.records import open_bag
from tutorial_atlas_control.bags.typestore import JOINT_COMMANDS_TYPE, load_typestore
from tutorial_atlas_control.joints import JOINT_NAMES, bare_joint_name
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
    assert analysis.fell is False, analysis.min_pelvis_height_m
    moved = foot_displacement(analysis.data)
    assert moved is not None
    assert moved.displacement_m[0] >= FORWARD_M, moved
