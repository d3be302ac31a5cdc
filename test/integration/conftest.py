"""One recorded tutorial run, shared by the integration tests (recording takes ~30-60 s)."""

from __future__ import annotations

import os
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
RUN_DEMO = REPO / 'scripts' / 'run_demo.py'
#: Wall-clock guard against a hung recording (s): far beyond the ~30 s it takes, as the
#: tests run niced beside other work (a niced process gets ~1/10 of a busy core's share).
DEMO_TIMEOUT_S = 900


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


@pytest.fixture(scope='session')
def demo_run(tmp_path_factory: pytest.TempPathFactory) -> DemoRun:
    pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')
    bag_dir = tmp_path_factory.mktemp('demo')
    env = dict(os.environ, ROS_LOG_DIR=str(bag_dir / 'ros_log'))
    result = subprocess.run(
        [sys.executable, str(RUN_DEMO), 'step_and_fall', '--bag-dir', str(bag_dir)],
        env=env, capture_output=True, text=True, timeout=DEMO_TIMEOUT_S, check=False)
    return DemoRun(result, bag_dir)
