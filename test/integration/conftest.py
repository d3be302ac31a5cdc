"""One recorded tutorial run, shared by the integration tests (recording takes ~30-60 s)."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
RUN_DEMO = REPO / 'scripts' / 'run_demo.py'
#: Wall-clock guard against a hung recording (s): far beyond the ~30 s it takes, as the
#: tests run niced beside other work (a niced process gets ~1/10 of a busy core's share).
DEMO_TIMEOUT_S = 900


#: The environment a ROS client reads its master from.
ROS_ENVIRONMENT = ('ROS_MASTER_URI', 'ROS_HOSTNAME', 'ROS_IP')


@pytest.fixture(autouse=True)
def ros_state_left_as_found() -> Iterator[None]:
    """Each test leaves this process's ROS state as it found it: no rospy node (one per
    process, never shut down for good) and the same ROS environment, so that no later test
    depends on the order the tests ran in. A test needing a node runs it in a subprocess."""
    before = {name: os.environ.get(name) for name in ROS_ENVIRONMENT}
    yield
    after = {name: os.environ.get(name) for name in ROS_ENVIRONMENT}
    assert after == before, f'the test changed this process\'s ROS environment: {after}'
    rospy = sys.modules.get('rospy')
    assert rospy is None or not rospy.core.is_initialized(), \
        'the test started a rospy node in the pytest process'


@dataclass(frozen=True)
class DemoRun:
    """`run_demo.py step_and_fall` as run by the tests: its output and its bag directory."""

    result: subprocess.CompletedProcess
    bag_dir: Path

    @property
    def bag(self) -> Path:
        bags = sorted(self.bag_dir.glob('atlas_*.bag'))
        assert bags, f'run_demo.py left no bag in {self.bag_dir}:\n{self.result.stderr}'
        return bags[-1]


#: The demo's pace: at a quarter of real time a busy machine's late commands matter a quarter
#: as much in sim time (test_offline_vs_live.py compares its fall with the offline run's: at
#: half real time, beside make test's parallel part, the live fall came 0.32 s before the
#: offline one, past its 0.3 s; touchdown_exhausted's run is at a quarter for the same reason).
DEMO_REAL_TIME_FACTOR = 0.25


@pytest.fixture(scope='session')
def demo_run(tmp_path_factory: pytest.TempPathFactory) -> DemoRun:
    """`run_demo.py step_and_fall` at DEMO_REAL_TIME_FACTOR, recording (and its plot and video)."""
    pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')
    bag_dir = tmp_path_factory.mktemp('demo')
    env = dict(os.environ, ROS_LOG_DIR=str(bag_dir / 'ros_log'))
    result = subprocess.run(
        [sys.executable, str(RUN_DEMO), 'step_and_fall', '--bag-dir', str(bag_dir),
         '--real-time-factor', str(DEMO_REAL_TIME_FACTOR)],
        env=env, capture_output=True, text=True, timeout=DEMO_TIMEOUT_S, check=False)
    return DemoRun(result, bag_dir)

