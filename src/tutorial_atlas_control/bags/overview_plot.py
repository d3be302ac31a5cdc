"""The analysis plot's first page: what a person looks for first in a run, on one picture.

The pelvis height (over the terrain under it on a VRC course run) with the fall threshold
and each fall (in fall_report's words: sim time, seconds after the try's first command), the
tries as bands labelled with what was played,
the played trajectories' waypoint boundaries, the control modes (a refused one marked),
and the tracking error of the few joints that tracked worst. The per-joint pages are
report.plot_joints, behind analyze_bag.py's --plot-joints.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from tutorial_atlas_control.bags.analysis import Analysis, TryAnalysis
from tutorial_atlas_control.bags.course_terrain import above_ground, terrain_heights
from tutorial_atlas_control.bags.reader import BagData
from tutorial_atlas_control.bags.tries import window
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.fall_report import fall_when
from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.sim import FALL_HEIGHT_M
from tutorial_atlas_control.trajectories import load_trajectory

__all__ = ['WORST_JOINTS', 'axis_shift_s', 'draw_overview', 'tracking_errors', 'waypoint_times']

#: How many of the worst-tracked joints the first page shows.
WORST_JOINTS = 4
#: The page (inches, at the report's 100 dpi: 1100 x 750 px).
OVERVIEW_SIZE_IN = (11.0, 7.5)
#: Alternating shades of the tries' bands.
TRY_SHADES = ('#f2f2f2', '#dde8f5')


def waypoint_times(data: BagData) -> list[float]:
    """Times (s from bag start) at which each played trajectory starts (its first command
    after the player's log line) and its waypoints are due (plus their durations). A
    trajectory file no longer where the bag says it was adds none."""
    commands = data.commands
    if commands is None or not len(commands.t_s):
        return []
    times: list[float] = []
    for t_s, played in data.played:
        later = np.flatnonzero(commands.t_s >= t_s)
        if not len(later):
            continue
        try:
            waypoints = load_trajectory(played.file, played.name)
        except (AtlasControlError, OSError):
            continue
        start_s = float(commands.t_s[later[0]])
        times.append(start_s)  # the trajectory's start: its first command
        times.extend((start_s + np.cumsum([w.duration_s for w in waypoints])).tolist())
    return [t_s for t_s in times if t_s <= data.duration_s]  # not past the recording


def tracking_errors(analysis: Analysis) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """|commanded - measured| (rad) over time of the WORST_JOINTS joints with the highest
    RMS, worst first; each try on its own (a reset drops the held command)."""
    ranked = sorted(((joint.rms_error_rad, name) for name, joint in analysis.joints.items()
                     if joint.rms_error_rad is not None and name in JOINT_NAMES),
                    reverse=True)[:WORST_JOINTS]
    tries = analysis.tries or []
    parts = ([window(analysis.data, each.window.start_s, each.window.end_s) for each in tries]
             or [analysis.data])
    errors: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for _rms, name in ranked:
        t_all, e_all = [], []
        for part in parts:
            states, commands = part.joint_states, part.commands
            if states is None or commands is None or not len(commands.t_s):
                continue
            rows = np.searchsorted(commands.t_s, states.t_s, side='right') - 1
            held = np.full(len(states.t_s), np.nan)
            held[rows >= 0] = commands.held[rows[rows >= 0], JOINT_NAMES.index(name)]
            measured = states.position[:, states.names.index(name)]
            t_all.append(np.append(states.t_s, np.nan))  # a gap between tries
            e_all.append(np.append(np.abs(held - measured), np.nan))
        if t_all:
            errors[name] = (np.concatenate(t_all), np.concatenate(e_all))
    return errors


def axis_shift_s(data: BagData) -> float:
    """What turns the bag's run times into sim time on the page's axis: the bag's start
    in sim time, unless sim time went back (reset_simulation), then 0 (bag time)."""
    return data.start_time_s if len(data.epoch_shifts_s) <= 1 else 0.0


def _fall_label(each: TryAnalysis) -> str:
    fall = each.fall
    assert fall is not None
    return f'try {each.window.number} fell {fall_when(fall.sim_time_s, fall.after_command_s)}'


def _draw_pelvis(ax: Any, analysis: Analysis, shift_s: float) -> None:
    pelvis = analysis.data.pelvis
    if pelvis is None or not len(pelvis.t_s):
        ax.text(0.5, 0.5, 'no pelvis data (/ground_truth_odom)', ha='center', va='center',
                transform=ax.transAxes)
        return
    # On a course run the height the fall is judged by: over the terrain under the pelvis.
    height_m = (above_ground(pelvis.position_m, terrain_heights())[:, 2]
                if analysis.over_terrain else pelvis.position_m[:, 2])
    ax.plot(pelvis.t_s + shift_s, height_m, color='tab:green',
            label='pelvis over the terrain' if analysis.over_terrain else 'pelvis height')
    ax.axhline(FALL_HEIGHT_M, color='tab:red', linestyle=':', label='fall threshold')
    # On a sim-time axis a fall sits at the sim time its label (the live log's) gives.
    falls = [(each.fall.sim_time_s if shift_s else each.analysis.fall_time_s,
              _fall_label(each)) for each in analysis.tries
             if each.fall is not None and each.analysis.fall_time_s is not None]
    for number, (t_s, label) in enumerate(falls):
        ax.plot([t_s], [FALL_HEIGHT_M], 'rX', markersize=9,
                label='fall' if number == 0 else None)
        ax.annotate(label, (t_s, FALL_HEIGHT_M), xytext=(6, -14 - 11 * (number % 2)),
                    textcoords='offset points', fontsize=8, color='tab:red')
    ax.set_ylabel('pelvis over the terrain (m)' if analysis.over_terrain
                  else 'pelvis height (m)')


def _draw_tries(axes: list[Any], analysis: Analysis, shift_s: float) -> None:
    """A band per try, labelled with its number and what was played in it."""
    for each in analysis.tries:
        end_s = min(each.window.end_s, analysis.data.duration_s)
        for ax in axes:
            ax.axvspan(each.window.start_s + shift_s, end_s + shift_s,
                       color=TRY_SHADES[each.window.number % 2], zorder=0)
        played = ', '.join(p.name for p in each.trajectories) or 'no trajectory logged'
        axes[0].annotate(f'try {each.window.number}: {played}',
                         (each.window.start_s + shift_s, 0.0),
                         xycoords=('data', 'axes fraction'), xytext=(3, 4),
                         textcoords='offset points', fontsize=8, fontweight='bold')


def _draw_marks(axes: list[Any], analysis: Analysis, refused: set[str],
                shift_s: float) -> None:
    """Waypoint boundaries (dotted) and control modes (dashed, named above the page)."""
    for number, t_s in enumerate(waypoint_times(analysis.data)):
        for ax in axes:
            ax.axvline(t_s + shift_s, color='tab:purple', linestyle=':', linewidth=0.8,
                       label='start, waypoints due' if number == 0 and ax is axes[0] else None)
    for number, (t_s, mode) in enumerate(analysis.data.modes):
        text = f'{mode} (refused)' if mode in refused else mode
        for ax in axes:
            ax.axvline(t_s + shift_s, color='gray', linestyle='--', linewidth=0.8)
        axes[0].annotate(text, (t_s + shift_s, 1.0), xycoords=('data', 'axes fraction'),
                         xytext=(2, 2 + 10 * (number % 2)), textcoords='offset points',
                         fontsize=8, color='tab:red' if mode in refused else 'black')


def _draw_tracking(ax: Any, analysis: Analysis, shift_s: float) -> None:
    errors = tracking_errors(analysis)
    for name, (t_s, error_rad) in errors.items():
        rms = analysis.joints[name].rms_error_rad
        ax.plot(t_s + shift_s, error_rad, linewidth=1.0, label=f'{name} (RMS {rms:.3g} rad)')
    if not errors:
        ax.text(0.5, 0.5, 'no joint tracking to show (no commands or joint states)',
                ha='center', va='center', transform=ax.transAxes)
    ax.set_ylabel('|commanded - measured|\n(rad)')
    shown = 'the worst-tracked joint' if len(errors) == 1 else (
        f'the {len(errors)} worst-tracked joints')
    ax.set_title(f'{shown}, by RMS over the run', fontsize=9, loc='left')


def draw_overview(analysis: Analysis, refused: set[str]) -> Any:
    """The first page as a matplotlib figure (save_figure writes it)."""
    import matplotlib.pyplot as plt  # noqa: PLC0415 - only needed with --plot

    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=OVERVIEW_SIZE_IN,
                                      gridspec_kw={'height_ratios': [3, 2]})
    shift_s = axis_shift_s(analysis.data)
    _draw_pelvis(top, analysis, shift_s)
    _draw_tracking(bottom, analysis, shift_s)
    _draw_tries([top, bottom], analysis, shift_s)
    _draw_marks([top, bottom], analysis, refused, shift_s)
    for ax in (top, bottom):
        if ax.get_legend_handles_labels()[0]:
            ax.legend(loc='upper right', fontsize=8)
    bottom.set_xlabel('sim time (s), as the live log' if shift_s else
                      'time from the bag\'s start (s): sim time went back (reset_simulation); '
                      'falls labelled in sim time')
    tries = len(analysis.tries)
    fig.suptitle(f'{analysis.data.path.name}: {tries} {"try" if tries == 1 else "tries"}',
                 y=0.995)
    return fig
