"""The benchmark's runs that time whole scenarios: the node under a load of commands, and
the tutorial itself.

load run:     the node at real_time_factor:=1.0 with the launch's default recorder
              (atlas_recorder), in User mode, while 3 tools/flood_commands.py publishers
              each send 2 kHz of valid 28-joint commands for 30 s (what the reliability
              test test_flood_and_load.py applies, where only speed-independent outcomes
              are asserted). Each publisher reports sim time advanced / wall time over its
              own window; the simulator's resident memory is read every second, from
              a baseline taken once every publisher has reported that its flood began.
tutorial run: `run_demo.py step_and_fall --video-fps 0` (its own master), then the rate of
              the port's commands in sim time, from the recorded bag, the share of the
              recorded /atlas/controller_statistics windows whose command ages are at
              their closed form (closed_form_share: a port that keeps up), and the bag's
              size per minute of sim time (its bytes / the span of its bag times, which
              are sim times): MB are 10^6 bytes.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from harness import READY_TIMEOUT_S, REPO_DIR, BenchError, Launch, Master
from online import Probes, recorded_fraction

from tutorial_atlas_control.node.transport import subscriber_names
from tutorial_atlas_control.processes import STOP_TIMEOUT_S, rss_kib, wait_until
from tutorial_atlas_control.units import NS_PER_S

FLOOD = REPO_DIR / 'tools' / 'flood_commands.py'
RUN_DEMO = REPO_DIR / 'scripts' / 'run_demo.py'
LOAD_PUBLISHERS = 3
LOAD_RATE_HZ = 2000.0
#: Sim time (s) the floods start at: after the torso is released (time_to_unpin 1 s).
LOAD_START_SIM_S = 2.0
#: Wall time (s) after the last flood reported its start before the baseline memory
#: reading: every flood's commands are then arriving (2 kHz each) and the simulator's
#: connections to them and its per-message buffers exist, so growth counts only what the
#: flood keeps adding.
LOAD_SETTLE_S = 1.0
#: What flood_commands.py prints on stderr when its flood begins.
FLOOD_STARTED = 'flood_commands.py: started'
#: Longest wait for every flood to start (s, wall): each waits up to 60 s itself for the
#: sim time and the subscribers.
FLOOD_START_TIMEOUT_S = 75.0
KIB_PER_MIB = 1024.0
#: Wall-clock guards (s).
FLOOD_EXTRA_S = 90.0
DEMO_TIMEOUT_S = 300.0


@dataclass
class Flood:
    """One flood_commands.py, its stderr read line by line by a thread (for its start)."""

    process: subprocess.Popen
    started: threading.Event = field(default_factory=threading.Event)
    stderr_lines: list[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.reader = threading.Thread(target=self._read_stderr, daemon=True)
        self.reader.start()

    def _read_stderr(self) -> None:
        for line in self.process.stderr:
            self.stderr_lines.append(line)
            if line.startswith(FLOOD_STARTED):
                self.started.set()

    def poll(self) -> int | None:
        return self.process.poll()


def _start_floods(master: Master, duration_s: float) -> list[Flood]:
    command = [sys.executable, str(FLOOD), '--kind', 'valid', '--rate', str(LOAD_RATE_HZ),
               '--duration', str(duration_s), '--start-sim', str(LOAD_START_SIM_S)]
    return [Flood(subprocess.Popen(command, env=master.env, stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE, text=True))
            for _ in range(LOAD_PUBLISHERS)]


def _wait_floods_started(launch: Launch, floods: list[Flood]) -> None:
    """Until every flood has reported that it began publishing (bounded)."""
    def check() -> None:
        launch.check_running()
        for flood in floods:
            if not flood.started.is_set() and flood.poll() is not None:
                flood.reader.join(timeout=1.0)  # its last lines may still be in the pipe
                if flood.started.is_set():
                    continue
                raise BenchError(f'flood_commands.py exited ({flood.poll()}) before its flood '
                                 f'began: {"".join(flood.stderr_lines).strip()}')

    wait_until(lambda: all(flood.started.is_set() for flood in floods), FLOOD_START_TIMEOUT_S,
               'the floods did not start', check)


def _flood_figures(floods: list[Flood], duration_s: float) -> list[dict]:
    figures = []
    for flood in floods:
        try:  # its stdout is one JSON line: the pipe cannot fill up before it exits
            flood.process.wait(timeout=duration_s + FLOOD_EXTRA_S)
        except subprocess.TimeoutExpired as err:
            flood.process.kill()
            raise BenchError('flood_commands.py did not finish in time') from err
        stdout = flood.process.stdout.read() if flood.process.stdout else ''
        flood.reader.join(timeout=5.0)
        if flood.process.returncode != 0:
            raise BenchError(f'flood_commands.py failed ({flood.process.returncode}): '
                             f'{"".join(flood.stderr_lines).strip()}')
        figures.append(json.loads(stdout.strip().splitlines()[-1]))
    return figures


def _recorded_commands(bag_dir: Path) -> int:
    from rosbags.rosbag1 import Reader

    bags = sorted(bag_dir.glob('*.bag'))
    if not bags:
        raise BenchError(f'the load run left no closed bag in {bag_dir}')
    with Reader(bags[-1]) as reader:
        return sum(c.msgcount for c in reader.connections if c.topic == '/atlas/joint_commands')


def _watch_memory(launch: Launch, floods: list[Flood]) -> tuple[int, int]:
    """(first, highest) resident memory (KiB) of the simulator while the floods run.

    The first reading is the baseline: LOAD_SETTLE_S after every flood reported its start.
    """
    sim_pid = launch.node_pid('atlas_sim')
    if sim_pid is None:
        raise BenchError(f'no atlas_sim node in the launch; see {launch.log_path}')
    _wait_floods_started(launch, floods)
    time.sleep(LOAD_SETTLE_S)
    samples_kib = [rss_kib(sim_pid) or 0]
    while any(flood.poll() is None for flood in floods):
        launch.check_running()
        samples_kib.append(rss_kib(sim_pid) or 0)
        time.sleep(1.0)
    samples_kib.append(rss_kib(sim_pid) or 0)
    return samples_kib[0], max(samples_kib)


def load_run(master: Master, launch_file: str, probes: Probes, work_dir: Path, name: str,
             duration_s: float) -> dict[str, float]:
    from std_msgs.msg import String

    bag_dir = work_dir / f'{name}_bags'
    args = {'gui': 'false', 'real_time_factor': '1.0', 'record': 'true', 'bag_dir': str(bag_dir)}
    with Launch(master, launch_file, args, work_dir / f'{name}.launch.log') as launch:
        wait_until(lambda: {'/atlas_sim', '/recorder'} <= set(
            master.subscribers('/atlas/joint_commands')), READY_TIMEOUT_S,
            'the simulator and the recorder did not subscribe', launch.check_running)
        wait_until(lambda: len(subscriber_names(probes.mode_pub)) >= 2, READY_TIMEOUT_S,
                   'the simulator did not subscribe to the mode', launch.check_running)
        probes.mode_pub.publish(String(data='User'))
        floods = _start_floods(master, duration_s)
        try:
            rss_start_kib, rss_max_kib = _watch_memory(launch, floods)
            figures = _flood_figures(floods, duration_s)
        finally:  # a failed run leaves no flood behind
            for flood in floods:
                if flood.poll() is None:
                    flood.process.kill()
                    flood.process.wait(timeout=STOP_TIMEOUT_S)
        shutdown_s = launch.interrupt(STOP_TIMEOUT_S)
    sent = sum(f['sent'] for f in figures)
    result = {
        'load_rtf': sum(f['real_time_factor'] for f in figures) / len(figures),
        'load_publish_rate_hz': sum(f['rate_hz'] for f in figures),
        'load_commands_lost': float(sent - _recorded_commands(bag_dir)),
        'load_rss_growth_mib': (rss_max_kib - rss_start_kib) / KIB_PER_MIB,
        'shutdown_s': shutdown_s,
    }
    fraction = recorded_fraction(bag_dir)
    if fraction is not None:
        result['load_recorded_fraction'] = fraction
    if result['load_commands_lost'] == 0:
        shutil.rmtree(bag_dir, ignore_errors=True)  # ~2.5 kB per command: hundreds of MB
    # else kept with the launch log: which commands are missing says why (run_bench keeps
    # the scratch directory then).
    return result


def tutorial_run(work_dir: Path, name: str) -> dict[str, float]:
    from tutorial_atlas_control.bags.analysis import analyze_bag

    bag_dir = work_dir / f'{name}_bags'
    log_path = work_dir / f'{name}.log'
    with log_path.open('w') as log_file:
        try:
            completed = subprocess.run(
                [sys.executable, str(RUN_DEMO), 'step_and_fall', '--video-fps', '0',
                 '--bag-dir', str(bag_dir)], stdout=log_file, stderr=subprocess.STDOUT,
                stdin=subprocess.DEVNULL, timeout=DEMO_TIMEOUT_S, check=False)
        except subprocess.TimeoutExpired as err:
            raise BenchError(f'run_demo.py did not finish in time; see {log_path}') from err
    bags = sorted(bag_dir.glob('atlas_*.bag'))
    if completed.returncode != 0 or not bags:
        raise BenchError(f'run_demo.py failed ({completed.returncode}); see {log_path}')
    rate_hz = analyze_bag(bags[-1]).command_rate_hz
    mb_per_min = bag_mb_per_min(bags[-1])
    age_share = bag_closed_form_share(bags[-1])
    shutil.rmtree(bag_dir, ignore_errors=True)
    if rate_hz is None or age_share is None:
        raise BenchError(f'the tutorial run recorded no commands or no controller statistics; '
                         f'see {log_path}')
    return {'tutorial_command_rate_hz': rate_hz, 'bag_mb_per_min': mb_per_min,
            'tutorial_age_closed_form_share': age_share}


def bag_mb_per_min(bag: Path) -> float:
    """The bag's size (MB, 10^6 bytes) per minute of the sim time it spans."""
    from rosbags.rosbag1 import Reader

    with Reader(bag) as reader:
        span_s = reader.duration / NS_PER_S
    if span_s <= 0:
        raise BenchError(f'{bag} spans no sim time')
    return bag.stat().st_size / 1e6 / (span_s / 60.0)


#: The 50 Hz port's command ages in closed form (test/rostest/test_command_age.py's
#: docstring): each command applied one step after its stamp and held 20 steps, so the ages
#: in a window of WINDOW_STEPS steps are 1..20 ms over and over (s, s^2).
STEP_S = 0.001
PERIOD_STEPS = 20
WINDOW_STEPS = 1000
CLOSED_FORM_MEAN_S = (1 + PERIOD_STEPS) / 2 * STEP_S
CLOSED_FORM_VARIANCE_S2 = ((PERIOD_STEPS ** 2 - 1) / 12 * STEP_S ** 2
                           * WINDOW_STEPS / (WINDOW_STEPS - 1))
#: A window "at the closed form": its mean 10-12 ms (a command held 20 steps plus one, with
#: room for one a step late now and then) and its variance within 10 %. A late command
#: (a busy machine) shortens one hold and lengthens the next.
CLOSED_FORM_MEAN_RANGE_S = (0.010, 0.012)
CLOSED_FORM_VARIANCE_TOLERANCE = 0.10


def closed_form_share(stamps_ns: Sequence[int], means_s: Sequence[float],
                      variances_s2: Sequence[float], first_command_ns: int,
                      last_command_ns: int) -> float | None:
    """The share of /atlas/controller_statistics windows lying wholly within the port's
    commands (from one window after its first) whose mean and variance are at the closed
    form; None without such a window."""
    start_ns = first_command_ns + int((WINDOW_STEPS + PERIOD_STEPS) * STEP_S * NS_PER_S)
    inside = [(mean, variance) for stamp, mean, variance in zip(stamps_ns, means_s, variances_s2)
              if start_ns <= stamp <= last_command_ns]
    if not inside:
        return None
    good = [CLOSED_FORM_MEAN_RANGE_S[0] <= mean <= CLOSED_FORM_MEAN_RANGE_S[1]
            and abs(variance / CLOSED_FORM_VARIANCE_S2 - 1.0) <= CLOSED_FORM_VARIANCE_TOLERANCE
            for mean, variance in inside]
    return sum(good) / len(good)


def bag_closed_form_share(bag: Path) -> float | None:
    """closed_form_share of a bag's /atlas/controller_statistics and /atlas/joint_commands
    (their header stamps)."""
    from rosbags.rosbag1 import Reader

    from tutorial_atlas_control import topics
    from tutorial_atlas_control.bags.typestore import load_typestore

    commands: list[int] = []
    stamps: list[int] = []
    means: list[float] = []
    variances: list[float] = []
    with Reader(bag) as reader:
        wanted = [c for c in reader.connections
                  if c.topic in (topics.JOINT_COMMANDS, topics.CONTROLLER_STATISTICS)]
        if not wanted:
            return None
        typestore = load_typestore(reader.connections)
        for connection, _t, raw in reader.messages(connections=wanted):
            message = typestore.deserialize_ros1(raw, connection.msgtype)
            stamp_ns = message.header.stamp.sec * NS_PER_S + message.header.stamp.nanosec
            if connection.topic == topics.JOINT_COMMANDS:
                commands.append(stamp_ns)
            else:
                stamps.append(stamp_ns)
                means.append(message.command_age_mean)
                variances.append(message.command_age_variance)
    if not commands:
        return None
    return closed_form_share(stamps, means, variances, min(commands), max(commands))
