"""An offline run (run_offline.py) reaches the outcome of the live run (`make demo`) it stands for.

The live run is run_demo.py's step_and_fall, the demo_run every test of the demo shares
(conftest.py, at 0.25x), compared with the offline run of the same trajectory, aligned on the
first applied command (bags/compare.py). Transport and scheduling move a live run a little
(the trajectory starts from a pose the robot held longer, commands arrive 1-2 ms late), so
only the outcome must agree: the robot falls in both, within FALL_TOLERANCE_S. The other
trajectories are held live to the offline figures elsewhere, at no live run of their own
here: touchdown_exhausted's fall within 0.6 s of the README's offline 6.837 s and touchdown's
stand (their rostests, test_tutorial_run.py; the three tries), touchdown offline
(test_sweep.py, test_arm_tracking.py).
"""

from __future__ import annotations

import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

from tutorial_atlas_control.bags.analysis import analyze_bag
from tutorial_atlas_control.bags.compare import (
    compare_bags,
    first_applied_command_s,
    format_comparison,
)
from tutorial_atlas_control.offline.player import run_offline

REPO = Path(__file__).resolve().parents[2]
TRAJECTORIES = REPO / 'trajectories' / 'Traj_data2.yaml'
#: Largest difference (s) between the live and the offline fall time, from the first command.
FALL_TOLERANCE_S = 0.3


@dataclass(frozen=True)
class LiveRun:
    result: subprocess.CompletedProcess
    bag: Path


@pytest.fixture(scope='module')
def step_and_fall_run(demo_run) -> LiveRun:  # demo_run: conftest.DemoRun, at 0.25x as here
    return LiveRun(demo_run.result, demo_run.bag)


def test_offline_run_reaches_the_live_outcome(step_and_fall_run: LiveRun,
                                              tmp_path: Path) -> None:
    trajectory, falls, live = 'step_and_fall', True, step_and_fall_run
    assert live.result.returncode == 0, live.result.stdout + live.result.stderr
    # The offline run on the live run's schedule: User and the first command at the same sim
    # times (traj_yaml.py's start-up after the switch depends on how busy the machine is).
    live_analysis = analyze_bag(live.bag)
    user_s = next(t_s for t_s, mode in live_analysis.data.modes if mode == 'User')
    start_s = live_analysis.data.start_time_s
    offline = run_offline(str(TRAJECTORIES), trajectory, tmp_path / f'{trajectory}.bag',
                          start_after_s=start_s + user_s,
                          play_after_s=first_applied_command_s(live_analysis) - user_s)
    comparison = compare_bags(live.bag, offline.bag)
    print(format_comparison(comparison))  # the figures, with pytest -s
    assert comparison.trajectory_a is not None and comparison.trajectory_a.name == trajectory
    assert comparison.trajectory_b is not None and comparison.trajectory_b.name == trajectory
    assert comparison.a.fell is falls and comparison.b.fell is falls
    if falls:
        assert abs(comparison.fall_time_diff_s) <= FALL_TOLERANCE_S
