"""The benchmark's measurements against the running simulator node (a private master).

fast run:     real_time_factor:=0 with the recorder subscribed (atlas_recorder, then
              `rosbag record`); achieved real-time factor = sim time advanced / wall time
              over a window, both taken from the
              /clock messages a raw subscriber receives (first and last of the window).
realtime run: real_time_factor:=1.0; over the window every /clock arrival is kept.
              lateness of step i = (arrival_i - sim_i) - min_j (arrival_j - sim_j), i.e.
              how much later than the best-placed step each step arrives against a wall
              schedule of one sim second per wall second. It includes /clock's transport
              and our callback jitter, and counts drift: an rtf of 0.999 over 30 s shows
              as 30 ms of lateness at the end, as it should.
              Then command latency (User mode): JointCommands for neck_ay only, with all
              its gains 0 and a unique feed-forward `effort` per message, so the effort the
              simulator publishes for neck_ay is exactly the commanded one from the step
              that first applied it. latency = arrival of the first /atlas/joint_states
              carrying that effort - the publish() call. `net` subtracts the median
              JointState transport measured by js_transport_probe.py on the same master,
              which sends pre-serialized joint states through the node's own transport
              (queue_size=None publisher, WireBatch / ConnectionWriter).
"""

from __future__ import annotations

import shutil
import struct
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar

import numpy as np
from harness import READY_TIMEOUT_S, BenchError, Launch, Master, log
from probes import RawRecorder, clock_ns, header_stamp_ns, joint_state_effort

from tutorial_atlas_control import topics
from tutorial_atlas_control.processes import cpu_seconds, wait_until
from tutorial_atlas_control.units import NS_PER_S

LATENCY_JOINT = 'neck_ay'
#: What the action during a paced window returns.
T = TypeVar('T')

#: Fewer applied commands than this in a latency window are logged as few.
FEW_LATENCIES = 10
JS_PROBE_TOPIC = '/tac_bench/js_probe'


@dataclass
class Probes:
    """The benchmark node's subscribers and publishers (created once per master)."""

    clock: RawRecorder
    joint_states: RawRecorder
    js_probe: RawRecorder
    command_pub: object
    mode_pub: object


def make_probes() -> Probes:
    import warnings

    import rospy
    from osrf_msgs.msg import JointCommands
    from std_msgs.msg import String

    # rospy warns about queue_size=None, which is what we want here (synchronous).
    warnings.filterwarnings('ignore', category=SyntaxWarning, module='rospy')
    warnings.filterwarnings('ignore', message='The publisher should be created')
    return Probes(
        clock=RawRecorder(topics.CLOCK),
        joint_states=RawRecorder(topics.JOINT_STATES),
        js_probe=RawRecorder(JS_PROBE_TOPIC),
        # Synchronous publishers: the publish() timestamp is then when the bytes leave.
        command_pub=rospy.Publisher(topics.JOINT_COMMANDS, JointCommands, queue_size=None,
                                    tcp_nodelay=True),
        mode_pub=rospy.Publisher(topics.CONTROL_MODE, String, queue_size=None),
    )


def _launch(master: Master, launch_file: str, work_dir: Path, name: str,
            rtf: float, recorder: str | None = None,
            extra_args: dict[str, str] | None = None) -> Launch:
    args = {'gui': 'false', 'real_time_factor': str(rtf), 'record': 'true',
            'bag_dir': str(work_dir / f'{name}_bags'), **(extra_args or {})}
    if recorder:
        args['recorder'] = recorder
    return Launch(master, launch_file, args, work_dir / f'{name}.launch.log')


def recorded_fraction(bag_dir: Path, topic: str = topics.JOINT_STATES) -> float | None:
    """Share of `topic`'s published messages that reached the bag, from the header seqs.

    The publisher numbers its messages (Header.seq); messages a subscriber queue dropped
    (the recorder's, when it cannot keep up) leave gaps. None if there is no closed bag.
    """
    from rosbags.rosbag1 import Reader

    bags = sorted(bag_dir.glob('*.bag'))
    if not bags:
        return None
    seqs = []
    with Reader(bags[-1]) as reader:
        connections = [c for c in reader.connections if c.topic == topic]
        if not connections:  # Reader.messages reads every connection when given none
            return None
        for _, _, raw in reader.messages(connections=connections):
            seqs.append(struct.unpack_from('<I', raw, 0)[0])
    if len(seqs) < 2:
        return None
    return len(seqs) / (max(seqs) - min(seqs) + 1)


def _drop_bags(launch: Launch) -> None:
    """Bags at real_time_factor 0 are large (~1 MB per sim second): delete each run's."""
    shutil.rmtree(launch.args['bag_dir'], ignore_errors=True)


#: Wall time (s) after the first /clock before a bdi_stand start is balancing in Stand (its
#: Stand begins at 2 s of sim time; a loaded machine may run a little slow).
STAND_STARTED_S = 3.0
#: The longest a bench walk may take (s, wall; walk_client.py gives up at 120 s itself):
#: eight steps take about 8 s.
WALK_TIMEOUT_S = 180.0
#: The bench's walk: walk_straight's eight steps of 0.25 m.
WALK_STEPS = 8


def _wait_ready(master: Master, launch: Launch, probes: Probes) -> None:
    """/clock arriving and the recorder subscribed to the simulator's topics."""
    start_count = probes.clock.count
    wait_until(lambda: probes.clock.count > start_count + 10, READY_TIMEOUT_S,
               'the simulator did not publish /clock', launch.check_running)
    wait_until(lambda: all(any('recorder' in node for node in master.subscribers(topic))
                           for topic in (topics.CLOCK, topics.JOINT_STATES, topics.IMU)),
               READY_TIMEOUT_S, 'the recorder did not subscribe', launch.check_running)


def _clock_series(samples: list[tuple[float, bytes]]) -> tuple[np.ndarray, np.ndarray]:
    if len(samples) < 2:
        raise BenchError(f'only {len(samples)} /clock messages in the window')
    wall = np.array([s[0] for s in samples])
    sim = np.array([clock_ns(s[1]) for s in samples], dtype=np.int64) / NS_PER_S
    return wall, sim


def fast_run(master: Master, launch_file: str, probes: Probes, work_dir: Path, name: str,
             warmup_s: float, window_s: float, recorder: str,
             prefix: str = 'fast', extra_args: dict[str, str] | None = None) -> dict[str, float]:
    """One run at real_time_factor:=0: `<prefix>_rtf`, `<prefix>_recorded_fraction`, and the
    CPU (cores) of each process that shares the machine's cores at that pace (`extra_args`:
    more launch arguments)."""
    with _launch(master, launch_file, work_dir, name, 0.0, recorder, extra_args) as launch:
        _wait_ready(master, launch, probes)
        time.sleep(warmup_s)
        pids = {'node': launch.node_pid('atlas_sim'), 'recorder': launch.node_pid('recorder'),
                'state_publisher': launch.node_pid('robot_state_publisher'),
                'master': master.pid_of('rosmaster')}
        cpu0 = {name: cpu_seconds(pid) if pid else 0.0 for name, pid in pids.items()}
        probes.clock.start()
        time.sleep(window_s)
        samples = probes.clock.stop()
        cpu1 = {name: cpu_seconds(pid) if pid else 0.0 for name, pid in pids.items()}
        launch.check_running()
    recorded = recorded_fraction(Path(launch.args['bag_dir']))
    _drop_bags(launch)
    wall, sim = _clock_series(samples)
    # Received /clock messages may be a subset; the first and last bound the window.
    span_s = wall[-1] - wall[0]
    result = {f'{prefix}_rtf': float((sim[-1] - sim[0]) / span_s)}
    if recorded is not None:
        result[f'{prefix}_recorded_fraction'] = recorded
    for name, pid in pids.items():
        if pid:  # CPU (cores) over the window, from /proc (utime + stime)
            result[f'{prefix}_{name}_cpu'] = (cpu1[name] - cpu0[name]) / window_s
    return result


def _lateness(wall: np.ndarray, sim: np.ndarray) -> np.ndarray:
    offset = wall - sim
    return (offset - offset.min()) * 1000.0


def _latency_command(effort: float) -> object:
    """JointCommands for LATENCY_JOINT alone, every gain 0: the law's torque is `effort`."""
    from osrf_msgs.msg import JointCommands

    return JointCommands(name=[LATENCY_JOINT], kp_position=[0.0], ki_position=[0.0],
                         kd_position=[0.0], kp_velocity=[0.0], effort=[effort])


def _send_commands(probes: Probes, rate_hz: float, duration_s: float,
                   first_key: int) -> list[tuple[float, float]]:
    """Publish neck_ay feed-forward commands; return (effort value, publish time) pairs."""
    msg = _latency_command(0.0)
    sent = []
    period = 1.0 / rate_hz
    count = int(round(rate_hz * duration_s))
    next_s = time.perf_counter()
    for index in range(count):
        key = first_key + index
        # Unique, small, alternating: the neck barely moves and every value is new.
        value = (0.5 + key * 1e-4) * (1.0 if key % 2 else -1.0)
        msg.effort = [value]
        now = time.perf_counter()
        probes.command_pub.publish(msg)
        sent.append((value, now))
        next_s += period
        delay = next_s - time.perf_counter()
        if delay > 0:
            time.sleep(delay)
        elif delay < -0.05:  # fell behind (a loaded machine): do not burst to catch up
            next_s = time.perf_counter()
    return sent


def _wait_effort_seen(probes: Probes, value: float, launch: Launch, failure: str,
                      resend: object | None = None) -> None:
    """Until /atlas/joint_states (being recorded) shows `value` as LATENCY_JOINT's effort.

    Waiting for the condition, not a fixed time: beside the test suite both the simulator
    and this process can be starved of CPU for seconds, and a sample not yet read off the
    socket when recording stops would read as a command lost. `resend` is published at
    every poll (a command that may have been ignored).
    """
    scanned = 0

    def seen() -> bool:
        nonlocal scanned
        if resend is not None:
            probes.command_pub.publish(resend)
        with probes.joint_states.lock:
            fresh = probes.joint_states.samples[scanned:]
        scanned += len(fresh)
        return any(joint_state_effort(raw, LATENCY_JOINT) == value for _, raw in fresh)

    wait_until(seen, READY_TIMEOUT_S, failure, launch.check_running)


def _wait_user_mode(probes: Probes, launch: Launch) -> None:
    """Until a command shows up in /atlas/joint_states: User mode is in effect (commands
    sent before the simulator acts on the mode change are ignored, not late)."""
    value = 0.25  # outside the measured commands' values
    msg = _latency_command(value)
    probes.joint_states.start()
    try:
        _wait_effort_seen(probes, value, launch, 'no command showed up in '
                          '/atlas/joint_states after the switch to User', resend=msg)
    finally:
        probes.joint_states.stop()


def _match_latencies(sent: list[tuple[float, float]],
                     states: list[tuple[float, bytes]]) -> tuple[np.ndarray, int]:
    """(latencies in ms of the commands that were applied, count sent)."""
    pending = {value: t_pub for value, t_pub in sent}
    latencies = []
    for t_recv, raw in states:
        effort = joint_state_effort(raw, LATENCY_JOINT)
        t_pub = pending.pop(effort, None)
        if t_pub is not None:
            latencies.append((t_recv - t_pub) * 1000.0)
    return np.array(latencies), len(sent)


def js_transport(master: Master, probes: Probes, work_dir: Path, count: int = 2000,
                 rate_hz: float = 1000.0) -> dict[str, float]:
    """JointState transport between two processes, on the node's send path (ms): p50, p99.

    js_transport_probe.py sends through node/transport.py as the simulator does (see there).
    """
    probes.js_probe.start()
    probe_log = (work_dir / 'js_probe.log').open('w')
    try:
        completed = subprocess.run(
            [sys.executable, str(Path(__file__).with_name('js_transport_probe.py')),
             JS_PROBE_TOPIC, str(count), str(rate_hz)],
            env=master.env, stdout=probe_log, stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL, timeout=count / rate_hz + 60, check=False)
        if completed.returncode == 0:
            # Its sends are synchronous, so all `count` arrive; this process, niced beside
            # the test suite, may still be reading them.
            deadline = time.monotonic() + READY_TIMEOUT_S
            while len(probes.js_probe.samples) < count and time.monotonic() < deadline:
                time.sleep(0.05)
    except subprocess.TimeoutExpired as err:
        raise BenchError('js_transport_probe.py did not finish in time') from err
    finally:
        samples = probes.js_probe.stop()
    if completed.returncode != 0 or len(samples) < count // 2:
        raise BenchError(f'js_transport_probe.py failed ({completed.returncode}, '
                         f'{len(samples)} messages); see {probe_log.name}')
    transport = np.array([t - header_stamp_ns(raw) / NS_PER_S for t, raw in samples]) * 1000.0
    return {'js_transport_p50_ms': float(np.percentile(transport, 50)),
            'js_transport_p99_ms': float(np.percentile(transport, 99))}


def _bdi_stand_pace(master: Master, launch_file: str, probes: Probes, work_dir: Path,
                    name: str, prefix: str, during: Callable[[], T]) -> tuple[dict[str, float], T]:
    """atlas.launch as DRCSim 2.7 started (startup_mode:=bdi_stand: the balancing Stand from
    2 s of sim time) at real_time_factor:=1 with the recorder, and from STAND_STARTED_S on,
    while `during` runs: the pace kept (`<prefix>_realtime_rtf`), the step lateness p99
    (`<prefix>_lateness_p99_ms`), and the CPU per step of the node and of the recorder
    (`<prefix>_node_us_per_step`, `<prefix>_recorder_us_per_step`: the recorder's is the
    cost of what the node sends it); and what `during` returned."""
    with _launch(master, launch_file, work_dir, name, 1.0,
                 extra_args={'startup_mode': 'bdi_stand'}) as launch:
        _wait_ready(master, launch, probes)
        time.sleep(STAND_STARTED_S)
        pids = {'node': launch.node_pid('atlas_sim'), 'recorder': launch.node_pid('recorder')}
        cpu0 = {role: cpu_seconds(pid) if pid else 0.0 for role, pid in pids.items()}
        probes.clock.start()
        try:
            outcome = during()
        finally:
            samples = probes.clock.stop()
        cpu1 = {role: cpu_seconds(pid) if pid else 0.0 for role, pid in pids.items()}
        launch.check_running()
    _drop_bags(launch)
    wall, sim = _clock_series(samples)
    steps = (sim[-1] - sim[0]) * 1000.0
    result = {f'{prefix}_realtime_rtf': float((sim[-1] - sim[0]) / (wall[-1] - wall[0])),
              f'{prefix}_lateness_p99_ms': float(np.percentile(_lateness(wall, sim), 99))}
    for role, pid in pids.items():
        if pid:
            result[f'{prefix}_{role}_us_per_step'] = \
                (cpu1[role] - cpu0[role]) / max(steps, 1.0) * 1e6
    return result, outcome


def stand_realtime_run(master: Master, launch_file: str, probes: Probes, work_dir: Path,
                       name: str, window_s: float) -> dict[str, float]:
    """The pace (`stand_realtime_rtf`), step lateness p99 and node CPU per step in the
    balancing Stand, over `window_s` (_bdi_stand_pace)."""
    result, _ = _bdi_stand_pace(master, launch_file, probes, work_dir, name, 'stand',
                                lambda: time.sleep(window_s))
    return result


def walk_realtime_run(master: Master, launch_file: str, probes: Probes, work_dir: Path,
                      name: str, steps: int) -> dict[str, float]:
    """As stand_realtime_run, over a walk: `walk_client.py --steps STEPS` streaming a WALK on
    every AtlasSimInterfaceState (1 kHz) from STAND_STARTED_S until it ends: the pace kept
    (`walk_realtime_rtf`), the step lateness p99, the node's CPU per step, and whether the
    walk ended back in Stand (`walk_realtime_walked`, 1 or 0: a fall is the walk's, not
    the pace's)."""
    log_path = work_dir / f'{name}_walk_client.log'

    def walk() -> int:
        with log_path.open('w') as client_log:
            try:
                return subprocess.run(
                    ['rosrun', 'tutorial_atlas_control', 'walk_client.py', '--steps',
                     str(steps)], env=master.env, stdout=client_log,
                    stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                    timeout=WALK_TIMEOUT_S, check=False).returncode
            except subprocess.TimeoutExpired as err:
                raise BenchError(f'walk_client.py did not end in time; see {log_path}') from err

    result, status = _bdi_stand_pace(master, launch_file, probes, work_dir, name, 'walk', walk)
    if status not in (0, 1):  # 1: the walk fell or was refused; 2 and more: it never ran
        raise BenchError(f'walk_client.py exited with {status}; see {log_path}')
    result['walk_realtime_walked'] = 1.0 if status == 0 else 0.0
    return result


def realtime_run(master: Master, launch_file: str, probes: Probes, work_dir: Path, name: str,
                 warmup_s: float, window_s: float, latency_s: dict[float, float],
                 transport_ms: float) -> dict[str, float]:
    from std_msgs.msg import String

    result: dict[str, float] = {}
    with _launch(master, launch_file, work_dir, name, 1.0) as launch:
        _wait_ready(master, launch, probes)
        time.sleep(warmup_s)
        probes.clock.start()
        time.sleep(window_s)
        samples = probes.clock.stop()
        launch.check_running()
        wall, sim = _clock_series(samples)
        lateness = _lateness(wall, sim)
        steps = int(round((sim[-1] - sim[0]) * 1000)) + 1
        result.update({
            'realtime_rtf': float((sim[-1] - sim[0]) / (wall[-1] - wall[0])),
            'lateness_p50_ms': float(np.percentile(lateness, 50)),
            'lateness_p99_ms': float(np.percentile(lateness, 99)),
            'lateness_max_ms': float(lateness.max()),
            'realtime_clock_received': len(samples) / max(steps, 1),
        })

        if latency_s:
            wait_until(lambda: probes.command_pub.get_num_connections() > 0
                       and probes.mode_pub.get_num_connections() > 0, READY_TIMEOUT_S,
                       'the simulator did not subscribe to the commands', launch.check_running)
            probes.mode_pub.publish(String(data='User'))
            _wait_user_mode(probes, launch)
        key = 0
        for rate_hz, duration_s in latency_s.items():
            label = f'{rate_hz:g}hz' if rate_hz < 1000 else f'{rate_hz / 1000:g}khz'
            probes.joint_states.start()
            sent = _send_commands(probes, rate_hz, duration_s, key)
            key += len(sent) + 1
            try:
                _wait_effort_seen(probes, sent[-1][0], launch,
                                  f'the last command at {label} did not show up in '
                                  '/atlas/joint_states')
            finally:
                states = probes.joint_states.stop()
            launch.check_running()
            latencies, count = _match_latencies(sent, states)
            # At least the last one (waited for). Few more: a starved simulator stepped in
            # bursts, each applying only the newest command; cmd_applied_* says so.
            if len(latencies) < FEW_LATENCIES:
                log(f'only {len(latencies)} of {count} commands at {label} showed up in '
                    '/atlas/joint_states: its latency figures rest on them')
            for pct in (50, 99):
                raw_ms = float(np.percentile(latencies, pct))
                result[f'cmd_latency_p{pct}_ms_raw_{label}'] = raw_ms
                result[f'cmd_latency_p{pct}_ms_{label}'] = raw_ms - transport_ms
            result[f'cmd_applied_{label}'] = len(latencies) / count
    _drop_bags(launch)
    return result
