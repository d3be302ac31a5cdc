"""The benchmark's `controller` section: echo_controller (src/echo_controller.cpp) in the loop.

floor:       real_time_factor:=1.0 before echo_controller starts (in the TCP age run's
             launch): the simulator's CPU per step with no controller, the floor the
             controller's cost sits on (`controller_none_node_us_per_step`).
age run:     real_time_factor:=1.0, echo_controller answering every /atlas/atlas_state over
             TCP (then over UDP): the command age /atlas/controller_statistics reports at
             each step (1 ms: the answer to a state arrived before the next step), p50 and
             p99, and the simulator's CPU per step while it serves the controller. A
             `udp`-only subscription connects only to a publisher that serves UDPROS (the
             node does, node/udpros.py): with one that does not (an older node, a
             --launch-file prototype), the UDP figures are absent and the run says so.
window run:  real_time_factor:=0 with echo_controller --period-ms 1 (DRCSim 2.6's
             synchronization window): every step waits for the answer to the state before
             it, so the pair's pace is one round trip per step. Every step waits, so the
             window's budget is lifted (delay_max_per_window = delay_window_size, LOCKSTEP):
             DRCSim's 0.25 s per 5 s is spent within the first few hundred steps of a window
             at this pace, and the rest of it would run without the controller. Steps per
             second of wall time over the window, from the /clock messages received, and the
             command age (exactly 1 ms at every step when the window works).
"""

from __future__ import annotations

import struct
import time
from pathlib import Path

import numpy as np
from harness import READY_TIMEOUT_S, BenchError, Launch, Master, log
from probes import RawRecorder, clock_ns

from tutorial_atlas_control import topics
from tutorial_atlas_control.processes import _RosProcess, cpu_seconds, node_api, wait_until
from tutorial_atlas_control.units import NS_PER_S

#: How long (s, wall) a udp-only subscription may take to connect before the run says
#: there is no UDP connection.
UDP_CONNECT_S = 10.0
#: The node that serves /atlas/atlas_state.
SIM_NODE = '/atlas_sim'
CONTROLLER_NODE = '/echo_controller'
#: The fewest messages a window's figures rest on: a starved simulator's window is recorded
#: past its length until they have come (within READY_TIMEOUT_S more), not failed.
MIN_STATISTICS = 100
MIN_CLOCKS = 2
#: ControllerStatistics ends with four float64: command_age, mean, variance, window.
_AGE_FROM_END = 32


class EchoController(_RosProcess):
    """`rosrun tutorial_atlas_control echo_controller ...` on the bench's master."""

    name = 'echo_controller'

    def __init__(self, master: Master, log_path: Path, transport: str, period_ms: int) -> None:
        super().__init__(['rosrun', 'tutorial_atlas_control', 'echo_controller',
                          '--transport', transport, '--period-ms', str(period_ms)],
                         master.env, log_path)


def command_age_s(raw: bytes) -> float:
    """command_age of a serialized atlas_msgs/ControllerStatistics (s)."""
    return struct.unpack_from('<d', raw, len(raw) - _AGE_FROM_END)[0]


def state_transport(master: Master) -> str | None:
    """The transport ('TCPROS'/'UDPROS') of the simulator's /atlas/atlas_state connection
    to echo_controller, from the simulator's getBusInfo; None while there is none."""
    try:
        code, _, rows = node_api(master.uri, SIM_NODE, '/tac_bench').getBusInfo('/tac_bench')
    except OSError:
        return None
    if code != 1:
        return None
    for row in rows:
        if row[2] == 'o' and row[4] == topics.ATLAS_STATE and row[1] == CONTROLLER_NODE:
            return str(row[3])
    return None


#: The window's budgets for lockstep at real_time_factor 0 (atlas.launch's arguments): any
#: share of wall time may be spent waiting; a step waits at most DRCSim's 25 ms.
LOCKSTEP = {'delay_window_size': '5.0', 'delay_max_per_window': '5.0',
            'delay_max_per_step': '0.025'}


def _launch(master: Master, launch_file: str, work_dir: Path, name: str, rtf: float,
            extra: dict[str, str] | None = None) -> Launch:
    args = {'gui': 'false', 'real_time_factor': str(rtf), 'record': 'false',
            'bag_dir': str(work_dir / f'{name}_bags'), **(extra or {})}
    return Launch(master, launch_file, args, work_dir / f'{name}.launch.log')


def _wait_clock(launch: Launch, clock: RawRecorder) -> None:
    start_count = clock.count
    wait_until(lambda: clock.count > start_count + 10, READY_TIMEOUT_S,
               'the simulator did not publish /clock', launch.check_running)


def age_run(master: Master, launch_file: str, clock: RawRecorder, statistics: RawRecorder,
            work_dir: Path, name: str, transport: str, warmup_s: float, window_s: float,
            per_sim_s: float, floor: bool = False) -> dict[str, float] | None:
    """One run at real_time_factor:=1 with echo_controller over `transport` ('tcp' or
    'udp'): `controller_<transport>_age_p50_ms`, `_age_p99_ms`, `_node_us_per_step`; None
    when the subscription never connected (no UDPROS). With `floor`, first the same
    window without the controller: `controller_none_node_us_per_step`."""
    with _launch(master, launch_file, work_dir, name, 1.0) as launch:
        _wait_clock(launch, clock)  # the gains are on the parameter server by then
        figures = {}
        if floor:
            time.sleep(warmup_s)
            figures['controller_none_node_us_per_step'] = _node_us_per_step(
                launch, clock, name, window_s, per_sim_s)
        with EchoController(master, work_dir / f'{name}.echo.log', transport, 0) as echo:
            served = _age_window(master, launch, echo, clock, statistics, name, transport,
                                 warmup_s, window_s, per_sim_s)
        return None if served is None else {**figures, **served}


def _node_us_per_step(launch: Launch, clock: RawRecorder, name: str, window_s: float,
                      per_sim_s: float) -> float:
    """The simulator's CPU (µs) per simulated step over at least `window_s` of wall time."""
    pid = launch.node_pid('atlas_sim')
    if pid is None:
        raise BenchError(f'{name}: no atlas_sim process')
    cpu0 = cpu_seconds(pid)
    clocks, _, recorded_s = _record(launch, name, window_s, clock, None)
    cpu1 = cpu_seconds(pid)
    steps = (clock_ns(clocks[-1][1]) - clock_ns(clocks[0][1])) / NS_PER_S * per_sim_s
    return (cpu1 - cpu0) * 1e6 / (steps * recorded_s / (clocks[-1][0] - clocks[0][0]))


def _record(launch: Launch, name: str, window_s: float, clock: RawRecorder,
            statistics: RawRecorder | None,
            echo: EchoController | None = None,
            ) -> tuple[list[tuple[float, bytes]], list[tuple[float, bytes]], float]:
    """Record /clock (and the controller statistics) for `window_s` of wall time, and on
    until MIN_CLOCKS (and MIN_STATISTICS) have come: the /clock and statistics samples and
    the wall time recorded (s)."""

    def check() -> None:
        launch.check_running()
        if echo is not None:
            echo.check_running()

    def enough() -> bool:
        return (clock.recorded() >= MIN_CLOCKS
                and (statistics is None or statistics.recorded() >= MIN_STATISTICS))

    started = time.monotonic()
    clock.start()
    if statistics is not None:
        statistics.start()
    try:
        time.sleep(window_s)
        wait_until(enough, READY_TIMEOUT_S,
                   f'{name}: fewer than {MIN_CLOCKS} /clock messages'
                   + ('' if statistics is None else
                      f' or {MIN_STATISTICS} controller statistics') + ' in the window',
                   check)
    finally:
        ages = [] if statistics is None else statistics.stop()
        clocks = clock.stop()
    return clocks, ages, time.monotonic() - started


def _age_window(master: Master, launch: Launch, echo: EchoController, clock: RawRecorder,
                statistics: RawRecorder, name: str, transport: str, warmup_s: float,
                window_s: float, per_sim_s: float) -> dict[str, float] | None:
    """age_run's measurement, with the launch and the controller running."""
    deadline = time.monotonic() + (UDP_CONNECT_S if transport == 'udp' else READY_TIMEOUT_S)
    while state_transport(master) is None:
        launch.check_running()
        echo.check_running()
        if time.monotonic() > deadline:
            if transport == 'udp':
                return None
            raise BenchError(f'echo_controller did not connect over {transport}')
        time.sleep(0.1)
    connected = state_transport(master)
    time.sleep(warmup_s)
    pid = launch.node_pid('atlas_sim')
    cpu0 = cpu_seconds(pid) if pid else 0.0
    age_ms, steps, span_s, recorded_s = _record_window(launch, echo, clock, statistics, name,
                                                       window_s, per_sim_s)
    cpu1 = cpu_seconds(pid) if pid else 0.0
    log(f'{name}: /atlas/atlas_state over {connected}')
    return {f'controller_{transport}_age_p50_ms': float(np.percentile(age_ms, 50)),
            f'controller_{transport}_age_p99_ms': float(np.percentile(age_ms, 99)),
            f'controller_{transport}_node_us_per_step':
                (cpu1 - cpu0) * 1e6 / (steps * recorded_s / span_s)}


def _record_window(launch: Launch, echo: EchoController, clock: RawRecorder,
                   statistics: RawRecorder, name: str, window_s: float,
                   per_sim_s: float) -> tuple[np.ndarray, float, float, float]:
    """Record /clock and the controller statistics for at least `window_s` (wall): the
    command ages (ms), the steps simulated and the wall time (s) between the first and last
    /clock, and the wall time recorded (s)."""
    clocks, ages, recorded_s = _record(launch, name, window_s, clock, statistics, echo)
    age_ms = np.array([command_age_s(raw) for _, raw in ages]) * 1000.0
    steps = (clock_ns(clocks[-1][1]) - clock_ns(clocks[0][1])) / NS_PER_S * per_sim_s
    return age_ms, steps, clocks[-1][0] - clocks[0][0], recorded_s


def window_run(master: Master, launch_file: str, clock: RawRecorder, statistics: RawRecorder,
               work_dir: Path, name: str, warmup_s: float, window_s: float,
               per_sim_s: float) -> dict[str, float]:
    """One run at real_time_factor:=0 with echo_controller --period-ms 1 over TCP:
    `controller_window_steps_per_s` and `controller_window_age_p99_ms`."""
    with _launch(master, launch_file, work_dir, name, 0.0, LOCKSTEP) as launch:
        _wait_clock(launch, clock)
        with EchoController(master, work_dir / f'{name}.echo.log', 'tcp', 1) as echo:
            return _window_window(master, launch, echo, clock, statistics, name, warmup_s,
                                  window_s, per_sim_s)


def _window_window(master: Master, launch: Launch, echo: EchoController, clock: RawRecorder,
                   statistics: RawRecorder, name: str, warmup_s: float, window_s: float,
                   per_sim_s: float) -> dict[str, float]:
    """window_run's measurement, with the launch and the controller running."""
    wait_until(lambda: state_transport(master) is not None, READY_TIMEOUT_S,
               'echo_controller did not connect', launch.check_running)
    time.sleep(warmup_s)
    age_ms, steps, span_s, _ = _record_window(launch, echo, clock, statistics, name, window_s,
                                              per_sim_s)
    return {'controller_window_steps_per_s': steps / span_s,
            'controller_window_age_p99_ms': float(np.percentile(age_ms, 99))}
