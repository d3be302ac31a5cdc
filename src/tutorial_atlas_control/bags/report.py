"""Present a bag :class:`~tutorial_atlas_control.bags.analysis.Analysis`: text, JSON, CSV, plot."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from tutorial_atlas_control import topics
from tutorial_atlas_control.bags.analysis import (
    EFFORT_LIMIT_TOLERANCE_NM,
    MOVED_RANGE_RAD,
    Analysis,
    TryAnalysis,
    input_timeline,
)
from tutorial_atlas_control.bags.overview_plot import draw_overview
from tutorial_atlas_control.bags.reader import BagData
from tutorial_atlas_control.bags.tries import RUN_START
from tutorial_atlas_control.control_modes import is_refused_mode
from tutorial_atlas_control.errors import BagAnalysisError
from tutorial_atlas_control.fall_report import fall_line, fall_when
from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.sim import FALL_HEIGHT_M

__all__ = ['analysis_to_json', 'format_summary', 'plot_joints', 'plot_run', 'write_csv']

#: Most points drawn per line; longer series are decimated (plots, not analysis).
PLOT_MAX_POINTS = 4000
#: Height of one subplot (inches) and the figure width (inches).
PLOT_ROW_HEIGHT_IN = 1.6
PLOT_WIDTH_IN = 11.0
#: How many of the worst-tracked joints the short summary names.
SUMMARY_WORST_JOINTS = 3
#: After a mode the simulator refused (the bag records every string published).
REFUSED_NOTE = '  (refused: not a control mode; the mode did not change)'
#: Significant digits written to CSV files.
CSV_FORMAT = '%.10g'


def _fmt(value: float | None, spec: str, unit: str = '') -> str:
    return 'n/a' if value is None else f'{value:{spec}}{unit}'


def _topic_lines(data: BagData, trajectory: str | None = None,
                 resets: list[tuple[float, str]] | None = None) -> list[str]:
    lines = [f'Bag:      {data.path}',
             f'Duration: {data.duration_s:.3f} s (start {data.start_time_s:.3f} s)']
    if trajectory is not None:
        lines.append(f'Trajectory: {trajectory}')
    lines.append('Topics:')
    width = max((len(name) for name in data.topics), default=0)
    type_width = max((len(topic.msgtype) for topic in data.topics.values()), default=0)
    for name, topic in data.topics.items():
        lines.append(f'  {name:<{width}}  {topic.msgtype:<{type_width}}  {topic.count:>8} msgs  '
                     f'{_fmt(topic.rate_hz, "9.2f", " Hz")}')
    if not data.topics:
        lines.append('  (none: the bag is empty)')
    lines.append('Control modes (and resets):')
    # VRCPlugin's inputs (mode, teleport, wrench, ...) on the same timeline, when applied.
    events = sorted([*data.modes, *(resets or []), *input_timeline(data)],
                    key=lambda entry: entry[0])
    lines.extend(f'  {t_s:9.3f} s  {text}' + (REFUSED_NOTE if is_refused_mode(text) and
                                                (t_s, text) in data.modes else '')
                 for t_s, text in events)
    if not data.modes:
        lines.append(f'  (no {topics.CONTROL_MODE} messages)')
    return lines


def _fall_line(analysis: Analysis) -> str:
    if analysis.fell is None:
        return f'Fall:     unknown ({analysis.unavailable.get("fall", "no pelvis data")})'
    first = analysis.first_fall()
    over = ' over the terrain' if analysis.over_terrain else ''
    if analysis.fell and first is not None:
        number, fall = first
        where = '' if number is None else f'try {number}, '
        return (f'Fall:     FELL {fall_when(fall.sim_time_s, fall.after_command_s)} ({where}'
                f'{analysis.fall_time_s:.3f} s from bag start; pelvis below {FALL_HEIGHT_M} m'
                f'{over}; lowest {analysis.min_pelvis_height_m:.3f} m)')
    return (f'Fall:     no (pelvis stayed above {FALL_HEIGHT_M} m{over}; lowest '
            f'{analysis.min_pelvis_height_m:.3f} m)')


def _commands_line(analysis: Analysis) -> str:
    commands = analysis.data.commands
    count = 0 if commands is None else len(commands.t_s)
    if not count:
        return f'Commands: none on {topics.JOINT_COMMANDS}'
    age = ('' if analysis.command_age_mean_s is None else
           f'; command age mean {analysis.command_age_mean_s * 1e3:.1f} ms, '
           f'max {analysis.command_age_max_s * 1e3:.1f} ms')
    return (f'Commands: {count} on {topics.JOINT_COMMANDS} at '
            f'{_fmt(analysis.command_rate_hz, ".1f", " Hz")}{age}')


def _tracking_lines(analysis: Analysis) -> list[str]:
    if 'joints' in analysis.unavailable:
        return [f'Tracking: unavailable ({analysis.unavailable["joints"]})']
    commands = analysis.data.commands
    if commands is None or not len(commands.t_s):
        return ['Tracking: no joint command to track (what moved the joints was a behaviour '
                'or a cheat)']
    if not analysis.joints:
        return [f'Tracking: no joint moved (measured range <= {MOVED_RANGE_RAD} rad, '
                'constant commands)']
    name_width = max(len(name) for name in analysis.joints)
    lines = ['Tracking (joints that moved; |command - measured| at each joint state, '
             'latest command held):',
             f'  {"joint":<{name_width}}  {"RMS (rad)":>10}  {"max (rad)":>10}  {"samples":>8}']
    for name, joint in analysis.joints.items():
        lines.append(f'  {name:<{name_width}}  {_fmt(joint.rms_error_rad, "10.5f")}  '
                     f'{_fmt(joint.max_error_rad, "10.5f")}  {joint.samples:>8}'
                     + ('' if joint.commanded else '  (never commanded)'))
    return lines


def _effort_lines(analysis: Analysis) -> list[str]:
    if analysis.effort_saturation is None:
        return [f'Effort:   unavailable ({analysis.unavailable.get("effort_saturation")})']
    if not analysis.effort_saturation:
        return ['Effort:   no joint reached its effort limit']
    lines = [f'Effort limit reached (|effort| >= limit - {EFFORT_LIMIT_TOLERANCE_NM} N·m):']
    for name, sat in analysis.effort_saturation.items():
        lines.append(f'  {name:<10} limit {sat.limit_nm:8.3f} N·m  for {sat.duration_s:.3f} s '
                     f'(first at {sat.first_time_s:.3f} s)')
    return lines


def _try_lines(each: TryAnalysis) -> list[str]:
    """Two lines for one try: when and what, then fall, commands and tracking."""
    a, window = each.analysis, each.window
    played = ', then '.join(f"'{p.name}'" for p in each.trajectories) or '(none logged)'
    lines = [f'  try {window.number}: {window.start_s:.3f} to {window.end_s:.3f} s (sim time '
             f'{a.data.sim_time_s(window.start_s):.3f} s at {window.cause}); trajectory {played}']
    if a.fell is None:
        fall = 'fall unknown'
    elif a.fell and each.fall is not None:
        fall = f'FELL {fall_when(each.fall.sim_time_s, each.fall.after_command_s)}'
    elif each.fall is not None:  # the simulator saw it, the 100 Hz odometry did not
        fall = f'fell {fall_when(each.fall.sim_time_s, each.fall.after_command_s)}'
    else:
        fall = f'no fall (lowest {a.min_pelvis_height_m:.3f} m)'
    count = 0 if a.data.commands is None else len(a.data.commands.t_s)
    commands = f'{count} commands at {_fmt(a.command_rate_hz, ".1f", " Hz")}'
    if a.command_age_mean_s is not None:
        commands += f', age mean {a.command_age_mean_s * 1e3:.1f} ms'
    tracked = [(joint.rms_error_rad, name) for name, joint in a.joints.items()
               if joint.rms_error_rad is not None]
    tracking = ('' if not tracked else
                '; worst tracking RMS {:.4f} rad ({})'.format(*max(tracked)))
    lines.append(f'         {fall}; {commands}{tracking}')
    return lines


def format_summary(analysis: Analysis, trajectory: str | None = None) -> str:
    """The human-readable report, several lines, no trailing newline.

    `trajectory`: what the bag's /rosout says was played (run_log), shown when given.
    """
    resets = [(each.window.start_s, f'{each.window.cause}: try {each.window.number} begins')
              for each in analysis.tries if each.window.cause != RUN_START]
    lines = _topic_lines(analysis.data, trajectory, resets)
    lines += [_fall_line(analysis), _commands_line(analysis)]
    lines += _tracking_lines(analysis) + _effort_lines(analysis)
    tries = analysis.tries
    if len(tries) > 1 or (tries and tries[0].window.cause != RUN_START):
        lines.append(f'Tries ({len(tries)}; a try starts at the bag\'s start or at a reset; '
                     'times from bag start):')
        for each in tries:
            lines += _try_lines(each)
    lines.extend(f'Warning:  {warning}' for warning in analysis.warnings)
    return '\n'.join(lines)


def short_summary(analysis: Analysis, table: bool = False, tracking: bool = True) -> str:
    """The demo's summary of a run (make demo, run_offline.py), a few lines: the fall, then
    the joints that tracked worst; with `table`, every joint that moved, a row each; without
    `tracking` (a walk: the behaviours drove every joint, no command did), the fall alone."""
    lines = ['=== summary ===']
    first = analysis.first_fall()
    if analysis.fell is None:
        lines.append(f'fall: unknown (no {topics.GROUND_TRUTH_ODOM} in the bag)')
    elif first is not None:
        lines.append(fall_line(FALL_HEIGHT_M, first[1].sim_time_s, first[1].after_command_s))
    else:
        lines.append('the robot did not fall (lowest pelvis height '
                     f'{analysis.min_pelvis_height_m:.2f} m)')
    if not tracking:
        return '\n'.join(lines)
    tracked = sorted(((joint.rms_error_rad, joint.max_error_rad, name)
                      for name, joint in analysis.joints.items()
                      if joint.rms_error_rad is not None), reverse=True)
    if not tracked:
        lines.append('tracking: no joint moved under a command')
    elif table:
        lines.append('tracking error of the joints that moved (commanded vs measured), '
                     'worst first:')
        lines.extend(f'  {name:10s} RMS {rms:.4f} rad, max {peak:.4f} rad'
                     for rms, peak, name in tracked)
    else:
        worst = ', '.join(f'{name} {rms:.3f} rad' for rms, _peak, name in
                          tracked[:SUMMARY_WORST_JOINTS])
        lines.append(f'worst tracking (RMS |commanded - measured|, of {len(tracked)} joints '
                     f'that moved): {worst}; --table lists them all')
    return '\n'.join(lines)


def json_safe(value: Any) -> Any:
    """NaN/inf -> None and numpy scalars -> Python, so the output is strict JSON."""
    if isinstance(value, dict):
        return {key: json_safe(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_safe(item) for item in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def analysis_to_json(analysis: Analysis, extra: dict[str, Any] | None = None) -> str:
    """The analysis as one JSON object (strict JSON: no NaN), plus the keys of `extra`."""
    return json.dumps(json_safe({**analysis.to_dict(), **(extra or {})}), indent=2,
                      allow_nan=False)


def _save_csv(path: Path, header: list[str], columns: list[np.ndarray]) -> Path:
    table = np.column_stack(columns) if columns else np.empty((0, len(header)))
    np.savetxt(path, table, delimiter=',', header=','.join(header), comments='', fmt=CSV_FORMAT)
    return path


def write_csv(data: BagData, directory: Path | str) -> list[Path]:
    """Write joint_states.csv, joint_commands.csv and pelvis_pose.csv (those available).

    Columns: `t` (s from bag start) then, for joint states, `<joint>_position` for
    every joint, then `_velocity`, then `_effort`; for commands, `<joint>_position` as
    sent (nan = not in that message); for the pelvis, x y z (m), qx qy qz qw,
    vx vy vz (m/s), wx wy wz (rad/s).

    Raises:
        BagAnalysisError: The directory cannot be created or written.
    """
    directory = Path(directory)
    written = []
    try:
        directory.mkdir(parents=True, exist_ok=True)
        states = data.joint_states
        if states is not None:
            quantities = ('position', 'velocity', 'effort')
            header = ['t'] + [f'{name}_{quantity}' for quantity in quantities
                              for name in states.names]
            written.append(_save_csv(directory / 'joint_states.csv', header,
                                     [states.t_s, states.position, states.velocity,
                                      states.effort]))
        if data.commands is not None:
            header = ['t'] + [f'{name}_position' for name in JOINT_NAMES]
            written.append(_save_csv(directory / 'joint_commands.csv', header,
                                     [data.commands.t_s, data.commands.position]))
        pelvis = data.pelvis
        if pelvis is not None:
            header = ['t', 'x', 'y', 'z', 'qx', 'qy', 'qz', 'qw', 'vx', 'vy', 'vz', 'wx', 'wy',
                      'wz']
            written.append(_save_csv(directory / 'pelvis_pose.csv', header,
                                     [pelvis.t_s, pelvis.position_m, pelvis.orientation_xyzw,
                                      pelvis.linear_velocity_m_s, pelvis.angular_velocity_rad_s]))
    except OSError as err:
        msg = f'Could not write CSV files to {directory}: {err.strerror or err}.'
        raise BagAnalysisError(msg) from err
    return written


def _decimate(t_s: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    step = max(1, len(t_s) // PLOT_MAX_POINTS)
    return t_s[::step], values[::step]


def _plot_joint(ax: Any, name: str, data: BagData, resets_s: list[float]) -> None:
    """Commanded (steps, held to the end of the run or the next reset, `resets_s`) and
    measured position of joint `name`."""
    states, commands = data.joint_states, data.commands
    if commands is not None and name in JOINT_NAMES:
        sent = commands.position[:, JOINT_NAMES.index(name)]
        finite = np.isfinite(sent)
        if finite.any():
            t_s, values = commands.t_s[finite], sent[finite]
            if states is not None and len(states.t_s) and states.t_s[-1] > t_s[-1]:
                t_s, values = np.append(t_s, states.t_s[-1]), np.append(values, values[-1])
            if resets_s:  # a reset drops the held command: break the line there
                t_s = np.append(t_s, resets_s)
                values = np.append(values, np.full(len(resets_s), np.nan))
                order = np.argsort(t_s, kind='stable')
                t_s, values = t_s[order], values[order]
            ax.plot(t_s, values, drawstyle='steps-post', color='tab:orange', label='commanded')
    if states is not None:
        ax.plot(*_decimate(states.t_s, states.position[:, states.names.index(name)]),
                color='tab:blue', linewidth=1.0, label='measured')
    ax.set_ylabel(f'{name}\n(rad)', fontsize=8)


def _plot_pelvis(ax: Any, analysis: Analysis) -> None:
    """Pelvis height, the fall threshold and the fall."""
    pelvis = analysis.data.pelvis
    assert pelvis is not None
    ax.plot(*_decimate(pelvis.t_s, pelvis.position_m[:, 2]), color='tab:green', label='pelvis z')
    ax.axhline(FALL_HEIGHT_M, color='tab:red', linestyle=':', label='fall threshold')
    falls = analysis.falls()
    if falls:
        ax.plot(falls, [FALL_HEIGHT_M] * len(falls), 'rx', label='fall')
    ax.set_ylabel('pelvis\nheight (m)', fontsize=8)


def _mark_modes(axes: list[Any], modes: list[tuple[float, str]]) -> None:
    """A vertical line per control-mode change, labelled above the first subplot."""
    for ax in axes:
        for t_s, _ in modes:
            ax.axvline(t_s, color='gray', linestyle='--', linewidth=0.8)
    for number, (t_s, mode) in enumerate(modes):
        # Alternate label heights so modes that change in quick succession stay legible.
        refused = is_refused_mode(mode)
        axes[0].annotate(f'{mode} (refused)' if refused else mode, (t_s, 1.0),
                         xycoords=('data', 'axes fraction'), xytext=(2, 2 + 10 * (number % 2)),
                         textcoords='offset points', fontsize=8,
                         color='tab:red' if refused else 'black')


def _mark_resets(axes: list[Any], analysis: Analysis) -> None:
    """A red vertical line at each reset that starts a try, labelled with the try."""
    for each in analysis.tries:
        if each.window.cause == RUN_START:
            continue
        for ax in axes:
            ax.axvline(each.window.start_s, color='tab:red', linewidth=1.2)
        axes[-1].annotate(f'try {each.window.number} ({each.window.cause})',
                          (each.window.start_s, 0.0), xycoords=('data', 'axes fraction'),
                          xytext=(2, 2), textcoords='offset points', fontsize=8,
                          color='tab:red')


def save_figure(fig: Any, path: Path | str) -> Path:
    """Lay out, write and close a matplotlib figure.

    Raises:
        BagAnalysisError: The image cannot be written.
    """
    import matplotlib.pyplot as plt  # noqa: PLC0415 - only needed with --plot

    fig.tight_layout()
    try:
        fig.savefig(path, dpi=100)
    except OSError as err:
        msg = f'Could not write the plot to {path}: {err.strerror or err}.'
        raise BagAnalysisError(msg) from err
    finally:
        plt.close(fig)
    return Path(path)


def plot_run(analysis: Analysis, path: Path | str) -> Path:
    """The first page (overview_plot): pelvis height and falls, the tries with what was
    played and its waypoints, the control modes, the worst-tracked joints.

    Raises:
        BagAnalysisError: The image cannot be written.
    """
    import matplotlib  # noqa: PLC0415 - only needed with --plot

    matplotlib.use('Agg')
    refused = {mode for _, mode in analysis.data.modes if is_refused_mode(mode)}
    return save_figure(draw_overview(analysis, refused), path)


def plot_joints(analysis: Analysis, path: Path | str) -> Path:
    """The per-joint pages: commanded vs measured positions of the joints that moved, and
    the pelvis height, one subplot each, sharing the time axis; control-mode changes are
    vertical lines labelled with the mode.

    Raises:
        BagAnalysisError: The image cannot be written.
    """
    import matplotlib  # noqa: PLC0415 - only needed with --plot-joints

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt  # noqa: PLC0415

    data, path = analysis.data, Path(path)
    names = list(analysis.joints)
    rows = len(names) + (data.pelvis is not None)
    fig, axes = plt.subplots(max(rows, 1), 1, sharex=True, squeeze=False,
                             figsize=(PLOT_WIDTH_IN, PLOT_ROW_HEIGHT_IN * max(rows, 2) + 1.0))
    axes = list(axes[:, 0])
    resets_s = [each.window.start_s for each in analysis.tries if each.window.cause != RUN_START]
    for ax, name in zip(axes, names):
        _plot_joint(ax, name, data, resets_s)
    if data.pelvis is not None:
        _plot_pelvis(axes[len(names)], analysis)
    if rows == 0:
        axes[0].text(0.5, 0.5, 'nothing to plot: no joint moved and no pelvis data',
                     ha='center', va='center', transform=axes[0].transAxes)
    _mark_modes(axes, data.modes)
    _mark_resets(axes, analysis)
    for ax in axes[:1] + axes[-1:] if rows else []:
        ax.legend(loc='upper right', fontsize=7)
    axes[-1].set_xlabel('time from bag start (s)')
    fig.suptitle(f'{data.path.name}: commanded vs measured', y=0.995)
    return save_figure(fig, path)
