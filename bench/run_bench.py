#!/usr/bin/env python3
"""`make bench`: the simulator's performance, each figure as min / median / max over runs.

Prints a table on stdout and, as its last line, one JSON object with the medians. Progress
goes to stderr. Runs on a private master on a free port (never 11311), under a scratch
directory in /tmp that is removed afterwards (kept with --keep or on failure).

Sections (see bench/README.md for what each figure means and how it is measured):
  physics   bare mj_step, and AtlasSimulator.step() (law + mj_step; C and numpy law) in a
            plain loop, no ROS
  offline   run_offline.py's run of touchdown to a bag, against the plain loop
  analysis  bags.analysis.analyze_bag vs Debian's rosbag API on a 60 s run bag
  fast      the node at real_time_factor:=0 with atlas_recorder (the launch's default; the
            fast_* keys), then with `rosbag record` (fast_rosbag_*); the CPU of every process
  realtime  the node at real_time_factor:=1.0: achieved factor, step lateness, then the
            command latency at 50 Hz and 1 kHz (User mode)
  load      the node at real_time_factor:=1.0 under 3 x 2 kHz of valid commands for 30 s:
            achieved factor, commands lost by the recorder, simulator memory growth,
            then the time SIGINT takes to stop the launch
  tutorial  run_demo.py step_and_fall: the port's command rate in sim time, and the bag's
            size per minute of sim time
  controller  echo_controller answering every /atlas/atlas_state: command age p50/p99 and
            the node's CPU per step at real_time_factor:=1 over TCP and over UDP ("n/a"
            while the node serves no UDPROS); steps per second of the pair with DRCSim
            2.6's synchronization window on (--period-ms 1) at real_time_factor:=0
  plot      realtime_rtf and node_us_per_step without and with plot_topics.py plotting
            three 1 kHz fields (bench/plot_cost.py)
  cameras   the head's stereo cameras at real_time_factor:=1.0: achieved factor, images per
            second of sim time and CPU per second of sim time, unwatched, the left image,
            both, and in the VRC course (bench/camera_cost.py)
  walking   the fractions of seeds whose walks fall: pushed every 5 s (walk_pushes.py), one
            push at each phase of a step, test_asi_live's walks varied (walk_variations.py);
            once, whatever --runs says (bench/walking.py)

--compression sets the bags' chunk compression for every launch (TAC_BAG_COMPRESSION, which
atlas.launch's `compression` argument defaults to); without it, the launch's default (lz4).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import statistics
import sys
import tempfile
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

try:
    from harness import (
        BenchError,
        Master,
        busy_and_steal,
        check_environment,
        cpu_stat,
        load_average,
        log,
    )

    from tutorial_atlas_control.errors import AtlasControlError
except ImportError as import_error:
    sys.exit(f'run_bench: cannot import {import_error.name}; run `make bench`, or '
             '`make setup` and `source ./env.sh` first')


class Section:
    """Records the load average, CPU busy and steal % while a section runs, and how long
    it took (wall)."""

    def __init__(self, name: str, loads: dict[str, str]) -> None:
        self.name, self.loads = name, loads

    def __enter__(self) -> None:
        self.load = load_average()
        self.stat = cpu_stat()
        self.started_s = time.monotonic()

    def __exit__(self, *exc: object) -> None:
        busy, steal = busy_and_steal(self.stat, cpu_stat())
        self.loads[self.name] = (f'load {self.load}, busy {busy:.0f}%, steal {steal:.0f}%, '
                                 f'{time.monotonic() - self.started_s:.0f} s')


#: The recorder's chunk compressions (atlas.launch's `compression` argument).
COMPRESSIONS = ('lz4', 'bz2', 'none')
#: What the table and the JSON call the launch's own compression (lz4, atlas.launch).
DEFAULT_COMPRESSION = 'the launch\'s default'
SECTIONS = ('physics', 'offline', 'analysis', 'fast', 'realtime', 'load', 'tutorial',
            'controller', 'plot', 'cameras', 'sweep', 'search', 'walking')
#: What the table and the JSON say for the UDP figures while no UDP connection is made.
NO_UDP = 'n/a (no UDP connection)'

#: (key, label, unit, target text, digits) in table order.
ROWS = (
    ('bare_physics_steps_per_s', 'bare mj_step, plain loop', 'steps/s', '', 0),
    ('physics_limit_steps_per_s', 'physics + law, plain loop', 'steps/s', '', 0),
    ('physics_numpy_law_steps_per_s', 'physics + numpy law, plain loop', 'steps/s', '', 0),
    ('unheard_topic_us_per_step', 'a topic nobody subscribes to', 'us/step', '< 1', 3),
    ('stand_us_per_step', 'balancing Stand: estimate + control', 'us/step', '<= 100', 1),
    ('laser_ms_per_sim_s', 'the head laser subscribed (40 scans)', 'ms/sim s', '', 2),
    ('spindle_step_us', 'the laser spindle spinning', 'us/step', '', 2),
    ('head_imu_ms_per_sim_s', 'the head IMU subscribed (1 kHz)', 'ms/sim s', '', 2),
    ('head_joint_states_ms_per_sim_s', 'the spindle joint state subscribed', 'ms/sim s', '', 2),
    ('walk_us_per_step', 'Walk, 6 steps: estimate + control (CPU)', 'us/step', '<= 150', 1),
    ('walk_offline_rtf', 'the same walk offline (no bag)', 'x real time', '>= 10', 2),
    ('stand_bare_ratio', 'Stand per step / bare mj_step', '', '<= 0.7', 2),
    ('stand_python_us_per_step', 'Stand, the Python reference (before)', 'us/step', '', 1),
    ('stand_python_bare_ratio', 'the same / bare mj_step', '', '', 2),
    ('walk_bare_ratio', 'Walk per step / bare mj_step', '', '<= 1.0', 2),
    ('walk_python_us_per_step', 'Walk, the Python reference (before)', 'us/step', '', 1),
    ('walk_python_bare_ratio', 'the same / bare mj_step', '', '', 2),
    ('walk_offline_bare_ratio', 'bare physics rtf / walk offline rtf', '', '<= 2.2', 2),
    ('offline_rtf', 'run_offline.py to a bag', 'x real time', '', 2),
    ('offline_ratio', 'offline_rtf*1000 / physics limit', '', '>= 0.8', 3),
    ('fast_rtf', 'node rtf:=0 + recorder', 'x real time', '>= 0.6 x bare/1000', 2),
    ('fast_bare_ratio', 'fast_rtf*1000 / bare mj_step', '', '>= 0.6', 3),
    ('fast_ratio', 'fast_rtf*1000 / physics limit', '', '', 3),
    ('fast_node_cpu', 'node CPU at rtf:=0', 'cores', '', 2),
    ('node_us_per_step', 'node CPU per step at rtf:=0', 'us', '<= 1.5 x bare', 1),
    ('node_bare_ratio', 'node_us_per_step / bare mj_step', '', '<= 1.5', 2),
    ('fast_recorder_cpu', 'recorder CPU at rtf:=0', 'cores', '', 2),
    ('recorder_us_per_step', 'recorder CPU per step at rtf:=0', 'us', '', 1),
    ('fast_state_publisher_cpu', 'robot_state_publisher CPU at rtf:=0', 'cores', '', 2),
    ('fast_master_cpu', 'rosmaster CPU at rtf:=0', 'cores', '< 0.01', 3),
    ('fast_rsp_master_cpu', 'rosmaster CPU, RSP publishing links', 'cores', '', 3),
    ('fast_rsp_state_publisher_cpu', 'robot_state_publisher CPU then', 'cores', '', 3),
    ('fast_rsp_rtf', 'node rtf:=0 + recorder, RSP on', 'x real time', '', 2),
    ('fast_cpu_us_per_step', 'all of them: CPU per step at rtf:=0', 'us', '', 1),
    ('fast_recorded_fraction', 'joint_states recorded at rtf:=0', 'fraction', '1', 4),
    ('fast_rosbag_rtf', 'same, `rosbag record` recording', 'x real time', '', 2),
    ('fast_rosbag_recorded_fraction', 'joint_states recorded (rosbag)', 'fraction', '', 4),
    ('realtime_rtf', 'node rtf:=1, achieved', 'x real time', '1.00 +- 0.01', 4),
    ('stand_realtime_rtf', 'same, balancing Stand (bdi_stand)', 'x real time', '1.00 +- 0.01',
     4),
    ('stand_lateness_p99_ms', 'its step lateness p99', 'ms', '< 2', 2),
    ('stand_node_us_per_step', 'its node CPU per step', 'us', '', 0),
    ('stand_recorder_us_per_step', 'its recorder CPU per step', 'us', '', 0),
    ('walk_realtime_rtf', 'same, walking: a 1 kHz streaming client', 'x real time',
     '1.00 +- 0.01', 4),
    ('walk_lateness_p99_ms', 'its step lateness p99', 'ms', '< 2', 2),
    ('walk_node_us_per_step', 'its node CPU per step', 'us', '', 0),
    ('walk_recorder_us_per_step', 'its recorder CPU per step', 'us', '', 0),
    ('walk_realtime_walked', 'that walk ended in Stand (1) or fell (0)', '', '', 0),
    ('lateness_p50_ms', 'step lateness p50', 'ms', '', 2),
    ('lateness_p99_ms', 'step lateness p99', 'ms', '< 2', 2),
    ('lateness_max_ms', 'step lateness max', 'ms', '', 2),
    ('js_transport_p50_ms', 'JointState transport p50', 'ms', '', 3),
    ('js_transport_p99_ms', 'JointState transport p99', 'ms', '', 3),
    ('cmd_latency_p50_ms_50hz', 'command latency p50, 50 Hz (net)', 'ms', '', 2),
    ('cmd_latency_p99_ms_50hz', 'command latency p99, 50 Hz (net)', 'ms', '< 2', 2),
    ('cmd_latency_p50_ms_1khz', 'command latency p50, 1 kHz (net)', 'ms', '', 2),
    ('cmd_latency_p99_ms_1khz', 'command latency p99, 1 kHz (net)', 'ms', '< 2', 2),
    ('cmd_latency_p50_ms_raw_50hz', 'command latency p50, 50 Hz (raw)', 'ms', '', 2),
    ('cmd_latency_p99_ms_raw_50hz', 'command latency p99, 50 Hz (raw)', 'ms', '', 2),
    ('cmd_latency_p50_ms_raw_1khz', 'command latency p50, 1 kHz (raw)', 'ms', '', 2),
    ('cmd_latency_p99_ms_raw_1khz', 'command latency p99, 1 kHz (raw)', 'ms', '', 2),
    ('cmd_applied_1khz', 'commands applied, 1 kHz', 'fraction', '', 3),
    ('load_rtf', 'node rtf:=1 under 3 x 2 kHz commands', 'x real time', '1.00 +- 0.05', 4),
    ('load_publish_rate_hz', 'commands published under load', 'msgs/s', '>= 5880 (98%)', 0),
    ('load_commands_lost', 'commands lost by the recorder', 'count', '0', 0),
    ('load_recorded_fraction', 'joint_states recorded under load', 'fraction', '1', 4),
    ('load_rss_growth_mib', 'simulator RSS growth under load', 'MiB', '<= 4', 2),
    ('shutdown_s', 'SIGINT until every process is gone', 's', '<= 5', 2),
    ('tutorial_command_rate_hz', 'step_and_fall commands (sim time)', 'Hz', '50 (45-51)', 2),
    ('tutorial_age_closed_form_share', 'step_and_fall: age windows at closed form', 'fraction',
     '>= 0.8', 3),
    ('bag_mb_per_min', 'step_and_fall bag per sim minute', 'MB/min', '<= 80 (lz4)', 1),
    ('analysis_s', 'analyze_bag, 60 s bag', 's', '< 2', 2),
    ('analysis_msgs_per_s', 'analyze_bag, 60 s bag', 'msgs/s', '', 0),
    ('rosbag_msgs_per_s', 'rosbag API, same topics', 'msgs/s', '', 0),
    ('analysis_speedup', 'analyze_bag / rosbag', 'x', '>= 5', 1),
    ('controller_none_node_us_per_step', 'no controller, rtf:=1: node CPU/step', 'us', '', 1),
    ('controller_tcp_age_p50_ms', 'echo_controller TCP: command age p50', 'ms', '', 2),
    ('controller_tcp_age_p99_ms', 'echo_controller TCP: command age p99', 'ms', '1', 2),
    ('controller_tcp_node_us_per_step', 'echo_controller TCP: node CPU/step', 'us', '<= 150',
     1),
    ('controller_udp_age_p50_ms', 'echo_controller UDP: command age p50', 'ms', '', 2),
    ('controller_udp_age_p99_ms', 'echo_controller UDP: command age p99', 'ms', '1', 2),
    ('controller_udp_node_us_per_step', 'echo_controller UDP: node CPU/step', 'us', '<= 150',
     1),
    ('controller_window_steps_per_s', 'sync window, rtf:=0: steps/s of pair', 'steps/s', '', 0),
    ('controller_window_age_p99_ms', 'sync window, rtf:=0: command age p99', 'ms', '1', 2),
    ('plot_off_realtime_rtf', 'node rtf:=1, no plotter', 'x real time', '', 4),
    ('plot_on_realtime_rtf', 'node rtf:=1, 3 x 1 kHz fields plotted', 'x real time', '', 4),
    ('plot_off_node_us_per_step', 'node CPU per step rtf:=0, no plotter', 'us', '', 1),
    ('plot_on_node_us_per_step', 'node CPU per step rtf:=0, plotted', 'us', '', 1),
    ('plot_on_plotter_cpu', 'plot_topics.py CPU at rtf:=1', 'cores', '', 2),
    ('cameras_none_rtf', 'node rtf:=1, cameras unwatched', 'x real time', '', 4),
    ('cameras_none_camera_cpu', 'camera node CPU then, per sim s', 's', '', 3),
    ('cameras_left_rtf', 'node rtf:=1, left image watched', 'x real time', '>= 0.99', 4),
    ('cameras_left_hz', 'left images per sim s', 'Hz', '', 1),
    ('cameras_left_camera_cpu', 'camera node CPU per sim s', 's', '', 3),
    ('cameras_left_node_cpu', 'simulator CPU per sim s', 's', '', 3),
    ('cameras_pair_rtf', 'node rtf:=1, both images watched', 'x real time', '', 4),
    ('cameras_pair_hz', 'pairs per sim s', 'Hz', '', 1),
    ('cameras_pair_camera_cpu', 'camera node CPU per sim s', 's', '', 3),
    ('cameras_course_none_rtf', 'VRC course rtf:=1, cameras unwatched', 'x real time', '',
     4),
    ('cameras_course_none_node_cpu', 'simulator CPU per sim s', 's', '', 3),
    ('cameras_course_left_rtf', 'VRC course rtf:=1, left image watched', 'x real time', '',
     4),
    ('cameras_course_left_node_cpu', 'simulator CPU per sim s', 's', '', 3),
    ('cameras_course_left_hz', 'left images per sim s', 'Hz', '', 1),
    ('cameras_course_left_camera_cpu', 'camera node CPU per sim s', 's', '', 3),
    ('sweep_runs_per_s_1', 'sweep.py offline runs, 1 worker', 'runs/s', '', 3),
    ('sweep_runs_per_s_2', 'sweep.py offline runs, 2 workers', 'runs/s', '', 3),
    ('sweep_scaling', 'sweep runs/s, 2 workers / 1', 'x', '', 2),
    ('search_wall_s', 'search.py: the step\'s search, wall', 's', '', 1),
    ('search_generations', 'search.py: its generations', 'count', '', 0),
    ('search_runs_per_s', 'search.py: offline runs per second', 'runs/s', '', 3),
    ('search_reproduced', 'search.py: found Stepping.yaml again', 'yes=1', '1', 0),
    ('walk_straight_runs', 'README\'s 20 straight steps: seeds', 'count', '', 0),
    ('walk_straight_within_fraction', 'of them walked, landings within 3 cm', 'fraction', '1',
     3),
    ('walk_straight_worst_landing_m', 'their worst landing', 'm', '', 4),
    ('walk_circle_runs', 'README\'s turn of the 2 m circle: seeds', 'count', '', 0),
    ('walk_circle_within_fraction', 'of them walked, landings within 3 cm', 'fraction', '1',
     3),
    ('walk_circle_worst_landing_m', 'their worst landing', 'm', '', 4),
    ('mode_switching_runs', 'DRCSim\'s mode-switching demo: seeds', 'count', '', 0),
    ('mode_switching_fell_fraction', 'of them fell', 'fraction', '0', 3),
    ('walk_pushes_runs', 'walks pushed every 5 s: seeds', 'count', '', 0),
    ('walk_pushes_fell_fraction_150n', 'of them fell, 150 N x 0.1 s', 'fraction', '0', 3),
    ('walk_pushes_fell_fraction_175n', 'of them fell, 175 N x 0.1 s', 'fraction', '', 3),
    ('walk_pushes_fell_fraction_200n', 'of them fell, 200 N x 0.1 s', 'fraction', '', 3),
    ('walk_phase_pushes_runs', 'one push at a phase of a step: runs', 'count', '', 0),
    ('walk_phase_pushes_fell_fraction_150n', 'of them fell, 150 N', 'fraction', '0', 3),
    ('walk_phase_pushes_fell_fraction_150n_unadjusted', 'same, no step adjustment', 'fraction',
     '', 3),
    ('walk_phase_pushes_fell_fraction_200n', 'of them fell, 200 N', 'fraction', '', 3),
    ('walk_phase_pushes_fell_fraction_250n', 'of them fell, 250 N', 'fraction', '', 3),
    ('walk_variations_runs', 'test_asi_live\'s walks varied: seeds', 'count', '', 0),
    ('walk_variations_fell_fraction', 'of them fell', 'fraction', '0', 3),
)
#: Rows shown as NO_UDP when the controller section ran without a UDP connection.
UDP_ROWS = ('controller_udp_age_p50_ms', 'controller_udp_age_p99_ms',
            'controller_udp_node_us_per_step')


@dataclass(frozen=True)
class Target:
    """A figure's target, judged on its median: low <= value <= high (strict: < and >).

    `per_bare`: the bounds are multiples of a bare mj_step (steps/s or µs), known only once
    `bare_physics_steps_per_s` has been measured in the same bench run.
    """

    low: float = -math.inf
    high: float = math.inf
    strict: bool = False
    per_bare: str = ''  # '' | 'rtf' (x bare steps/s / 1000) | 'us' (x 1e6 / bare steps/s)
    lz4_only: bool = False  # a bag size: only with the launch's lz4 chunks

    def bounds(self, medians: dict[str, float]) -> tuple[float, float] | None:
        if not self.per_bare:
            return self.low, self.high
        bare = medians.get('bare_physics_steps_per_s')
        if bare is None or not bare > 0:
            return None
        scale = bare / 1000.0 if self.per_bare == 'rtf' else 1e6 / bare
        return self.low * scale, self.high * scale

    def met(self, value: float, medians: dict[str, float]) -> bool | None:
        """True / False; None when it cannot be judged in this run (no bare figure)."""
        bounds = self.bounds(medians)
        if bounds is None:
            return None
        low, high = bounds
        if self.strict:
            return low < value < high
        return low <= value <= high


@dataclass(frozen=True)
class Budget:
    """How long each section measures: `--quick` (a smoke test), the default (`make bench`,
    about 11 minutes) or `--full` (the windows of the bench before it had a default, and
    the whole search). Every figure is measured in each; only their windows differ."""

    name: str
    physics_steps: int
    unheard_calls: int
    analysis_bag_s: float
    sweep_runs: int
    #: The search's generations; None: the whole search (search_time.GENERATIONS), which
    #: also says whether it found Stepping.yaml again.
    search_generations: int | None
    fast_window_s: float
    realtime_window_s: float
    latency_s: tuple[tuple[float, float], ...]  # (command rate Hz, seconds at it)
    load_s: float
    controller_window_s: float
    plot_window_s: float
    #: Runs of the untargeted figures that need launches or clusters of their own (the fast
    #: section's `rosbag record` and robot_state_publisher variants, the plot and sweep
    #: sections); None: --runs.
    side_runs: int | None = None
    #: The search's population in its few generations (None: Stepping.yaml's 8).
    search_popsize: int | None = None
    #: The least runs of the physics and offline sections, whose medians need a few even
    #: when --runs is 1; the smoke test's one is enough to produce each figure.
    min_offline_runs: int = 5

    def side(self, runs: int) -> int:
        """How many of `runs` measure the untargeted launches too."""
        return runs if self.side_runs is None else min(runs, self.side_runs)


BUDGETS = {
    'quick': Budget('quick', 2000, 5000, 10.0, 2, 1, 2.0, 4.0, ((50.0, 1.0), (1000.0, 0.5)),
                    4.0, 2.0, 2.0, search_popsize=2, min_offline_runs=1),
    'default': Budget('default', 5000, 20000, 60.0, 8, 1, 5.0, 15.0,
                      ((50.0, 4.0), (1000.0, 2.0)), 15.0, 6.0, 6.0, side_runs=1),
    'full': Budget('full', 5000, 20000, 60.0, 16, None, 10.0, 30.0,
                   ((50.0, 6.0), (1000.0, 3.0)), 30.0, 15.0, 15.0),
}


#: The targets (bench/README.md), by JSON key.
TARGETS = {
    'unheard_topic_us_per_step': Target(high=1.0, strict=True),
    # The open AtlasSimInterface's Stand at 1 kHz beside a recorder and a client.
    'stand_us_per_step': Target(high=100.0),
    # Walking: the controller in the 1 ms loop, and offline runs of it (issue's goals).
    'walk_us_per_step': Target(high=150.0),
    'walk_offline_rtf': Target(low=10.0),
    # The compiled core's targets, as multiples of the same run's bare mj_step.
    'stand_bare_ratio': Target(high=0.7),
    'walk_bare_ratio': Target(high=1.0),
    'walk_offline_bare_ratio': Target(high=2.2),
    'offline_ratio': Target(low=0.8),
    # Standing with the left camera watched, real time holds (its node at niceness 10).
    'cameras_left_rtf': Target(low=0.99),
    'fast_rtf': Target(low=0.6, per_bare='rtf'),
    'fast_bare_ratio': Target(low=0.6),
    'node_us_per_step': Target(high=1.5, per_bare='us'),
    'node_bare_ratio': Target(high=1.5),
    'fast_recorded_fraction': Target(low=1.0, high=1.0),
    # With TF on (the simulator publishing the links), the master idles.
    'fast_master_cpu': Target(high=0.01, strict=True),
    'realtime_rtf': Target(low=0.99, high=1.01),
    # Real time holds with the balancing Stand in the loop and the recorder.
    'stand_realtime_rtf': Target(low=0.99, high=1.01),
    'stand_lateness_p99_ms': Target(high=2.0, strict=True),
    # ... and walking, with a client streaming a WALK on every state.
    'walk_realtime_rtf': Target(low=0.99, high=1.01),
    'walk_lateness_p99_ms': Target(high=2.0, strict=True),
    'lateness_p99_ms': Target(high=2.0, strict=True),
    'cmd_latency_p99_ms_50hz': Target(high=2.0, strict=True),
    'cmd_latency_p99_ms_1khz': Target(high=2.0, strict=True),
    'load_rtf': Target(low=0.95, high=1.05),
    # The floods pace to 6000/s on average; 2 % short (start and end of their windows) is
    # still the load asked for, more means they were starved of CPU.
    'load_publish_rate_hz': Target(low=0.98 * 6000.0),
    'load_commands_lost': Target(low=0.0, high=0.0),
    'load_recorded_fraction': Target(low=1.0, high=1.0),
    'load_rss_growth_mib': Target(high=4.0),
    'shutdown_s': Target(high=5.0),
    'tutorial_command_rate_hz': Target(low=45.0, high=51.0),
    # The 50 Hz port's command ages at their closed form in most windows: it keeps up.
    'tutorial_age_closed_form_share': Target(low=0.8),
    'bag_mb_per_min': Target(high=80.0, lz4_only=True),
    'analysis_s': Target(high=2.0, strict=True),
    'analysis_speedup': Target(low=5.0),
    # Serving a 1 kHz controller at real time: a fraction of a core, every step answered.
    'controller_tcp_node_us_per_step': Target(high=150.0),
    'controller_udp_node_us_per_step': Target(high=150.0),
    'controller_tcp_age_p99_ms': Target(low=1.0, high=1.0),
    'controller_udp_age_p99_ms': Target(low=1.0, high=1.0),
    # The window's promise: every step obeys the answer to the state before it.
    'controller_window_age_p99_ms': Target(low=1.0, high=1.0),
    # The search, run again whole, finds the committed step (one machine).
    'search_reproduced': Target(low=1.0, high=1.0),
    # The README's walks: every seed walks them, each landing within 3 cm.
    'walk_straight_within_fraction': Target(low=1.0, high=1.0),
    'walk_circle_within_fraction': Target(low=1.0, high=1.0),
    # Mixed control as DRC-era demos used it: no seed falls.
    'mode_switching_fell_fraction': Target(low=0.0, high=0.0),
    # The push while walking (15 N s) and the live test's walks: no seed falls.
    'walk_pushes_fell_fraction_150n': Target(low=0.0, high=0.0),
    'walk_phase_pushes_fell_fraction_150n': Target(low=0.0, high=0.0),
    'walk_variations_fell_fraction': Target(low=0.0, high=0.0),
}

#: The keys each section must produce (a crash or an empty window shows as a missing key).
EXPECTED = {
    'physics': ('bare_physics_steps_per_s', 'physics_limit_steps_per_s',
                'physics_numpy_law_steps_per_s', 'unheard_topic_us_per_step',
                'stand_us_per_step', 'walk_us_per_step', 'walk_offline_rtf',
                'laser_ms_per_sim_s', 'spindle_step_us', 'head_imu_ms_per_sim_s',
                'head_joint_states_ms_per_sim_s', 'stand_python_us_per_step',
                'walk_python_us_per_step',
                *(f'{name}_bare_ratio' for name in ('stand', 'stand_python', 'walk',
                                                    'walk_python', 'walk_offline'))),
    'offline': ('offline_rtf', 'offline_ratio'),
    'analysis': ('analysis_s', 'rosbag_s', 'analysis_msgs_per_s', 'rosbag_msgs_per_s',
                 'analysis_speedup'),
    'fast': ('fast_rtf', 'fast_recorded_fraction', 'fast_node_cpu', 'fast_recorder_cpu',
             'node_us_per_step', 'recorder_us_per_step', 'fast_cpu_us_per_step',
             'fast_rosbag_rtf', 'fast_rosbag_recorded_fraction', 'fast_master_cpu',
             'fast_rsp_rtf', 'fast_rsp_master_cpu', 'fast_rsp_state_publisher_cpu'),
    'realtime': ('realtime_rtf', 'lateness_p50_ms', 'lateness_p99_ms', 'lateness_max_ms',
                 'stand_realtime_rtf', 'stand_lateness_p99_ms', 'walk_realtime_rtf',
                 'walk_lateness_p99_ms', 'walk_realtime_walked',
                 'js_transport_p50_ms', 'js_transport_p99_ms', 'cmd_latency_p50_ms',
                 'cmd_latency_p99_ms', 'cmd_applied_1khz',
                 *(f'cmd_latency_p{pct}_ms{raw}_{rate}' for pct in (50, 99)
                   for raw in ('', '_raw') for rate in ('50hz', '1khz'))),
    'load': ('load_rtf', 'load_publish_rate_hz', 'load_commands_lost',
             'load_recorded_fraction', 'load_rss_growth_mib', 'shutdown_s'),
    'tutorial': ('tutorial_command_rate_hz', 'bag_mb_per_min', 'tutorial_age_closed_form_share'),
    # The UDP keys only once the node serves UDPROS (else the JSON says NO_UDP).
    'controller': ('controller_none_node_us_per_step', 'controller_tcp_age_p50_ms',
                   'controller_tcp_age_p99_ms',
                   'controller_tcp_node_us_per_step', 'controller_window_steps_per_s',
                   'controller_window_age_p99_ms'),
    'cameras': tuple(f'cameras_{case}_{key}'
                     for case in ('none', 'left', 'pair', 'course_none', 'course_left')
                     for key in ('rtf', 'hz', 'node_cpu', 'camera_cpu')),
    'plot': ('plot_off_realtime_rtf', 'plot_on_realtime_rtf', 'plot_off_node_us_per_step',
             'plot_on_node_us_per_step', 'plot_on_plotter_cpu'),
    'sweep': ('sweep_runs_per_s_1', 'sweep_runs_per_s_2', 'sweep_scaling'),
    # search_reproduced only from a whole search (--full, --only search).
    'search': ('search_wall_s', 'search_generations', 'search_runs_per_s'),
    # The other forces only in the budgets that push harder (bench/walking.BUDGETS).
    'walking': ('walk_straight_runs', 'walk_straight_within_fraction',
                'walk_straight_worst_landing_m', 'walk_circle_runs',
                'walk_circle_within_fraction', 'walk_circle_worst_landing_m',
                'mode_switching_runs', 'mode_switching_fell_fraction',
                'walk_pushes_runs', 'walk_pushes_fell_fraction_150n', 'walk_phase_pushes_runs',
                'walk_phase_pushes_fell_fraction_150n', 'walk_variations_runs',
                'walk_variations_fell_fraction'),
}
#: Keys computed from two sections, expected when both ran.
EXPECTED_ACROSS = {('physics', 'fast'): ('fast_ratio', 'fast_bare_ratio', 'node_bare_ratio')}


def verdicts(medians: dict[str, float], compression: str) -> dict[str, str]:
    """'met' or 'MISSED' for every measured figure with a target, judged on its median;
    'unjudged (...)' only where this run has nothing to judge it by."""
    result = {}
    for key, target in TARGETS.items():
        if key not in medians:
            continue
        if target.lz4_only and compression not in ('lz4', DEFAULT_COMPRESSION):
            result[key] = f'unjudged ({compression} chunks; the target is for lz4)'
            continue
        met = target.met(medians[key], medians)
        if met is None:
            result[key] = 'unjudged (no bare_physics_steps_per_s: run the physics section)'
        else:
            result[key] = 'met' if met else 'MISSED'
    return result


def invalid_figures(medians: dict[str, float], sections: list[str]) -> list[str]:
    """The keys the sections run should have produced but did not, or that are not finite."""
    expected = [key for section in sections for key in EXPECTED[section]]
    for pair, keys in EXPECTED_ACROSS.items():
        if set(pair) <= set(sections):
            expected += keys
    bad = [key for key in expected if key not in medians]
    bad += [key for key, value in medians.items() if not math.isfinite(value)]
    return sorted(set(bad))


def parse_args(argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--runs', type=int, default=3, help='runs per figure (default 3)')
    parser.add_argument('--only',
                        help=f'comma-separated sections to run (default: {",".join(SECTIONS)}); '
                             'naming search runs the whole search (unless --quick)')
    windows = parser.add_mutually_exclusive_group()
    windows.add_argument('--quick', action='store_true',
                         help='short windows (a smoke test, not a measurement)')
    windows.add_argument('--full', action='store_true',
                         help='the long windows and the whole search (about 30 minutes)')
    parser.add_argument('--launch-file', default='atlas.launch',
                        help='launch file to benchmark instead of the package\'s atlas.launch '
                             '(a path, or a file name in tutorial_atlas_control); it must take '
                             'the same arguments (gui, real_time_factor, record, bag_dir)')
    parser.add_argument('--keep', action='store_true', help='keep the scratch directory')
    parser.add_argument('--compression', choices=COMPRESSIONS,
                        help='chunk compression of every bag recorded (default: the launch\'s)')
    args = parser.parse_args(argv)
    only = args.only if args.only is not None else ','.join(SECTIONS)
    args.sections = [s.strip() for s in only.split(',') if s.strip()]
    unknown = set(args.sections) - set(SECTIONS)
    if unknown:
        parser.error(f'unknown section(s) {", ".join(sorted(unknown))}; choose from '
                     + ', '.join(SECTIONS))
    if args.runs < 1:
        parser.error('--runs must be >= 1')
    if args.launch_file.endswith('.launch') and os.path.sep in args.launch_file:
        args.launch_file = str(Path(args.launch_file).resolve())
    args.budget = BUDGETS['quick' if args.quick else 'full' if args.full else 'default']
    # The whole search with --full, or when --only names it; else a short fixed budget.
    args.whole_search = args.full or (args.only is not None and 'search' in args.sections
                                      and not args.quick)
    return args


def add(samples: dict[str, list[float]], values: dict[str, float]) -> None:
    for key, value in values.items():
        samples.setdefault(key, []).append(value)


def run_offline(args: argparse.Namespace, samples: dict[str, list[float]],
                loads: dict[str, str]) -> None:
    import offline

    if 'physics' in args.sections:
        import node_loop

        with Section('physics', loads):
            for run in range(max(args.runs, args.budget.min_offline_runs)):
                steps = args.budget.physics_steps
                rates = {'bare_physics_steps_per_s': node_loop.bare_physics_run(steps),
                         'physics_limit_steps_per_s': offline.physics_run(steps=steps),
                         'physics_numpy_law_steps_per_s':
                             offline.physics_run(steps=steps, compiled_law=False)}
                log(f'physics run {run + 1}: ' + ', '.join(
                    f'{key} {rate:.0f}' for key, rate in rates.items()))
                add(samples, rates)
                unheard_us = node_loop.unheard_topic_run(args.budget.unheard_calls)
                log(f'physics run {run + 1}: an unheard topic costs {unheard_us:.3f} us/step')
                add(samples, {'unheard_topic_us_per_step': unheard_us})
                head = node_loop.head_sensors_run()
                log(f'physics run {run + 1}: the head laser costs '
                    f'{head["laser_ms_per_sim_s"]:.2f} ms per sim s, its IMU '
                    f'{head["head_imu_ms_per_sim_s"]:.2f}, the spindle\'s joint state '
                    f'{head["head_joint_states_ms_per_sim_s"]:.2f}; the spinning spindle '
                    f'{head["spindle_step_us"]:.2f} us/step')
                add(samples, head)
                # Compiled (as shipped) and the pure Python reference, interleaved: the
                # compiled core's before/after, paired on the same load.
                stand_us = offline.stand_run(steps=steps)
                with offline.python_reference():
                    stand_python_us = offline.stand_run(steps=steps)
                log(f'physics run {run + 1}: the balancing Stand costs {stand_us:.1f} us/step '
                    f'({stand_python_us:.1f} in Python)')
                add(samples, {'stand_us_per_step': stand_us,
                              'stand_python_us_per_step': stand_python_us})
                if run < args.runs:  # a walk is 7 s of sim time: --quick walks once
                    walk_us, walk_rtf = offline.walk_run()
                    with offline.python_reference():
                        walk_python_us, _ = offline.walk_run()
                    log(f'physics run {run + 1}: Walk costs {walk_us:.1f} us/step '
                        f'({walk_python_us:.1f} in Python), walks offline at {walk_rtf:.2f}x '
                        'real time')
                    add(samples, {'walk_us_per_step': walk_us, 'walk_offline_rtf': walk_rtf,
                                  'walk_python_us_per_step': walk_python_us})
    if 'offline' in args.sections:
        steps_per_s = offline.steps_per_sim_second()
        with Section('offline', loads), tempfile.TemporaryDirectory(prefix='tac_bench_') as tmp:
            for run in range(max(args.runs, args.budget.min_offline_runs)):
                # Interleaved with the plain loop: both see the same load.
                physics = offline.physics_run(steps=args.budget.physics_steps)
                rtf = offline.offline_run(Path(tmp))
                log(f'offline run {run + 1}: {rtf:.2f}x real time; plain loop {physics:.0f} '
                    'steps/s')
                add(samples, {'offline_rtf': rtf,
                              'offline_ratio': rtf * steps_per_s / physics})
    if 'analysis' in args.sections:
        path = offline.run_bag(Path(tempfile.gettempdir()) / 'tac_bench_cache',
                               args.budget.analysis_bag_s)
        count = offline.analysis_message_count(path)
        offline.analysis_run(path)  # warm the page cache and imports for both readers
        with Section('analysis', loads):
            for run in range(args.runs):
                analysis_s = offline.analysis_run(path)
                rosbag_s, read = offline.rosbag_run(path)
                if read != count:
                    raise BenchError(f'rosbag read {read} messages, expected {count}')
                log(f'analysis run {run + 1}: analyze_bag {analysis_s:.2f} s, '
                    f'rosbag {rosbag_s:.2f} s for {count} messages')
                add(samples, {'analysis_s': analysis_s, 'rosbag_s': rosbag_s,
                              'analysis_msgs_per_s': count / analysis_s,
                              'rosbag_msgs_per_s': count / rosbag_s,
                              'analysis_speedup': rosbag_s / analysis_s})


def run_sweep(args: argparse.Namespace, samples: dict[str, list[float]],
              loads: dict[str, str]) -> None:
    """Offline runs per second through sweep.py's Dask engine on 1 and 2 workers."""
    if 'sweep' not in args.sections:
        return
    import sweep_rate

    with Section('sweep', loads):
        for run in range(args.budget.side(args.runs)):
            runs = args.budget.sweep_runs
            one, two = sweep_rate.runs_per_s(1, runs), sweep_rate.runs_per_s(2, runs)
            log(f'sweep run {run + 1}: {one:.3f} runs/s on 1 worker, {two:.3f} on 2')
            add(samples, {'sweep_runs_per_s_1': one, 'sweep_runs_per_s_2': two,
                          'sweep_scaling': two / one})


def run_search(args: argparse.Namespace, samples: dict[str, list[float]],
               loads: dict[str, str], work_dir: Path) -> None:
    """The wall time of the search that found Stepping.yaml's step, once whatever
    --runs says: whole (about ten minutes on 2 cores) with --full or `--only search`, else
    the budget's few generations (the search's speed: search_runs_per_s)."""
    if 'search' not in args.sections:
        return
    import search_time

    with Section('search', loads):
        timed = search_time.search_time(
            work_dir, None if args.whole_search else args.budget.search_generations,
            args.budget.search_popsize)
        figures = {'search_wall_s': timed.wall_s, 'search_generations': timed.generations,
                   'search_runs_per_s': timed.runs / timed.wall_s}
        if timed.reproduced is not None:
            figures['search_reproduced'] = float(timed.reproduced)
        log(f'search: {timed.generations} generations, {timed.runs} runs in '
            f'{timed.wall_s:.1f} s' + ('' if timed.reproduced is None else
                                      f'; found Stepping.yaml again: {timed.reproduced}'))
        add(samples, figures)


def run_walking(args: argparse.Namespace, samples: dict[str, list[float]],
                loads: dict[str, str]) -> None:
    """How often pushed and varied walks fall, over seeds: once, whatever --runs says (the
    figures are fractions of seeds, not medians of runs)."""
    if 'walking' not in args.sections:
        return
    import walking

    with Section('walking', loads):
        add(samples, walking.walking_figures(walking.BUDGETS[args.budget.name], log=log))


def run_online(args: argparse.Namespace, samples: dict[str, list[float]],
               loads: dict[str, str], work_dir: Path) -> None:
    if not {'fast', 'realtime', 'load', 'controller', 'plot', 'cameras'} & set(args.sections):
        return
    import online

    master = Master(work_dir)
    try:
        log(f'started a private roscore on port {master.port}')
        master.wait_online()
        os.environ.update({'ROS_MASTER_URI': master.uri,
                           'ROS_LOG_DIR': str(work_dir / 'ros_log')})
        import rospy

        # Before any launch sets /use_sim_time: our node keeps wall time, no /clock client.
        rospy.init_node('tac_bench', disable_signals=True)
        probes = online.make_probes()
        if 'fast' in args.sections:
            with Section('fast', loads):
                run_fast(args, samples, master, probes, work_dir)
        if 'realtime' in args.sections:
            with Section('realtime', loads):
                run_realtime(args, samples, master, probes, work_dir)
        if 'load' in args.sections:
            with Section('load', loads):
                run_load(args, samples, master, probes, work_dir)
        if 'controller' in args.sections:
            with Section('controller', loads):
                run_controller(args, samples, master, probes, work_dir)
        if 'plot' in args.sections:
            with Section('plot', loads):
                run_plot(args, samples, master, probes, work_dir)
        if 'cameras' in args.sections:
            with Section('cameras', loads):
                run_cameras(args, samples, master, probes, work_dir)
        rospy.signal_shutdown('bench done')
    finally:
        master.close()


def run_load(args, samples, master, probes, work_dir) -> None:  # noqa: ANN001
    import load

    for run in range(args.runs):
        values = load.load_run(master, args.launch_file, probes, work_dir, f'load{run + 1}',
                               duration_s=args.budget.load_s)
        log(f'load run {run + 1}: rtf {values["load_rtf"]:.4f}, '
            f'{values["load_commands_lost"]:.0f} commands lost, RSS growth '
            f'{values["load_rss_growth_mib"]:.2f} MiB, shutdown {values["shutdown_s"]:.2f} s')
        add(samples, values)
        if values['load_commands_lost']:
            args.keep = True
            log(f'load run {run + 1} lost commands: its bag and launch log stay in {work_dir}')


def run_controller(args, samples, master, probes, work_dir) -> None:  # noqa: ANN001
    """Each run: echo_controller over TCP, then over UDP (at real_time_factor:=1), then
    with the synchronization window at real_time_factor:=0 (bench/controller.py)."""
    import controller
    import offline
    from probes import RawRecorder

    from tutorial_atlas_control import topics

    per_sim_s = offline.steps_per_sim_second()
    statistics = RawRecorder(topics.CONTROLLER_STATISTICS)
    window_s = args.budget.controller_window_s
    for run in range(args.runs):
        values: dict[str, float] = {}
        for transport in ('tcp', 'udp'):
            figures = controller.age_run(
                master, args.launch_file, probes.clock, statistics, work_dir,
                f'controller_{transport}{run + 1}', transport, warmup_s=2.0,
                window_s=window_s, per_sim_s=per_sim_s, floor=transport == 'tcp')
            if figures is None:
                log(f'controller run {run + 1}: {NO_UDP}: echo_controller --transport udp '
                    'never connected (the node serves no UDPROS)')
                args.udp = NO_UDP
            else:
                values.update(figures)
        values.update(controller.window_run(
            master, args.launch_file, probes.clock, statistics, work_dir,
            f'controller_window{run + 1}', warmup_s=2.0, window_s=window_s,
            per_sim_s=per_sim_s))
        log(f'controller run {run + 1}: node '
            f'{values["controller_none_node_us_per_step"]:.0f} us/step without a controller, '
            f'{values["controller_tcp_node_us_per_step"]:.0f} with it over TCP; TCP age p99 '
            f'{values["controller_tcp_age_p99_ms"]:.2f} ms, UDP age p99 '
            + (f'{values["controller_udp_age_p99_ms"]:.2f} ms'
               if 'controller_udp_age_p99_ms' in values else NO_UDP)
            + f', window {values["controller_window_steps_per_s"]:.0f} steps/s')
        add(samples, values)


def run_plot(args, samples, master, probes, work_dir) -> None:  # noqa: ANN001
    import offline
    import plot_cost

    for run in range(args.budget.side(args.runs)):
        values = plot_cost.plot_run(master, args.launch_file, probes, work_dir, f'plot{run + 1}',
                                    warmup_s=2.0, window_s=args.budget.plot_window_s,
                                    steps_per_sim_s=offline.steps_per_sim_second())
        log(f'plot run {run + 1}: rtf {values["plot_off_realtime_rtf"]:.4f} without, '
            f'{values["plot_on_realtime_rtf"]:.4f} with the plotter; node '
            f'{values["plot_off_node_us_per_step"]:.1f} / '
            f'{values["plot_on_node_us_per_step"]:.1f} us per step; plotter '
            f'{values["plot_on_plotter_cpu"]:.2f} cores')
        add(samples, values)


def run_cameras(args, samples, master, probes, work_dir) -> None:  # noqa: ANN001
    import camera_cost

    for run in range(args.budget.side(args.runs)):
        values = camera_cost.camera_run(master, args.launch_file, probes, work_dir,
                                        f'cameras{run + 1}', warmup_s=3.0,
                                        window_s=args.budget.plot_window_s)
        log(f'cameras run {run + 1}: rtf {values["cameras_left_rtf"]:.4f} with the left image '
            f'at {values["cameras_left_hz"]:.1f} Hz (camera node '
            f'{values["cameras_left_camera_cpu"]:.2f} s per sim s), pair at '
            f'{values["cameras_pair_hz"]:.1f} Hz, course left at '
            f'{values["cameras_course_left_hz"]:.1f} Hz')
        add(samples, values)


def run_tutorial(args: argparse.Namespace, samples: dict[str, list[float]],
                 loads: dict[str, str], work_dir: Path) -> None:
    if 'tutorial' not in args.sections:
        return
    import load

    with Section('tutorial', loads):
        for run in range(args.runs):
            values = load.tutorial_run(work_dir, f'tutorial{run + 1}')
            log(f'tutorial run {run + 1}: commands at '
                f'{values["tutorial_command_rate_hz"]:.2f} Hz of sim time, bag '
                f'{values["bag_mb_per_min"]:.1f} MB per sim minute')
            add(samples, values)


def run_fast(args, samples, master, probes, work_dir) -> None:  # noqa: ANN001
    """Each run: the launch's default recorder (atlas_recorder, the headline fast_* keys),
    then `rosbag record` (fast_rosbag_*)."""
    import online

    variants = (('atlas_recorder', 'fast', None), ('rosbag', 'fast_rosbag', None),
                # Debian's robot_state_publisher publishing the links (the
                # master's and its CPU, beside the default's).
                ('atlas_recorder', 'fast_rsp', {'tf_publisher': 'robot_state_publisher'}))
    for run in range(args.runs):
        values = {}
        # The headline (atlas_recorder) every run; the variants in the budget's side runs.
        for recorder, prefix, extra in variants[:3 if run < args.budget.side(args.runs) else 1]:
            values.update(online.fast_run(
                master, args.launch_file, probes, work_dir, f'{prefix}{run + 1}',
                warmup_s=2.0, window_s=args.budget.fast_window_s, recorder=recorder,
                prefix=prefix, extra_args=extra))
        log(f'fast run {run + 1}: rtf {values["fast_rtf"]:.3f} (atlas_recorder), master '
            f'{values["fast_master_cpu"]:.4f} cores' + (
                '' if 'fast_rosbag_rtf' not in values else
                f'; {values["fast_rosbag_rtf"]:.3f} (rosbag record), with '
                f'robot_state_publisher master {values["fast_rsp_master_cpu"]:.4f} (it: '
                f'{values.get("fast_rsp_state_publisher_cpu", 0.0):.3f})'))
        add(samples, values)


def run_realtime(args, samples, master, probes, work_dir) -> None:  # noqa: ANN001
    import online

    latency_s = dict(args.budget.latency_s)
    for run in range(args.runs):
        transport = online.js_transport(master, probes, work_dir)
        values = online.realtime_run(
            master, args.launch_file, probes, work_dir, f'realtime{run + 1}', warmup_s=2.0,
            window_s=args.budget.realtime_window_s, latency_s=latency_s,
            transport_ms=transport['js_transport_p50_ms'])
        values.update(transport)
        log(f'realtime run {run + 1}: rtf {values["realtime_rtf"]:.4f}, lateness p99 '
            f'{values["lateness_p99_ms"]:.2f} ms, command latency p99 (net) '
            f'{values["cmd_latency_p99_ms_50hz"]:.2f} ms at 50 Hz, '
            f'{values["cmd_latency_p99_ms_1khz"]:.2f} ms at 1 kHz')
        add(samples, values)
        stand = online.stand_realtime_run(master, args.launch_file, probes, work_dir,
                                          f'stand{run + 1}', args.budget.realtime_window_s)
        log(f'realtime run {run + 1}: in the balancing Stand rtf '
            f'{stand["stand_realtime_rtf"]:.4f}, lateness p99 '
            f'{stand["stand_lateness_p99_ms"]:.2f} ms, node '
            f'{stand.get("stand_node_us_per_step", float("nan")):.0f} us/step, recorder '
            f'{stand.get("stand_recorder_us_per_step", float("nan")):.0f}')
        add(samples, stand)
        walk = online.walk_realtime_run(master, args.launch_file, probes, work_dir,
                                        f'walk{run + 1}', online.WALK_STEPS)
        log(f'realtime run {run + 1}: walking (a 1 kHz streaming client) rtf '
            f'{walk["walk_realtime_rtf"]:.4f}, lateness p99 '
            f'{walk["walk_lateness_p99_ms"]:.2f} ms, node '
            f'{walk.get("walk_node_us_per_step", float("nan")):.0f} us/step, recorder '
            f'{walk.get("walk_recorder_us_per_step", float("nan")):.0f}, '
            f'{"walked" if walk["walk_realtime_walked"] else "fell"}')
        add(samples, walk)


def summarize(samples: dict[str, list[float]],
              per_sim_s: float | None = None) -> dict[str, float]:
    """The medians, and the figures derived from several keys (added to `samples` per run
    too). `per_sim_s`: simulated steps per sim second (default: the model's timestep)."""
    medians = {key: statistics.median(values) for key, values in samples.items()}
    if per_sim_s is None and samples:
        import offline

        per_sim_s = offline.steps_per_sim_second()
    if 'fast_rtf' in samples and 'physics_limit_steps_per_s' in medians:
        physics = medians['physics_limit_steps_per_s']
        samples['fast_ratio'] = [rtf * per_sim_s / physics for rtf in samples['fast_rtf']]
        medians['fast_ratio'] = medians['fast_rtf'] * per_sim_s / physics
    for process, key in (('node', 'node_us_per_step'), ('recorder', 'recorder_us_per_step')):
        if f'fast_{process}_cpu' in samples:  # the process's CPU (µs) per simulated step
            samples[key] = [cpu * 1e6 / (rtf * per_sim_s) for cpu, rtf
                            in zip(samples[f'fast_{process}_cpu'], samples['fast_rtf'])]
            medians[key] = statistics.median(samples[key])
    # What one sim step costs the machine (a launch with tf:=false has no state publisher).
    cpu_keys = [key for key in (f'fast_{name}_cpu' for name in
                                ('node', 'recorder', 'state_publisher', 'master'))
                if len(samples.get(key, ())) == len(samples.get('fast_rtf', ()))]
    if 'fast_rtf' in samples and 'fast_node_cpu' in cpu_keys:
        samples['fast_cpu_us_per_step'] = [
            sum(cpus) * 1e6 / (rtf * per_sim_s)
            for rtf, *cpus in zip(samples['fast_rtf'], *(samples[key] for key in cpu_keys))]
        medians['fast_cpu_us_per_step'] = statistics.median(samples['fast_cpu_us_per_step'])
    if 'bare_physics_steps_per_s' in medians:
        add_bare_ratios(samples, medians, per_sim_s)
    for pct in (50, 99):  # the headline: the worse of the two command rates
        rates = [medians.get(f'cmd_latency_p{pct}_ms_{label}') for label in ('50hz', '1khz')]
        if all(value is not None for value in rates):
            medians[f'cmd_latency_p{pct}_ms'] = max(rates)
    return medians


def bare_ratios(keys: list[str], bare_steps_per_s: float,
                per_sim_s: float) -> dict[str, tuple[str, Callable[[float], float]]]:
    """Each figure's ratio to the same run's bare mj_step, by the figure's key: `X_us_per_step`
    (a cost) as X_bare_ratio = µs / bare µs; `fast_rtf` as fast_rtf × steps per sim second /
    bare steps/s; `walk_offline_rtf` as bare physics's real-time factor / the walk's."""
    bare_us = 1e6 / bare_steps_per_s
    ratios: dict[str, tuple[str, Callable[[float], float]]] = {
        key: (key.removesuffix('_us_per_step') + '_bare_ratio', lambda us: us / bare_us)
        for key in keys if key.endswith('_us_per_step') and key != 'unheard_topic_us_per_step'}
    if 'fast_rtf' in keys:
        ratios['fast_rtf'] = ('fast_bare_ratio', lambda rtf: rtf * per_sim_s / bare_steps_per_s)
    if 'walk_offline_rtf' in keys:
        ratios['walk_offline_rtf'] = ('walk_offline_bare_ratio',
                                      lambda rtf: bare_steps_per_s / per_sim_s / rtf)
    return ratios


def add_bare_ratios(samples: dict[str, list[float]], medians: dict[str, float],
                    per_sim_s: float) -> None:
    """bare_ratios' figures, per run and as the ratio of the medians (the issue's targets are
    ratios: a host 40 % slower moves both sides)."""
    bare = medians['bare_physics_steps_per_s']
    for key, (name, ratio) in bare_ratios(list(medians), bare, per_sim_s).items():
        samples[name] = [ratio(value) for value in samples[key]]
        medians[name] = ratio(medians[key])


def table(samples: dict[str, list[float]], loads: dict[str, str], runs: int,
          compression: str, judged: dict[str, str], udp: str = '', budget: str = '') -> str:
    lines = [f'tutorial_atlas_control benchmark, {os.cpu_count()} CPUs; per section: load '
             'average (1/5/15 min) at its start, CPU busy and hypervisor steal % during it, '
             'its wall time:']
    lines += [f'  {section:<9} {load}' for section, load in loads.items()]
    if budget:
        lines.append(f'windows: {budget}')
    lines += [f'bags: chunk compression {compression}',
              f'min / median / max over {runs} runs (physics: over >= 5 runs)', '']
    header = (f'{"figure":<38} {"min":>10} {"median":>10} {"max":>10}  {"unit":<12} '
              f'{"target":<20} verdict')
    lines += [header, '-' * len(header)]
    for key, label, unit, target, digits in ROWS:
        values = samples.get(key)
        if not values and udp and key in UDP_ROWS:
            lines.append(f'{label:<38} {udp}')
            continue
        if not values:
            continue
        low, mid, high = min(values), statistics.median(values), max(values)
        lines.append((f'{label:<38} {low:>10.{digits}f} {mid:>10.{digits}f} '
                      f'{high:>10.{digits}f}  {unit:<12} {target:<20} '
                      f'{judged.get(key, "")}').rstrip())
    missed = [key for key, verdict in judged.items() if verdict == 'MISSED']
    lines += ['', f'targets: {len(judged) - len(missed)} of {len(judged)} met'
              + (f'; MISSED: {", ".join(missed)}' if missed else '')]
    return '\n'.join(lines)


def budget_text(budget: Budget, whole_search: bool | None) -> str:
    """The table's line saying which windows were measured, and what --full adds
    (`whole_search` None: no search section)."""
    text = {'quick': '--quick (a smoke test, not a measurement)',
            'default': 'the default (--full: the longer windows and the whole search)',
            'full': '--full'}[budget.name]
    if whole_search is None:
        return text
    search = ('the whole search' if whole_search
              else f'the search for {budget.search_generations} generation(s)')
    return f'{text}; {search}'


def main(argv: list[str] | None = None) -> int:
    args = parse_args(sys.argv[1:] if argv is None else argv)
    started = time.monotonic()
    try:
        check_environment()
    except BenchError as err:
        print(f'run_bench: {err}', file=sys.stderr)
        return 2
    if args.compression:
        os.environ['TAC_BAG_COMPRESSION'] = args.compression
    compression = os.environ.get('TAC_BAG_COMPRESSION') or DEFAULT_COMPRESSION
    work_dir = Path(tempfile.mkdtemp(prefix='tac_bench_'))
    samples: dict[str, list[float]] = {}
    loads: dict[str, str] = {}
    ok = False
    try:
        run_offline(args, samples, loads)
        run_sweep(args, samples, loads)
        run_search(args, samples, loads, work_dir)
        run_walking(args, samples, loads)
        run_online(args, samples, loads, work_dir)
        run_tutorial(args, samples, loads, work_dir)
        ok = True
    except AtlasControlError as err:
        print(f'run_bench: {err}', file=sys.stderr)
    except KeyboardInterrupt:
        print('run_bench: interrupted', file=sys.stderr)
    except Exception:  # noqa: BLE001 - report, clean up, fail
        traceback.print_exc()
    finally:
        if ok and not args.keep:
            shutil.rmtree(work_dir, ignore_errors=True)
        else:
            # Bags are large; keep logs only unless asked to keep everything.
            if not args.keep:
                for bag_dir in work_dir.glob('*_bags'):
                    shutil.rmtree(bag_dir, ignore_errors=True)
            log(f'scratch directory kept: {work_dir}')
    if not ok:
        return 1
    medians = summarize(samples)
    judged = verdicts(medians, compression)
    invalid = invalid_figures(medians, args.sections)
    udp = getattr(args, 'udp', '')
    print(table(samples, loads, args.runs, compression, judged, udp,
                budget_text(args.budget, args.whole_search if 'search' in args.sections
                            else None)))
    result: dict[str, object] = {key: round(value, 4) for key, value in medians.items()}
    result.update({'runs': args.runs, 'quick': args.quick, 'budget': args.budget.name,
                   'cpus': os.cpu_count(),
                   'compression': compression,
                   'load_avg': load_average(), 'wall_s': round(time.monotonic() - started, 1),
                   'missed': sorted(key for key, verdict in judged.items()
                                    if verdict == 'MISSED'),
                   'invalid': invalid})
    if udp:
        result['controller_udp'] = udp
    if 'search' in args.sections:
        result['search'] = 'whole' if args.whole_search else 'short'
    print(json.dumps(result, sort_keys=True), flush=True)
    if invalid:  # a missed target is a figure; a missing or NaN one is a broken bench
        print(f'run_bench: missing or not finite: {", ".join(invalid)}', file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
