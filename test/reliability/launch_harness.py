"""atlas.launch as the reliability tests drive it: its own master, its own bag directory.

Each test starts the real launch (roscore, the simulator, the recorder), injects a fault from outside (signals, floods, bad files) and judges the outcome
from the processes and from the recorded bag, as a user would afterwards.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import rosgraph

from tutorial_atlas_control.demo import alive, descendants, free_local_port, stop

HERE = Path(__file__).resolve().parent
FLOOD = HERE / 'flood_commands.py'
#: Wall-clock bounds (s).
STARTUP_TIMEOUT_S = 60.0
EXIT_TIMEOUT_S = 30.0


def command_line(pid: int) -> str:
    try:
        return (Path('/proc') / str(pid) / 'cmdline').read_bytes().replace(b'\0', b' ').decode()
    except OSError:
        return ''


def rss_kib(pid: int) -> int:
    for line in (Path('/proc') / str(pid) / 'status').read_text().splitlines():
        if line.startswith('VmRSS:'):
            return int(line.split()[1])
    raise AssertionError(f'no VmRSS for pid {pid}')


class AtlasLaunch:
    """One `roslaunch tutorial_atlas_control atlas.launch` run, and what it left behind."""

    def __init__(self, tmp_path: Path, *args: str) -> None:
        self.port = free_local_port()
        self.bag_dir = tmp_path / 'bags'
        self.log_path = tmp_path / 'atlas_launch.log'
        self.env = dict(os.environ, ROS_MASTER_URI=f'http://localhost:{self.port}',
                        ROS_HOSTNAME='localhost', ROS_LOG_DIR=str(tmp_path / 'ros_log'))
        self._log = open(self.log_path, 'w')  # noqa: SIM115 - closed in close()
        self.process = subprocess.Popen(
            ['roslaunch', '-p', str(self.port), 'tutorial_atlas_control', 'atlas.launch',
             'gui:=false', f'bag_dir:={self.bag_dir}', *args],
            env=self.env, stdout=self._log, stderr=subprocess.STDOUT, start_new_session=True)

    # -- processes ------------------------------------------------------------------------
    def pids(self) -> list[int]:
        """roslaunch and everything it started that still runs."""
        return alive([self.process.pid, *descendants(self.process.pid)])

    def pid_of(self, fragment: str) -> int:
        """The launch's process whose command line contains `fragment`."""
        found = [pid for pid in self.pids() if fragment in command_line(pid)]
        assert found, f'no process running {fragment!r} in the launch; see {self.log_path}'
        return found[0]

    def output(self) -> str:
        self._log.flush()
        return self.log_path.read_text(errors='replace')

    def wait_ready(self) -> None:
        """Until the simulator and the recorder are both subscribed to the commands."""
        master = rosgraph.Master('/reliability_test', master_uri=self.env['ROS_MASTER_URI'])
        deadline = time.monotonic() + STARTUP_TIMEOUT_S
        while True:
            try:
                _, subscribers, _ = master.getSystemState()
                nodes = dict(subscribers).get('/atlas/joint_commands', [])
                if '/atlas_sim' in nodes and '/recorder' in nodes:
                    return
            except OSError:
                pass  # the master is not up yet
            if self.process.poll() is not None:
                pytest.fail(f'atlas.launch exited early:\n{self.output()}')
            if time.monotonic() > deadline:
                pytest.fail(f'atlas.launch not ready within {STARTUP_TIMEOUT_S} s:\n'
                            f'{self.output()}')
            time.sleep(0.2)

    def wait_exit(self, timeout_s: float = EXIT_TIMEOUT_S) -> int:
        try:
            return self.process.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            pytest.fail(f'atlas.launch did not exit within {timeout_s} s:\n{self.output()}')

    def interrupt(self) -> float:
        """SIGINT, as Ctrl-C; return the seconds until every process of the launch is gone."""
        pids = self.pids()  # before: once roslaunch is gone, its orphans have no parent link
        started_s = time.monotonic()
        self.process.send_signal(signal.SIGINT)
        while alive(pids) and time.monotonic() - started_s < EXIT_TIMEOUT_S:
            time.sleep(0.02)
        gone_s = time.monotonic() - started_s
        self.process.wait(timeout=EXIT_TIMEOUT_S)
        return gone_s

    def close(self) -> None:
        stop(self.process, 'roslaunch')
        self._log.close()

    # -- helpers run against this launch's master ----------------------------------------
    def run(self, *command: str, timeout_s: float = 60.0) -> subprocess.CompletedProcess:
        return subprocess.run(command, env=self.env, capture_output=True, text=True,
                              timeout=timeout_s, check=False)

    def set_mode(self, mode: str) -> None:
        """The tutorial's `rostopic pub /atlas/control_mode std_msgs/String -- User`."""
        result = self.run('rostopic', 'pub', '-1', '/atlas/control_mode', 'std_msgs/String',
                          '--', mode)
        assert result.returncode == 0, result.stderr

    def start_flood(self, *args: str) -> subprocess.Popen:
        return subprocess.Popen([sys.executable, str(FLOOD), *args],
                                env=self.env,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    # -- the recording -------------------------------------------------------------------
    def bag(self) -> Path:
        """The run's one bag: closed (no .active left) and alone in its directory."""
        active = sorted(self.bag_dir.glob('*.active'))
        assert not active, f'the recorder left {[p.name for p in active]} unclosed'
        bags = sorted(self.bag_dir.glob('atlas_*.bag'))
        assert len(bags) == 1, f'expected one bag in {self.bag_dir}, found {bags}'
        return bags[0]


def flood_figures(process: subprocess.Popen, timeout_s: float) -> dict:
    """Wait for a flood_commands.py and return its JSON figures."""
    stdout, stderr = process.communicate(timeout=timeout_s)
    assert process.returncode == 0, f'flood_commands.py failed:\n{stderr}'
    return json.loads(stdout.strip().splitlines()[-1])
