"""atlas.launch as the integration and reliability tests drive it: its own master, bag
directory and ROS log directory under the test's tmp_path.

Each test starts the real launch (roscore, the simulator, the recorder), injects a fault
or a load from outside (signals, floods, bad files) and judges the outcome from the
processes and from the recorded bag, as a user would afterwards. Waits fail the test
with the launch's output; they are bounded in wall time only as guards against hangs.
"""

from __future__ import annotations

import json
import select
import subprocess
import sys
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pytest

from tutorial_atlas_control import processes

REPO = Path(__file__).resolve().parents[2]
FLOOD = REPO / 'tools' / 'flood_commands.py'
TALKER = Path(__file__).resolve().with_name('ros_talker.py')
SIM, RECORDER = '/atlas_sim', '/recorder'
#: Wall-clock guards (s): far beyond what any step takes on a loaded machine.
STARTUP_TIMEOUT_S = 120.0
EXIT_TIMEOUT_S = 60.0
SIM_TIME_TIMEOUT_S = 120.0
#: wait_sim_time's guard (s): it also waits for the master and the simulator to start.
WAIT_SIM_TIME_TIMEOUT_S = 180.0


class Talker:
    """ros_talker.py against one master: publishes and reads topics in milliseconds."""

    def __init__(self, env: Mapping[str, str], log_path: Path) -> None:
        self.log_path = log_path
        with log_path.open('a') as log:
            self.process = subprocess.Popen(
                [sys.executable, '-u', str(TALKER)], env=dict(env), stdin=subprocess.PIPE,
                stdout=subprocess.PIPE, stderr=log, text=True)

    def ask(self, answer_within_s: float, **request: Any) -> dict[str, Any]:
        """One request, its reply; fails the test on an error or after `answer_within_s`."""
        assert self.process.stdin is not None and self.process.stdout is not None
        self.process.stdin.write(json.dumps(request) + '\n')
        self.process.stdin.flush()
        ready, _, _ = select.select([self.process.stdout], [], [], answer_within_s)
        line = self.process.stdout.readline() if ready else ''
        if not line:
            pytest.fail(f'ros_talker.py did not answer {request} within {answer_within_s:.0f} s; '
                        f'see {self.log_path}')
        reply = json.loads(line)
        if 'error' in reply:
            pytest.fail(f'ros_talker.py: {request}: {reply["error"]}')
        return reply

    def close(self) -> None:
        if self.process.stdin is not None and not self.process.stdin.closed:
            self.process.stdin.close()
        try:
            self.process.wait(timeout=10.0)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


class TestLaunch(processes.AtlasLaunch):
    """One `roslaunch tutorial_atlas_control atlas.launch` run, and what it left behind."""

    __test__ = False  # not a test class, whatever pytest's name rules say

    def __init__(self, tmp_path: Path, *args: str,
                 base_env: Mapping[str, str] | None = None,
                 launch_file: str = 'atlas.launch',
                 master: processes.RosMaster | None = None) -> None:
        self.bag_dir = tmp_path / 'bags'
        launch_args = {'gui': 'false', 'bag_dir': str(self.bag_dir)}
        launch_args.update(arg.split(':=', 1) for arg in args)
        super().__init__(tmp_path / 'atlas_launch.log', launch_args,
                         ros_log_dir=tmp_path / 'ros_log', base_env=base_env,
                         launch_file=launch_file, master=master)
        self._talker: Talker | None = None
        self._talker_log = tmp_path / 'ros_talker.log'

    # -- processes ------------------------------------------------------------------------
    def pid_of(self, fragment: str) -> int:
        """The launch's process whose command line contains `fragment`."""
        pid = super().pid_of(fragment)
        assert pid is not None, f'no process running {fragment!r}; see {self.log_path}'
        return pid

    def wait(self, condition: object, timeout_s: float, failure: str) -> None:
        """processes.wait_until, failing the test with the launch's output."""
        try:
            processes.wait_until(condition, timeout_s, failure, self.check_running)
        except processes.ProcessError as err:
            pytest.fail(f'{err}:\n{self.output()}')

    def wait_ready(self) -> None:
        """Until the simulator and the recorder are both subscribed to the commands, and
        the recorder is connected to every topic of the simulator's it records."""
        self.wait(lambda: {SIM, RECORDER} <= set(
            self.subscribers('/atlas/joint_commands')), STARTUP_TIMEOUT_S,
            'atlas.launch was not ready')
        self.wait(lambda: self.unrecorded_topics() == [], STARTUP_TIMEOUT_S,
                  f'the recorder was not connected to all of {SIM}\'s topics')

    def unrecorded_topics(self) -> list[str] | None:
        """The simulator's topics the recorder subscribes to but has no connection to yet
        (the simulator's getBusInfo, what `rosnode info` shows); None while unknown."""
        caller = '/tutorial_atlas_control_tests'
        try:
            publishers, subscribers = processes.system_state(self.uri)
            code, _, bus = processes.node_api(self.uri, SIM, caller).getBusInfo(caller)
        except OSError:
            return None
        recorded = {topic for topic, nodes in publishers.items()
                    if SIM in nodes and RECORDER in subscribers.get(topic, [])}
        if code != 1 or not recorded:
            return None
        connected = {row[4] for row in bus if row[1] == RECORDER and row[2] == 'o'}
        return sorted(recorded - connected)

    def interrupt(self, timeout_s: float = processes.STOP_TIMEOUT_S) -> float:
        self.close_talker()  # not a node of the launch: it would outlive the master
        return super().interrupt(timeout_s)

    def close(self, timeout_s: float = processes.STOP_TIMEOUT_S) -> bool:
        self.close_talker()
        return super().close(timeout_s)

    def wait_exit(self, timeout_s: float = EXIT_TIMEOUT_S) -> int:
        try:
            return self.process.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            pytest.fail(f'atlas.launch did not exit within {timeout_s} s:\n{self.output()}')

    # -- helpers run against this launch's master ----------------------------------------
    def run(self, *command: str, timeout_s: float = 60.0) -> subprocess.CompletedProcess:
        return subprocess.run(command, env=self.env, capture_output=True, text=True,
                              timeout=timeout_s, check=False)

    @property
    def talker(self) -> Talker:
        """This launch's ros_talker.py, started at its first use."""
        if self._talker is None:
            self._talker = Talker(self.env, self._talker_log)
        return self._talker

    def close_talker(self) -> None:
        """Stop the talker (the next use starts a new client, as a new `rostopic` would)."""
        if self._talker is not None:
            self._talker.close()
            self._talker = None

    def publish(self, topic: str, msg_type: str, yaml_text: str) -> None:
        """`rostopic pub -1 topic msg_type -- yaml_text`, once every subscriber is connected."""
        self.talker.ask(SIM_TIME_TIMEOUT_S, do='publish', topic=topic, type=msg_type,
                        yaml=yaml_text)

    def next_message(self, topic: str) -> dict[str, Any]:
        """The next message on `topic`, as `rostopic echo -n 1` prints it (a YAML mapping)."""
        return self.talker.ask(SIM_TIME_TIMEOUT_S + 5.0, do='next', topic=topic,
                               timeout_s=SIM_TIME_TIMEOUT_S)['message']

    def set_mode(self, mode: str) -> None:
        """The tutorial's `rostopic pub /atlas/control_mode std_msgs/String -- User`."""
        self.publish('/atlas/control_mode', 'std_msgs/String', mode)

    def sim_time_s(self) -> float:
        """The simulator's clock now (s), from one /clock message."""
        clock = self.next_message('/clock')['clock']
        return int(clock['secs']) + int(clock['nsecs']) * 1e-9

    def wait_sim_until(self, until_s: float) -> None:
        """Until the simulator's clock reaches `until_s`: at any speed of the machine.

        Sleeps the sim time still to go between readings: at real_time_factor <= 1 a sim
        second takes at least a wall second.
        """
        deadline = time.monotonic() + SIM_TIME_TIMEOUT_S
        while (now_s := self.sim_time_s()) < until_s:
            self.check_running()
            if time.monotonic() > deadline:
                pytest.fail(f'sim time {now_s:.1f} s did not reach {until_s:.1f} s within '
                            f'{SIM_TIME_TIMEOUT_S:.0f} s:\n{self.output()}')
            time.sleep(max(0.05, until_s - now_s))

    def wait_sim_s(self, seconds: float) -> None:
        """Until `seconds` of sim time have passed."""
        self.wait_sim_until(self.sim_time_s() + seconds)

    def start_flood(self, *args: str) -> subprocess.Popen:
        return subprocess.Popen([sys.executable, str(FLOOD), *args], env=self.env,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    # -- the recording -------------------------------------------------------------------
    def bag(self) -> Path:
        """The run's one bag: closed (no .active left) and alone in its directory."""
        active = sorted(self.bag_dir.glob('*.active'))
        assert not active, f'the recorder left {[p.name for p in active]} unclosed'
        bags = sorted(self.bag_dir.glob('atlas_*.bag'))
        assert len(bags) == 1, f'expected one bag in {self.bag_dir}, found {bags}'
        return bags[0]


WAIT_SIM_TIME = '''
import sys, rospy
from rosgraph_msgs.msg import Clock
rospy.init_node('wait_sim_time', anonymous=True, disable_signals=True)
target = float(sys.argv[1])
while rospy.wait_for_message('/clock', Clock, timeout=120).clock.to_sec() < target:
    pass
'''


def wait_sim_time(env: dict[str, str], seconds: float) -> None:
    """Until the /clock of the master in `env` reaches `seconds` of sim time: for a launch
    started by hand (a GUI one, with its own environment) rather than as a TestLaunch."""
    subprocess.run([sys.executable, '-c', WAIT_SIM_TIME, str(seconds)], env=env, check=True,
                   timeout=WAIT_SIM_TIME_TIMEOUT_S, capture_output=True)


def flood_figures(process: subprocess.Popen, timeout_s: float) -> dict:
    """Wait for a flood_commands.py and return its JSON figures."""
    stdout, stderr = process.communicate(timeout=timeout_s)
    assert process.returncode == 0, f'flood_commands.py failed:\n{stderr}'
    return json.loads(stdout.strip().splitlines()[-1])
