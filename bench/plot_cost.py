"""The `plot` section: what plot_topics.py plotting three 1 kHz fields costs the simulator.

Each run launches the simulator four times, without and then with a plotter running
(`plot_topics.py` on /atlas/joint_states, /atlas/atlas_state and /atlas/imu, each published
every 1 ms step, `--png` so that no window is needed): at real_time_factor:=1.0 the achieved
factor over the window (/clock, as the realtime section), and at real_time_factor:=0 the
node's CPU per simulated step (as the fast section's node_us_per_step); and the plotter's
own CPU (cores). Keys: plot_{off,on}_realtime_rtf, plot_{off,on}_node_us_per_step,
plot_on_plotter_cpu.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

from harness import READY_TIMEOUT_S, BenchError, Master
from online import Probes, _clock_series, _launch, _wait_ready

from tutorial_atlas_control.processes import cpu_seconds, stop_tree, wait_until

REPO = Path(__file__).resolve().parents[1]
PLOT = REPO / 'scripts' / 'plot_topics.py'
#: Three fields of three topics the simulator publishes every step (1 kHz).
FIELDS = ('/atlas/joint_states/position[19]', '/atlas/atlas_state/position[19]',
          '/atlas/imu/linear_acceleration/z')
TOPICS = ('/atlas/joint_states', '/atlas/atlas_state', '/atlas/imu')
#: Longer than any window: the plotter is stopped with SIGINT, it never writes its PNG.
PLOT_DURATION_S = '100000'
EXIT_TIMEOUT_S = 30.0
EXIT_INTERRUPTED = 130


def _start_plotter(master: Master, work_dir: Path, name: str) -> subprocess.Popen:
    log = open(work_dir / f'{name}.plot.log', 'w')  # noqa: SIM115 - the process keeps it
    process = subprocess.Popen(
        [sys.executable, str(PLOT), *FIELDS, '--png', str(work_dir / f'{name}.png'),
         '--duration', PLOT_DURATION_S], env=master.env, stdout=log, stderr=log)

    def subscribed() -> bool:
        return all(any('plot_topics' in node for node in master.subscribers(topic))
                   for topic in TOPICS)

    def running() -> None:
        if process.poll() is not None:
            raise BenchError(f'plot_topics.py exited with {process.returncode}; see {log.name}')

    wait_until(subscribed, READY_TIMEOUT_S, 'plot_topics.py did not subscribe', running)
    return process


def _stop_plotter(process: subprocess.Popen, work_dir: Path, name: str) -> None:
    process.send_signal(signal.SIGINT)
    try:
        status = process.wait(timeout=EXIT_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        stop_tree(process)
        status = process.returncode
    if status != EXIT_INTERRUPTED:
        raise BenchError(f'plot_topics.py ended with {status}, not {EXIT_INTERRUPTED}; see '
                         f'{work_dir / f"{name}.plot.log"}')


def _window(master: Master, launch_file: str, probes: Probes, work_dir: Path, name: str,
            rtf: float, warmup_s: float, window_s: float, plotted: bool
            ) -> tuple[float, float, float]:
    """(achieved rtf, node CPU cores, plotter CPU cores) over one window of one launch."""
    with _launch(master, launch_file, work_dir, name, rtf) as launch:
        _wait_ready(master, launch, probes)
        plotter = _start_plotter(master, work_dir, name) if plotted else None
        try:
            time.sleep(warmup_s)
            pids = {'node': launch.node_pid('atlas_sim'),
                    'plotter': plotter.pid if plotter else None}
            cpu0 = {key: cpu_seconds(pid) if pid else 0.0 for key, pid in pids.items()}
            probes.clock.start()
            time.sleep(window_s)
            samples = probes.clock.stop()
            cpu1 = {key: cpu_seconds(pid) if pid else 0.0 for key, pid in pids.items()}
            launch.check_running()
        finally:
            if plotter is not None:
                _stop_plotter(plotter, work_dir, name)
    wall, sim = _clock_series(samples)
    achieved = float((sim[-1] - sim[0]) / (wall[-1] - wall[0]))
    return (achieved, (cpu1['node'] - cpu0['node']) / window_s,
            (cpu1['plotter'] - cpu0['plotter']) / window_s)


def plot_run(master: Master, launch_file: str, probes: Probes, work_dir: Path, name: str,
             warmup_s: float, window_s: float, steps_per_sim_s: float) -> dict[str, float]:
    values = {}
    for plotted, prefix in ((False, 'plot_off'), (True, 'plot_on')):
        rtf, _node, plotter = _window(master, launch_file, probes, work_dir,
                                      f'{name}_{prefix}_rt', 1.0, warmup_s, window_s, plotted)
        values[f'{prefix}_realtime_rtf'] = rtf
        if plotted:
            values['plot_on_plotter_cpu'] = plotter
        fast_rtf, node, _plotter = _window(master, launch_file, probes, work_dir,
                                           f'{name}_{prefix}_fast', 0.0, warmup_s, window_s,
                                           plotted)
        values[f'{prefix}_node_us_per_step'] = node * 1e6 / (fast_rtf * steps_per_sim_s)
    return values
