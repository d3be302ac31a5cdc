"""The benchmark's environment check, its master, and the machine's load figures.

Starting and stopping ROS processes is tutorial_atlas_control.processes (as for the demo
and the tests): every wait is bounded, everything started is stopped, and nothing touches
another developer's master or processes.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.processes import AtlasLaunch, ProcessError, RosMaster

#: Longest wait for the simulator to publish /clock and the recorder to subscribe (s).
READY_TIMEOUT_S = 60.0

REPO_DIR = Path(__file__).resolve().parents[1]


class BenchError(AtlasControlError):
    """The benchmark cannot run; the message says what to do."""


def check_environment() -> None:
    """Fail early, clearly, when `make setup` / `source ./env.sh` has not been done."""
    missing = [tool for tool in ('roscore', 'roslaunch', 'rosbag') if shutil.which(tool) is None]
    if missing:
        raise BenchError(f'{", ".join(missing)} not on PATH; run `make setup` and '
                         '`source ./env.sh` (or just `make bench`)')
    if not os.environ.get('TAC_WS'):
        raise BenchError('the workspace is not sourced; run `make bench`, or '
                         '`source ./env.sh` before `python3 bench/run_bench.py`')
    try:
        import mujoco  # noqa: F401
        import rosbags  # noqa: F401
        import rospy  # noqa: F401
        from osrf_msgs.msg import JointCommands  # noqa: F401
    except ImportError as err:
        raise BenchError(f'cannot import {err.name}; run `make setup` and `source ./env.sh`') \
            from err
    found = subprocess.run(['rospack', 'find', 'tutorial_atlas_control'], capture_output=True,
                           text=True, timeout=30, check=False)
    if found.returncode != 0:
        raise BenchError('rospack cannot find tutorial_atlas_control; run `make setup` '
                         'and `source ./env.sh`')


class Master(RosMaster):
    """The benchmark's roscore: logs and ROS logs under the scratch directory."""

    def __init__(self, work_dir: Path) -> None:
        # PYTHONWARNINGS: rospy's queue_size=None warning in every client.
        super().__init__(work_dir / 'roscore.log', work_dir / 'ros_log',
                         {'PYTHONWARNINGS': 'ignore::SyntaxWarning'})


class Launch(AtlasLaunch):
    """A launch on the benchmark's master; an exit is reported with its log's last lines."""

    def __init__(self, master: Master, launch_file: str, args: dict[str, str],
                 log_path: Path) -> None:
        super().__init__(log_path, args, master=master, launch_file=launch_file)

    def check_running(self) -> None:
        try:
            super().check_running()
        except ProcessError as err:
            raise BenchError(f'{err}; its last lines:\n{self.tail()}') from None

    def node_pid(self, name: str) -> int | None:
        """Pid of the launched node `__name:=name`."""
        return self.pid_of(f'__name:={name} ')


def load_average() -> str:
    try:
        return ' '.join(Path('/proc/loadavg').read_text().split()[:3])
    except OSError:
        return '?'


def cpu_stat() -> list[int]:
    """The machine's aggregate CPU jiffies from /proc/stat (user ... steal)."""
    try:
        return [int(v) for v in Path('/proc/stat').read_text().split('\n', 1)[0].split()[1:9]]
    except (OSError, ValueError):
        return [0] * 8


def busy_and_steal(before: list[int], after: list[int]) -> tuple[float, float]:
    """(busy %, steal %) of all CPUs between two cpu_stat() readings.

    Steal is time the hypervisor gave our virtual CPUs to someone else: other tenants'
    load that `uptime` inside this machine does not show.
    """
    delta = [b - a for a, b in zip(before, after)]
    total = sum(delta) or 1
    idle = delta[3] + delta[4]
    return 100.0 * (total - idle - delta[7]) / total, 100.0 * delta[7] / total


def log(text: str) -> None:
    print(f'[bench {time.strftime("%H:%M:%S")}] {text}', file=sys.stderr, flush=True)
