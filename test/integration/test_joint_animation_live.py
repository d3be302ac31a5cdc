"""DRCSim's animate-joints tutorial over ROS, against a running, recording atlas.launch.

Its client (support/joint_animation.py, the tutorial's in Python 3) publishes the 1500-point
trajectory once: the simulator says once what it clamped and how it read the times, plays
it with physics off, and the recorded joint states follow the clamped sines point by point
(each point exactly, from the step it is due) for the 15 s it lasts; the bag, input and
all, replays offline bit for bit.

Run with `python3 -m pytest test/integration/test_joint_animation_live.py -q -s` after
`source env.sh`. Wall time about 40-60 s.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')
pytest.importorskip('trajectory_msgs.msg', reason='needs python3-trajectory-msgs')
if shutil.which('roslaunch') is None:
    pytest.skip('roslaunch is not on PATH (source env.sh)', allow_module_level=True)

from support.joint_animation import (
    TUTORIAL_DT_NS,
    TUTORIAL_ORDER,
    TUTORIAL_POINTS,
    tutorial_sines,
)
from support.launch import EXIT_TIMEOUT_S, TestLaunch
from tutorial_atlas_control import topics
from tutorial_atlas_control.bags.reader import read_bag
from tutorial_atlas_control.joints import JOINT_INDEX
from tutorial_atlas_control.offline.replay import replay_bag
from tutorial_atlas_control.processes import stop_tree
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.vrc import InputEvent, TrajectoryInput
from tutorial_atlas_control.units import NS_PER_S

pytestmark = pytest.mark.filterwarnings('ignore::DeprecationWarning')

TEST_DIR = Path(__file__).resolve().parents[1]
APPLIED = '/joint_trajectory 28 joints, 1500 points'
#: The simulator's lines about the message (their full texts: test_joint_trajectory.py).
NOTES = ("/joint_trajectory: positions outside their joints' limits, clamped to the limits: "
         'l_leg_uhz by up to 0.18 rad',
         '/joint_trajectory: time_from_start does not increase (point 1: 0.01 s after 0.01 s)')
PLAY_S = (TUTORIAL_POINTS - 1) * TUTORIAL_DT_NS / NS_PER_S
CLIENT_TIMEOUT_S = 120.0


def test_the_animate_joints_tutorial_plays_live_and_replays(tmp_path: Path) -> None:
    with TestLaunch(tmp_path) as launch:
        launch.wait_ready()
        launch.wait(lambda: '/atlas_sim' in launch.subscribers(topics.JOINT_TRAJECTORY),
                    120.0, 'the simulator did not subscribe to /joint_trajectory')
        launch.wait_sim_until(1.5)
        client = subprocess.Popen([sys.executable, '-m', 'support.joint_animation'],
                                  cwd=TEST_DIR, env=launch.env, stdout=subprocess.PIPE,
                                  stderr=subprocess.STDOUT, text=True, start_new_session=True)
        try:
            launch.wait(lambda: APPLIED in launch.output(), CLIENT_TIMEOUT_S,
                        'the tutorial\'s trajectory was not applied')
        finally:
            stop_tree(client)
        launch.wait_sim_s(PLAY_S + 0.5)
        launch.interrupt(EXIT_TIMEOUT_S)
        bag = launch.bag()
        output = launch.output()
    for note in NOTES:
        assert output.count(note) == 1, f'not once: {note!r}'

    data = read_bag(bag)
    (_, text), = data.sim_inputs
    event = InputEvent.from_json(text)
    item = event.item
    assert isinstance(item, TrajectoryInput)
    states = data.joint_states
    assert states is not None
    columns = [states.names.index(name) for name in TUTORIAL_ORDER]
    # Sim time (ns) of each joint state: its stamp, after the step that set it.
    stamps_ns = np.array([round(data.sim_time_s(t) * NS_PER_S) for t in states.t_s])
    since_ns = stamps_ns - event.time_ns
    playing = (since_ns > 0) & (since_ns <= PLAY_S * NS_PER_S + 1_000_000)
    step_ns = int(np.median(np.diff(stamps_ns)))
    point = (since_ns[playing] - step_ns) // TUTORIAL_DT_NS
    seen = states.position[playing][:, columns]
    played = np.array(item.positions_rad)
    np.testing.assert_array_equal(seen, played[point])  # each point exactly, in its steps
    assert point[0] == 0 and point[-1] == TUTORIAL_POINTS - 1
    atlas = atlas_model.load_model()
    limits = [JOINT_INDEX[name] for name in TUTORIAL_ORDER]
    wanted = np.clip(tutorial_sines((since_ns[playing] - step_ns) / NS_PER_S),
                     atlas.lower_rad[limits], atlas.upper_rad[limits])
    error = np.abs(seen - wanted)
    print(f'figures: live, {len(seen)} joint states over {PLAY_S:g} s: against the clamped '
          f'sines, max {error.max() * 1e3:.3f} mrad, RMS '
          f'{np.sqrt((error ** 2).mean()) * 1e3:.3f} mrad (all joints)')
    assert error.max() < 2.9e-3

    result = replay_bag(bag)
    print(f'figures: replay: {result.recorded_steps} steps, max joint deviation '
          f'{result.joint_position.max_abs}')
    assert result.reproduced and result.joint_position.max_abs == 0.0
