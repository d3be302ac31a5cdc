"""vrc_task_2.launch live, headless (gzname:=gzserver): Atlas starts in the course's pen as
the VRC started it (bdi_stand: pinned, released at 1 s, the balancing Stand at 2 s) and
stands on the course's ground, scored (/vrc_score latched: no gate, no fall) and recorded;
from a start in the pen's opening, the course walker (vrc_walker.py --to gate_0) walks
through gate_0, the scorer's clock starts and nobody falls.

Run with `python3 -m pytest test/integration/test_vrc_launch_live.py -q -s` after
`source env.sh` (needs roslaunch and the workspace's messages; skipped otherwise).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

pytest.importorskip('atlas_msgs.msg', reason='needs the catkin workspace: source ./env.sh')
if shutil.which('roslaunch') is None:
    pytest.skip('roslaunch is not on PATH (source env.sh)', allow_module_level=True)

from support.launch import TestLaunch
from tutorial_atlas_control import topics
from tutorial_atlas_control.bags import read_bag, read_scores
from tutorial_atlas_control.course import STARTS

pytestmark = pytest.mark.filterwarnings('ignore::DeprecationWarning')

#: Sim time the robot must stand to (s): 4 s of the balancing Stand after its take-over.
STAND_UNTIL_S = 6.0
#: The course's ground in the pen (m): the heightfield's flat level.
PEN_GROUND_M = 0.03
#: Standing, the pelvis is about 0.91 m over the ground; fallen, under 0.5.
UPRIGHT_OVER_GROUND_M = 0.8
#: Most tilt of the pelvis's z axis from vertical, standing (its z axis's world z).
MIN_UP_Z = 0.98


def test_the_course_launch_stands_the_robot_in_the_pen_scored(tmp_path: Path) -> None:
    score_dir = tmp_path / 'vrc_task_2'
    with TestLaunch(tmp_path, 'gzname:=gzserver', 'course_markers:=false',
                    f'score_dir:={score_dir}', launch_file='vrc_task_2.launch') as launch:
        launch.wait_ready()
        launch.wait_sim_until(STAND_UNTIL_S)
        pose = launch.next_message(topics.GROUND_TRUTH_ODOM)['pose']['pose']
        score = launch.next_message(topics.VRC_SCORE)
        launch.interrupt()
    position, turn = pose['position'], pose['orientation']
    up_z = 1.0 - 2.0 * (float(turn['x']) ** 2 + float(turn['y']) ** 2)
    pen = STARTS['vrc_task_2']
    print(f'figures: pelvis at ({position["x"]:.3f}, {position["y"]:.3f}, {position["z"]:.3f}), '
          f'up z {up_z:.4f}; /vrc_score completion {score["completion_score"]}, '
          f'falls {score["falls"]}')
    assert float(position['z']) - PEN_GROUND_M > UPRIGHT_OVER_GROUND_M
    assert up_z > MIN_UP_Z
    assert abs(float(position['x']) - pen.x_m) < 0.1 and abs(float(position['y']) - pen.y_m) < 0.1
    assert (score['completion_score'], score['falls']) == (0, 0)
    assert (score_dir / 'score.log').read_text().startswith('# Score data for world vrc_task_2')
    bag = next(launch.bag_dir.glob('*.bag'))
    entries = read_scores(read_bag(bag))
    assert entries and entries[-1].falls == 0


#: A start in the pen's opening, 0.7 m before gate_0 (x 1), facing it: the walker's leg to
#: gate_0 is then 9 strides, about 7 s of walking.
NEAR_GATE_0 = '0.3 -38.0 1.1 0.0'
#: The walker starts once Stand has balanced a second (it takes over at 2 s).
WALK_FROM_S = 3.0


def test_the_course_walker_walks_through_gate_0_scored_without_a_fall(tmp_path: Path) -> None:
    score_dir = tmp_path / 'vrc_task_2'
    with TestLaunch(tmp_path, 'gzname:=gzserver', 'course_markers:=false',
                    f'score_dir:={score_dir}', f'start:={NEAR_GATE_0}',
                    launch_file='vrc_task_2.launch') as launch:
        launch.wait_ready()
        launch.wait_sim_until(WALK_FROM_S)
        walked = launch.run('rosrun', 'tutorial_atlas_control', 'vrc_walker.py', '--to',
                            'gate_0', '--timeout', '240', timeout_s=300.0)
        pose = launch.next_message(topics.GROUND_TRUTH_ODOM)['pose']['pose']
        launch.interrupt()
    print(walked.stdout, walked.stderr)
    assert walked.returncode == 0, walked.stderr
    lines = walked.stdout.splitlines()
    assert lines[0] == 'vrc_walker.py: from (0.30, -38.00): gate_0'
    assert any(line.endswith('Successfully passed through gate 1. Starting clock.')
               for line in lines), lines
    assert lines[-1].startswith('vrc_walker.py: score: completion 0 of 4, falls 0, ')
    position = pose['position']
    assert float(position['x']) == pytest.approx(1.6, abs=0.15)  # the leg's end, past the gate
    assert float(position['z']) - PEN_GROUND_M > UPRIGHT_OVER_GROUND_M
