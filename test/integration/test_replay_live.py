"""Live replay: a recorded run's commands, played with `rosbag play` into a fresh simulator,
reproduce its outcome (step_and_fall: the robot falls).

The run is recorded first with `run_demo.py step_and_fall` (its own master on a free port),
or taken from $TAC_LIVE_REPLAY_BAG. Then a fresh `atlas.launch` (record:=false) is started on
another free port, and once its torso is released `rosbag play BAG --topics
/atlas/control_mode /atlas/joint_commands` sends the recorded mode switch and commands.

`rosbag play` cannot follow the simulator's /clock: it paces messages by wall time from the
first selected message (`--clock` would make it a second /clock source). So the commands
keep their recorded spacing only while the simulator keeps real time; the test measures
the sim-time span the played commands arrived over and reports it next to the recorded one.

The same bag must also replay offline (replay_bag) exactly.

Run with `python3 -m pytest test/integration -q -s` after `source env.sh` (needs roslaunch,
rosbag and the workspace's osrf_msgs; skipped otherwise). Wall time about 60 s.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

pytest.importorskip('osrf_msgs.msg', reason='osrf_msgs is not built (source env.sh)')
if shutil.which('roslaunch') is None or shutil.which('rosbag') is None:
    pytest.skip('roslaunch/rosbag are not on PATH (source env.sh)', allow_module_level=True)

from tutorial_atlas_control.processes import AtlasLaunch

REPO = Path(__file__).resolve().parents[2]
REPLAY_PROBE = Path(__file__).resolve().parent / 'replay_probe.py'
TRAJECTORY = 'step_and_fall'
FALLEN_BELOW_M = 0.5
STANDING_ABOVE_M = 0.8
#: Wall-clock guards against hangs (s), far beyond what a loaded machine takes.
STARTUP_TIMEOUT_S = 120.0
PLAY_TIMEOUT_S = 120.0
#: Start playing this long (sim time) after the torso is released (1 s), so that the
#: first played message (the switch to User) arrives while the robot stands free.
PLAY_AFTER_S = 1.2
#: Sim time to watch for the fall after the last played command.
FALL_WINDOW_S = 5.0


@pytest.fixture(scope='session')
def recorded_bag(demo_run) -> Path:  # demo_run: conftest.DemoRun
    """A step_and_fall bag: $TAC_LIVE_REPLAY_BAG, or the shared run_demo.py recording."""
    given = os.environ.get('TAC_LIVE_REPLAY_BAG')
    if given:
        return Path(given)
    assert demo_run.result.returncode == 0, \
        f'run_demo.py failed:\n{demo_run.result.stdout}\n{demo_run.result.stderr}'
    return demo_run.bag


@pytest.fixture()
def fresh_simulator(tmp_path: Path) -> Iterator[AtlasLaunch]:
    """atlas.launch (no recording: record:=false) on its own master, bag_dir tmp_path/bags."""
    with AtlasLaunch(tmp_path / 'atlas_launch.log',
                     {'gui': 'false', 'record': 'false', 'bag_dir': str(tmp_path / 'bags')},
                     ros_log_dir=tmp_path / 'ros_log') as launch:
        launch.wait_master(STARTUP_TIMEOUT_S)
        yield launch


def test_played_commands_make_the_robot_fall(
        recorded_bag: Path, fresh_simulator: AtlasLaunch, tmp_path: Path) -> None:
    from tutorial_atlas_control.bags.analysis import analyze_bag

    recorded = analyze_bag(recorded_bag)
    assert recorded.fell, f'the recorded run did not fall: {recorded_bag}'
    assert recorded.data.commands is not None and len(recorded.data.commands.t_s)
    recorded_span_s = float(recorded.data.commands.t_s[-1] - recorded.data.commands.t_s[0])

    # The ROS side in its own process (replay_probe.py): this one stays without a node.
    probe = subprocess.run(
        [sys.executable, str(REPLAY_PROBE), str(recorded_bag), '--play-at',
         str(1.0 + PLAY_AFTER_S), '--fallen-below', str(FALLEN_BELOW_M), '--fall-window',
         str(FALL_WINDOW_S), '--timeout', str(PLAY_TIMEOUT_S),
         '--commands', str(len(recorded.data.commands.t_s))],
        env=fresh_simulator.env, capture_output=True, text=True,
        timeout=STARTUP_TIMEOUT_S + 2 * PLAY_TIMEOUT_S, check=False)
    assert probe.returncode == 0 and probe.stdout.strip(), probe
    outcome = json.loads(probe.stdout.strip().splitlines()[-1])
    assert 'error' not in outcome, (
        f'{outcome["error"]} ({len(outcome["arrivals_s"])} of {len(recorded.data.commands.t_s)} '
        f'commands arrived; rosbag play: {outcome.get("play_output")!r}):\n'
        f'{fresh_simulator.output()}')
    assert outcome['z_before_m'] > STANDING_ABOVE_M, \
        'the fresh robot is not standing before the replay'
    assert outcome['play_returncode'] == 0, f'rosbag play failed:\n{outcome["play_output"]}'
    arrivals, min_z_m = outcome['arrivals_s'], outcome['min_z_m']
    assert len(arrivals) == len(recorded.data.commands.t_s), 'commands were lost in playback'
    played_span_s = arrivals[-1] - arrivals[0]
    print(f'\nlive replay of {recorded_bag.name}: {len(arrivals)} commands arrived over '
          f'{played_span_s:.2f} s of sim time (recorded over {recorded_span_s:.2f} s), '
          f'first at {arrivals[0]:.2f} s; lowest pelvis height {min_z_m:.2f} m')
    # README: record:=false records nothing (the run is over; the launch still up).
    assert not list((tmp_path / 'bags').glob('*')), 'record:=false wrote a bag'
    assert min_z_m < FALLEN_BELOW_M, (
        f'the replayed run did not fall (lowest pelvis {min_z_m:.2f} m); commands arrived over '
        f'{played_span_s:.2f} s of sim time vs {recorded_span_s:.2f} s recorded')


def test_offline_replay_of_the_recording_is_exact(recorded_bag: Path) -> None:
    """The same bag, re-simulated without ROS from its recorded torques: bit for bit."""
    from tutorial_atlas_control.offline.replay import replay_bag

    result = replay_bag(recorded_bag)
    assert result.recorded_steps > 1000
    assert result.joint_position.max_abs == 0.0 and result.joint_velocity.max_abs == 0.0
    assert result.pelvis_position is not None and result.pelvis_position.max_abs == 0.0
    assert result.pelvis_orientation is not None and result.pelvis_orientation.max_abs == 0.0
