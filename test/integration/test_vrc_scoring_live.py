"""DRCSim's VRC scoring live: the node with ~vrc_scoring true on the default world, Atlas
teleported through gate_0 and gate_1 with DRCSim's checks' Pose() (an all-zero quaternion);
/vrc_score says completion 1, score.log has the plugin's rows, the bag recorded them, and
the bag's replay scores the same.

Run with `python3 -m pytest test/integration/test_vrc_scoring_live.py -q -s` after
`source env.sh` (needs roslaunch and the workspace's messages; skipped otherwise).
"""

from __future__ import annotations

import shutil
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest

pytest.importorskip('atlas_msgs.msg', reason='needs the catkin workspace: source ./env.sh')
if shutil.which('roslaunch') is None:
    pytest.skip('roslaunch is not on PATH (source env.sh)', allow_module_level=True)

from support.launch import SIM, TestLaunch
from tutorial_atlas_control import topics
from tutorial_atlas_control.bags import read_bag, read_scores
from tutorial_atlas_control.offline.replay import format_report, replay_bag
from tutorial_atlas_control.processes import RosMaster

pytestmark = pytest.mark.filterwarnings('ignore::DeprecationWarning')

#: Pelvis (x, y): before and after gate_0 (x 1, y -38, yaw 0), before and after gate_1
#: (0, -22, yaw 90°), 1 m up.
TELEPORTS = ((0.7, -38.0), (1.3, -38.0), (0.0, -22.3), (0.0, -21.7))
PASSED = ('Successfully passed through gate 1. Starting clock. ',
          'Successfully passed through gate 2. ')


@pytest.fixture
def master(tmp_path: Path) -> Iterator[RosMaster]:
    with RosMaster(tmp_path / 'roscore.log', ros_log_dir=tmp_path / 'ros_log') as core:
        core.wait_online(60.0)
        yield core


def set_param(master: RosMaster, name: str, value: str) -> None:
    done = subprocess.run(['rosparam', 'set', name, value], env=master.env, capture_output=True,
                          text=True, timeout=60, check=False)
    assert done.returncode == 0, done.stderr


def pelvis_xy(launch: TestLaunch) -> tuple[float, float]:
    position = launch.next_message(topics.GROUND_TRUTH_ODOM)['pose']['pose']['position']
    return float(position['x']), float(position['y'])


def test_teleports_through_gate_0_and_gate_1_score_1_live(tmp_path: Path,
                                                          master: RosMaster) -> None:
    score_dir = tmp_path / 'vrc_task_2'
    # The VRC launches set these; atlas.launch leaves them to the master.
    set_param(master, f'{SIM}/vrc_scoring', 'true')
    set_param(master, f'{SIM}/score_dir', str(score_dir))
    with TestLaunch(tmp_path, master=master) as launch:
        launch.wait_ready()
        launch.wait_sim_until(1.5)
        for x_m, y_m in TELEPORTS:
            launch.publish(topics.SET_POSE, 'geometry_msgs/Pose',
                           f'{{position: {{x: {x_m}, y: {y_m}, z: 1.0}}}}')
            # Seen on the odometry, the pose was the scorer's at that step too.
            launch.wait(lambda x_m=x_m, y_m=y_m: max(
                abs(a - b) for a, b in zip(pelvis_xy(launch), (x_m, y_m))) < 0.05, 60.0,
                f'the teleport to ({x_m}, {y_m}) did not happen')
        launch.wait(lambda: launch.next_message(topics.VRC_SCORE)['completion_score'] == 1,
                    60.0, '/vrc_score did not reach completion 1')
        assert 'taken as upright (identity), as Gazebo did' in launch.output()
        launch.wait(lambda: (score_dir / 'score.log').read_text().count(PASSED[1]) == 1, 30.0,
                    'score.log has no row for gate 2')
        launch.interrupt()
    rows = (score_dir / 'score.log').read_text().splitlines()
    assert rows[0] == '# Score data for world vrc_task_2'
    events = [row.split(',', 6) for row in rows[4:] if not row.endswith(',""')]
    assert [(int(row[4]), int(row[5]), row[6]) for row in events] == [
        (0, 0, f'"{PASSED[0]}"'), (1, 0, f'"{PASSED[1]}"')]
    bag = next(launch.bag_dir.glob('*.bag'))
    entries = read_scores(read_bag(bag))
    assert entries is not None
    assert [entry.message for entry in entries if entry.message] == list(PASSED)
    assert entries[-1].completion == 1
    # Replayed offline, the run scores the same, row for row.
    result = replay_bag(bag)
    print(f'figures: replay: {result.recorded_steps} steps, score rows '
          f'{result.score and result.score.line().strip()}')
    assert result.score is not None and result.score.same, result.score
    assert result.reproduced, format_report(result)
