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

import os
import shutil
import subprocess
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

rospy = pytest.importorskip('rospy')
osrf_msgs = pytest.importorskip('osrf_msgs.msg', reason='osrf_msgs is not built (source env.sh)')
if shutil.which('roslaunch') is None or shutil.which('rosbag') is None:
    pytest.skip('roslaunch/rosbag are not on PATH (source env.sh)', allow_module_level=True)

from nav_msgs.msg import Odometry  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402

from tutorial_atlas_control.processes import AtlasLaunch, ProcessError, wait_until  # noqa: E402

#: rospy (Debian's 1.15) uses the deprecated Condition.notifyAll on every /clock message.
pytestmark = pytest.mark.filterwarnings('ignore::DeprecationWarning')

REPO = Path(__file__).resolve().parents[2]
TRAJECTORY = 'step_and_fall'
FALLEN_BELOW_M = 0.5
STANDING_ABOVE_M = 0.8
#: Wall-clock guards against hangs (s), far beyond what a loaded machine takes.
STARTUP_TIMEOUT_S = 120.0
PLAY_TIMEOUT_S = 120.0
FALL_TIMEOUT_S = 60.0
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


class Probe:
    """Test-side subscriptions: sim time, pelvis height, arrival of played commands."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.clock_s = 0.0
        self.min_z_m = float('inf')
        self.z_m: float | None = None
        self.command_arrivals_s: list[float] = []
        self.command_stamps_s: list[float] = []
        self.subscribers = [
            rospy.Subscriber('/clock', Clock, self._on_clock, queue_size=10),
            rospy.Subscriber('/ground_truth_odom', Odometry, self._on_odom, queue_size=10),
            rospy.Subscriber('/atlas/joint_commands', osrf_msgs.JointCommands, self._on_command,
                             queue_size=100),
        ]

    def _on_clock(self, msg: Clock) -> None:
        with self.lock:
            self.clock_s = msg.clock.to_sec()

    def _on_odom(self, msg: Odometry) -> None:
        with self.lock:
            self.z_m = msg.pose.pose.position.z
            self.min_z_m = min(self.min_z_m, self.z_m)

    def _on_command(self, msg: object) -> None:
        with self.lock:
            self.command_arrivals_s.append(self.clock_s)
            self.command_stamps_s.append(msg.header.stamp.to_sec())

    def close(self) -> None:
        for subscriber in self.subscribers:
            subscriber.unregister()

    def wait_for(self, condition: object, timeout_s: float, what: str,
                 process: subprocess.Popen | None = None) -> None:
        def holds() -> bool:
            with self.lock:
                return condition(self)

        def launch_running() -> None:
            if process is not None and process.poll() is not None:
                pytest.fail(f'{what}: roslaunch exited early (status {process.returncode})')

        try:
            wait_until(holds, timeout_s, f'{what}: not reached', launch_running)
        except ProcessError as err:
            pytest.fail(str(err))


@pytest.fixture()
def fresh_simulator(tmp_path: Path) -> Iterator[tuple[dict[str, str], Probe, subprocess.Popen]]:
    """atlas.launch (no recording) on its own master; a probe node in this process."""
    with AtlasLaunch(tmp_path / 'atlas_launch.log', {'gui': 'false', 'record': 'false'},
                     ros_log_dir=tmp_path / 'ros_log') as launch:
        os.environ['ROS_MASTER_URI'] = launch.uri
        os.environ['ROS_HOSTNAME'] = launch.env['ROS_HOSTNAME']
        launch.wait_master(STARTUP_TIMEOUT_S)
        rospy.init_node('replay_live_probe', anonymous=True, disable_signals=True)
        probe = Probe()
        try:
            yield launch.env, probe, launch.process
        finally:
            probe.close()
            rospy.signal_shutdown('live replay test done')


def test_played_commands_make_the_robot_fall(
        recorded_bag: Path,
        fresh_simulator: tuple[dict[str, str], Probe, subprocess.Popen]) -> None:
    from tutorial_atlas_control.bags.analysis import analyze_bag

    recorded = analyze_bag(recorded_bag)
    assert recorded.fell, f'the recorded run did not fall: {recorded_bag}'
    assert recorded.data.commands is not None and len(recorded.data.commands.t_s)
    recorded_span_s = float(recorded.data.commands.t_s[-1] - recorded.data.commands.t_s[0])

    env, probe, launch = fresh_simulator
    probe.wait_for(lambda p: p.clock_s >= 1.0 + PLAY_AFTER_S and p.z_m is not None,
                   STARTUP_TIMEOUT_S, 'simulator start', launch)
    assert probe.z_m > STANDING_ABOVE_M, 'the fresh robot is not standing before the replay'
    play = subprocess.run(
        ['rosbag', 'play', '--quiet', '--wait-for-subscribers', str(recorded_bag),
         '--topics', '/atlas/control_mode', '/atlas/joint_commands'],
        env=env, capture_output=True, text=True, timeout=PLAY_TIMEOUT_S, check=False)
    assert play.returncode == 0, f'rosbag play failed:\n{play.stdout}\n{play.stderr}'
    with probe.lock:
        played_until_s = probe.clock_s
    probe.wait_for(lambda p: p.min_z_m < FALLEN_BELOW_M
                   or p.clock_s > played_until_s + FALL_WINDOW_S,
                   FALL_TIMEOUT_S, 'fall watch', launch)
    with probe.lock:
        arrivals = list(probe.command_arrivals_s)
        min_z_m = probe.min_z_m
    assert len(arrivals) == len(recorded.data.commands.t_s), 'commands were lost in playback'
    played_span_s = arrivals[-1] - arrivals[0]
    print(f'\nlive replay of {recorded_bag.name}: {len(arrivals)} commands arrived over '
          f'{played_span_s:.2f} s of sim time (recorded over {recorded_span_s:.2f} s), '
          f'first at {arrivals[0]:.2f} s; lowest pelvis height {min_z_m:.2f} m')
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
