"""traj_yaml.py's start-up against a real ROS master, run as a user would: its errors (exit 1,
one clear line, nothing published on /atlas/joint_commands) and its wait for the simulator.

A private roscore (own port); no simulator, or a fake one (fake_simulator.py) that publishes
joint states and subscribes to the commands late. The gains and timeouts come from the
parameter server.
"""

from __future__ import annotations

import contextlib
import json
import queue
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

from tutorial_atlas_control.processes import (
    RosMaster,
    default_sigint,
    stop_tree,
    system_state,
    wait_until,
)

REPO = Path(__file__).resolve().parents[2]
TRAJ_YAML = REPO / 'scripts' / 'traj_yaml.py'
FAKE_SIMULATOR = Path(__file__).resolve().parent / 'fake_simulator.py'
COMMAND_LISTENER = Path(__file__).resolve().parent / 'command_listener.py'
COMMAND_LISTENER_NODE = '/command_listener'
TRAJECTORIES = REPO / 'trajectories' / 'Traj_data2.yaml'
GAINS = REPO / 'config' / 'atlas_controller.yaml'
MASTER_TIMEOUT_S = 60.0
#: step_and_fall: 4 waypoints of 1 s at 50 Hz.
STEP_AND_FALL_COMMANDS = 200
#: Wall-clock guard (s): how long the fake simulator runs at most.
FAKE_SIMULATOR_GUARD_S = 90.0
#: Wall-clock guard (s): how long the port may take to start playing beside the fake simulator.
PLAYING_TIMEOUT_S = 60.0
#: The positive control's command: one joint position (rad) no trajectory of the file has.
CONTROL_POSITION = 0.123456
#: Wall-clock guard (s): for the listener to subscribe, and to get the latched control
#: message; seconds on a loaded machine.
CONTROL_TIMEOUT_S = 30.0


class Master(RosMaster):
    """A roscore of our own, and commands run against it."""

    def __init__(self, tmp_path: Path) -> None:
        super().__init__(tmp_path / 'roscore.log', ros_log_dir=tmp_path / 'ros_log')

    def run(self, *command: str, timeout_s: float = 60.0) -> subprocess.CompletedProcess:
        return subprocess.run(command, env=self.env, capture_output=True, text=True,
                              timeout=timeout_s, check=False)

    def subscribed(self, node: str) -> bool:
        """Whether the master lists `node` among /atlas/joint_commands' subscribers."""
        try:
            _, subscribers = system_state(self.uri)
        except OSError:
            return False
        return node in subscribers.get('/atlas/joint_commands', [])

    def traj_yaml(self, *ros_args: str) -> tuple[subprocess.CompletedProcess, str]:
        """Run the port on step_and_fall; return its result and what was published meanwhile.

        The listener's subscription is on the master before the port starts (so the port,
        once it advertises, is told of it). Positive control: after the port, a command
        published on purpose must reach the same listener; else a listener that never
        connected would make "nothing was published" pass whatever the port did.
        """
        listener = subprocess.Popen([sys.executable, str(COMMAND_LISTENER)], env=self.env,
                                    stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                    text=True, start_new_session=True,
                                    preexec_fn=default_sigint)
        lines: queue.Queue[str] = queue.Queue()
        reader = threading.Thread(
            target=lambda: [lines.put(line) for line in listener.stdout or ()], daemon=True)
        reader.start()
        heard: list[str] = []
        try:
            wait_until(lambda: self.subscribed(COMMAND_LISTENER_NODE), CONTROL_TIMEOUT_S,
                       'the command listener did not subscribe to /atlas/joint_commands')
            result = self.run(sys.executable, str(TRAJ_YAML), str(TRAJECTORIES),
                              'step_and_fall', *ros_args)
            # Stopped once heard: `rostopic pub -1` would latch 3 s more before exiting.
            control = subprocess.Popen(
                ['rostopic', 'pub', '-1', '/atlas/joint_commands', 'osrf_msgs/JointCommands',
                 f'{{position: [{CONTROL_POSITION}]}}'], env=self.env,
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
                preexec_fn=default_sigint)
            try:
                deadline = time.monotonic() + CONTROL_TIMEOUT_S
                while not any(str(CONTROL_POSITION) in line for line in heard):
                    assert time.monotonic() < deadline, (
                        f'the listener did not hear the control command within '
                        f'{CONTROL_TIMEOUT_S} s: it would not have heard the port\'s either '
                        f'(heard {heard!r}; rostopic pub exit status {control.poll()})')
                    with contextlib.suppress(queue.Empty):
                        heard.append(lines.get(timeout=0.1))
            finally:
                stop_tree(control)
        finally:
            stop_tree(listener)
        before_control = heard[:next(k for k, line in enumerate(heard)
                                     if str(CONTROL_POSITION) in line)]
        return result, ''.join(before_control)


@pytest.fixture()
def master(tmp_path: Path) -> Iterator[Master]:
    with Master(tmp_path) as core:
        core.wait_online(MASTER_TIMEOUT_S)
        yield core


def refusal(master: Master, *ros_args: str) -> str:
    """Run the port; assert it exits 1 with one stderr line and publishes nothing; the line."""
    result, published = master.traj_yaml(*ros_args)
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert result.returncode == 1, result
    assert len(lines) == 1, lines
    assert 'Traceback' not in result.stderr
    assert published == '', f'published while refusing: {published[:200]}'
    return lines[0]


def test_missing_gains_name_the_parameter_and_how_to_load_it(master: Master) -> None:
    line = refusal(master)
    assert 'parameter atlas_controller/gains is not set' in line
    assert 'roslaunch tutorial_atlas_control atlas.launch' in line
    assert 'rosparam load' in line


def test_non_numeric_gain_is_named(master: Master) -> None:
    assert master.run('rosparam', 'load', str(GAINS)).returncode == 0
    assert master.run('rosparam', 'set', '/atlas_controller/gains/l_arm_elx/p',
                      'fast').returncode == 0
    assert 'atlas_controller/gains/l_arm_elx/p' in refusal(master)


def test_no_simulator_times_out_with_a_hint(master: Master) -> None:
    assert master.run('rosparam', 'load', str(GAINS)).returncode == 0
    line = refusal(master, '_joint_state_timeout:=1.5')
    assert 'no simulator is publishing /atlas/joint_states' in line
    assert 'atlas.launch' in line
    assert 'within 1.5 s' in line, 'the ~joint_state_timeout parameter was not used'


def test_bad_timeout_parameter_is_named(master: Master) -> None:
    assert master.run('rosparam', 'load', str(GAINS)).returncode == 0
    line = refusal(master, '_joint_state_timeout:=-1')
    assert '~joint_state_timeout' in line and 'positive number of seconds' in line


def test_bad_subscriber_timeout_is_named_before_any_wait(master: Master) -> None:
    assert master.run('rosparam', 'load', str(GAINS)).returncode == 0
    line = refusal(master, '_subscriber_timeout:=soon')
    assert '~subscriber_timeout' in line and "got 'soon'" in line


def run_with_fake_simulator(master: Master, subscribe_after_s: float,
                            *ros_args: str) -> tuple[subprocess.CompletedProcess, dict]:
    """Run the port on step_and_fall (4 s) beside fake_simulator.py; both results.

    The fake simulator stops on its own once it has all 200 commands; otherwise when the
    port has exited (SIGINT), so that a slow machine only makes the test slower.
    """
    assert master.run('rosparam', 'load', str(GAINS)).returncode == 0
    simulator = subprocess.Popen(
        [sys.executable, str(FAKE_SIMULATOR), '--subscribe-after', str(subscribe_after_s),
         '--until-received', str(STEP_AND_FALL_COMMANDS), '--run-for', str(FAKE_SIMULATOR_GUARD_S)],
        env=master.env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        start_new_session=True)
    try:
        port = master.run(sys.executable, str(TRAJ_YAML), str(TRAJECTORIES), 'step_and_fall',
                          *ros_args)
        if port.returncode != 0:
            simulator.send_signal(signal.SIGINT)
        out, err = simulator.communicate(timeout=FAKE_SIMULATOR_GUARD_S + 30)
    finally:
        stop_tree(simulator)
    assert simulator.returncode == 0, err
    return port, json.loads(out.strip().splitlines()[-1])


def test_a_simulator_that_subscribes_late_gets_every_command(master: Master) -> None:
    """The port waits for the simulator: it used to publish after 2 s and the robot fell."""
    port, simulator = run_with_fake_simulator(master, 3.0)
    assert port.returncode == 0, port.stderr
    assert simulator['received'] == STEP_AND_FALL_COMMANDS, \
        'every command of step_and_fall reached the simulator'
    assert simulator['first_position'] == [0.0] * 28, 'the first command is the measured pose'


def test_a_simulator_that_never_subscribes_is_refused(master: Master) -> None:
    port, simulator = run_with_fake_simulator(master, -1.0, '_subscriber_timeout:=1.5')
    lines = [line for line in port.stderr.splitlines() if line.strip()]
    assert port.returncode == 1, port
    assert 'Traceback' not in port.stderr
    assert len(lines) == 1 \
        and 'nothing subscribed to /atlas/joint_commands within 1.5 s' in lines[0], lines
    assert simulator['received'] == 0


def test_ctrl_c_while_playing_exits_130_without_traceback(master: Master) -> None:
    """Ctrl-C mid-trajectory ends the port with 130, like every script (rospy handles SIGINT)."""
    assert master.run('rosparam', 'load', str(GAINS)).returncode == 0
    simulator = subprocess.Popen(
        [sys.executable, str(FAKE_SIMULATOR), '--subscribe-after', '0',
         '--run-for', str(FAKE_SIMULATOR_GUARD_S)],
        env=master.env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        start_new_session=True, preexec_fn=default_sigint)
    # Its own session, SIGINT at its default even when the suite runs as a background job.
    port = subprocess.Popen(
        [sys.executable, str(TRAJ_YAML), str(TRAJECTORIES), 'step_and_fall'],
        env={**master.env, 'PYTHONUNBUFFERED': '1'}, stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True, start_new_session=True, preexec_fn=default_sigint)
    lines: queue.Queue[str] = queue.Queue()
    threading.Thread(target=lambda: [lines.put(line) for line in port.stdout or ()],
                     daemon=True).start()
    try:
        deadline = time.monotonic() + PLAYING_TIMEOUT_S
        # The port announces the trajectory once it plays.
        while "playing trajectory 'step_and_fall'" not in lines.get(
                timeout=max(0.0, deadline - time.monotonic())):
            pass
        port.send_signal(signal.SIGINT)
        port.wait(timeout=30)
        err = port.stderr.read() if port.stderr else ''
    except queue.Empty:
        pytest.fail(f'traj_yaml.py did not start playing within {PLAYING_TIMEOUT_S} s')
    finally:
        stop_tree(port)
        simulator.send_signal(signal.SIGINT)
        simulator.communicate(timeout=30)
        stop_tree(simulator)
    assert port.returncode == 130, err
    assert 'Traceback' not in err, err
