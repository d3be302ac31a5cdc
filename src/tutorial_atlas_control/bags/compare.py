"""Compare two recorded runs (`analyze_bag.py A.bag --compare B.bag`): how far apart are they?

Two runs of one trajectory start it at different times (a live run waits for traj_yaml to
start, an offline run does not), so they are aligned on the first applied joint command:
the first /atlas/joint_commands at or after the switch to User mode (the first command at
all when the bag has no mode switch). Times below are seconds from that command.

Over the time both runs cover after it, at each of A's joint states: B's measured
positions (linearly interpolated) and each run's latest commanded position are compared
per joint; B's pelvis height likewise at A's /ground_truth_odom times. Fall times are each
run's (analysis.py's definition), from its first applied command.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from tutorial_atlas_control import topics
from tutorial_atlas_control.bags.analysis import (
    Analysis,
    analyze_try,
)
from tutorial_atlas_control.bags.analysis import first_applied_command_s as first_applied_command
from tutorial_atlas_control.bags.reader import read_bag
from tutorial_atlas_control.bags.report import json_safe, save_figure
from tutorial_atlas_control.bags.run_log import PlayedTrajectory
from tutorial_atlas_control.errors import BagAnalysisError
from tutorial_atlas_control.joints import JOINT_INDEX
from tutorial_atlas_control.sim import FALL_HEIGHT_M

__all__ = ['ALIGNED_ON', 'Comparison', 'JointDifference', 'compare_analyses', 'compare_bags',
           'format_comparison', 'plot_comparison', 'comparison_to_json']

#: What the runs are aligned on, as the output says.
ALIGNED_ON = 'first applied joint command'
ALIGNED_ON_DETAIL = ('the first /atlas/joint_commands at or after the switch to User mode '
                     '(header stamp; the first command if the bag has no mode switch)')
#: Plot: decimate longer series to about this many points.
PLOT_MAX_POINTS = 4000
PLOT_ROW_HEIGHT_IN = 1.6
PLOT_WIDTH_IN = 11.0
#: The plot spans the compared window, plus this fraction of it on each side.
PLOT_MARGIN = 0.02


@dataclass(frozen=True)
class JointDifference:
    """A - B for one joint (rad): measured RMS and max |diff|, commanded RMS (None: no data)."""

    rms_diff_rad: float | None
    max_diff_rad: float | None
    command_rms_diff_rad: float | None


@dataclass(frozen=True)
class Comparison:
    """Two runs aligned on their first applied command; times in s from that command."""

    a: Analysis
    b: Analysis
    trajectory_a: PlayedTrajectory | None
    trajectory_b: PlayedTrajectory | None
    align_a_s: float
    align_b_s: float
    window_s: tuple[float, float]
    joints: dict[str, JointDifference]
    moved: list[str]
    pelvis_height_rms_diff_m: float | None
    pelvis_height_max_diff_m: float | None
    fall_time_a_s: float | None
    fall_time_b_s: float | None

    @property
    def fall_time_diff_s(self) -> float | None:
        """B's fall time minus A's (s), when both fell."""
        if self.fall_time_a_s is None or self.fall_time_b_s is None:
            return None
        return self.fall_time_b_s - self.fall_time_a_s

    def to_dict(self) -> dict[str, Any]:
        """The --json document (keys: see analyze_bag.py --help)."""
        def run(analysis: Analysis, played: PlayedTrajectory | None) -> dict[str, Any]:
            return {'bag': str(analysis.data.path),
                    'trajectory': None if played is None else {'file': played.file,
                                                               'name': played.name}}
        return {
            'a': run(self.a, self.trajectory_a),
            'b': run(self.b, self.trajectory_b),
            'aligned_on': {'event': ALIGNED_ON, 'time_a': self.align_a_s,
                           'time_b': self.align_b_s, 'window': list(self.window_s)},
            'joints': {name: {'rms_diff': joint.rms_diff_rad, 'max_diff': joint.max_diff_rad,
                              'command_rms_diff': joint.command_rms_diff_rad}
                       for name, joint in self.joints.items()},
            'pelvis_height_rms_diff': self.pelvis_height_rms_diff_m,
            'fall_time_a': self.fall_time_a_s,
            'fall_time_b': self.fall_time_b_s,
        }


def first_applied_command_s(analysis: Analysis) -> float:
    """Time (s from bag start) of the run's first applied command; see the module docstring.

    Raises:
        BagAnalysisError: the bag has no joint commands (nothing to align on).
    """
    data = analysis.data
    first_s = first_applied_command(data)
    if first_s is None:
        raise BagAnalysisError(f'{data.path} has no {topics.JOINT_COMMANDS}: cannot align it on '
                               f'its {ALIGNED_ON}.')
    return first_s


def _held_commands(analysis: Analysis, t_s: np.ndarray, align_s: float) -> np.ndarray:
    """Each joint's latest commanded position at aligned times `t_s` (NaN before any)."""
    commands = analysis.data.commands
    assert commands is not None
    rows = np.searchsorted(commands.t_s - align_s, t_s, side='right') - 1
    held = np.full((len(t_s), commands.held.shape[1]), np.nan)
    held[rows >= 0] = commands.held[rows[rows >= 0]]
    return held


def _rms(values: np.ndarray) -> float | None:
    values = values[np.isfinite(values)]
    return float(np.sqrt(np.mean(values ** 2))) if len(values) else None


def _max_abs(values: np.ndarray) -> float | None:
    values = values[np.isfinite(values)]
    return float(np.abs(values).max()) if len(values) else None


def compare_analyses(a: Analysis, b: Analysis, trajectory_a: PlayedTrajectory | None = None,
            trajectory_b: PlayedTrajectory | None = None) -> Comparison:
    """Align `a` and `b` on their first applied command and measure their differences.

    Raises:
        BagAnalysisError: a run has no joint commands or joint states, or the runs share no
            time after their first command.
    """
    align_a_s, align_b_s = first_applied_command_s(a), first_applied_command_s(b)
    states_a, states_b = a.data.joint_states, b.data.joint_states
    for analysis, states in ((a, states_a), (b, states_b)):
        if states is None or not len(states.t_s):
            raise BagAnalysisError(f'{analysis.data.path} has no /atlas/joint_states to compare.')
    assert states_a is not None and states_b is not None
    t_a = states_a.t_s - align_a_s
    t_b = states_b.t_s - align_b_s
    window = (0.0, float(min(t_a[-1], t_b[-1])))
    rows = (t_a >= window[0]) & (t_a <= window[1])
    if not rows.any():
        raise BagAnalysisError(f'{a.data.path} and {b.data.path} share no time after their '
                               f'{ALIGNED_ON}.')
    t_s = t_a[rows]
    held_a = _held_commands(a, t_s, align_a_s)
    held_b = _held_commands(b, t_s, align_b_s)
    joints: dict[str, JointDifference] = {}
    for column, name in enumerate(states_a.names):
        if name not in states_b.names:
            continue
        measured_b = states_b.position[:, states_b.names.index(name)]
        diff = states_a.position[rows, column] - np.interp(t_s, t_b, measured_b)
        index = JOINT_INDEX.get(name)
        command_rms = None if index is None else _rms(held_a[:, index] - held_b[:, index])
        joints[name] = JointDifference(_rms(diff), _max_abs(diff), command_rms)
    moved = [name for name in joints if name in a.joints or name in b.joints]

    pelvis_rms = pelvis_max = None
    pelvis_a, pelvis_b = a.data.pelvis, b.data.pelvis
    if pelvis_a is not None and pelvis_b is not None and len(pelvis_a.t_s) and len(pelvis_b.t_s):
        p_a = pelvis_a.t_s - align_a_s
        in_window = (p_a >= window[0]) & (p_a <= window[1])
        diff = (pelvis_a.position_m[in_window, 2]
                - np.interp(p_a[in_window], pelvis_b.t_s - align_b_s, pelvis_b.position_m[:, 2]))
        pelvis_rms, pelvis_max = _rms(diff), _max_abs(diff)

    def fall(analysis: Analysis, align_s: float) -> float | None:
        return None if analysis.fall_time_s is None else analysis.fall_time_s - align_s

    return Comparison(a, b, trajectory_a, trajectory_b, align_a_s, align_b_s, window, joints,
                      moved, pelvis_rms, pelvis_max, fall(a, align_a_s), fall(b, align_b_s))


def compare_bags(path_a: Path | str, path_b: Path | str, try_a: int = -1,
                 try_b: int = -1) -> Comparison:
    """:func:`compare` try `try_a` of A with try `try_b` of B (default: the last of each),
    with the trajectories their /rosout names.

    Raises:
        BagAnalysisError: unreadable bag, no such try, nothing to compare.
    """
    a, b = analyze_try(read_bag(path_a), try_a), analyze_try(read_bag(path_b), try_b)
    played_a, played_b = a.data.played, b.data.played
    return compare_analyses(a, b, played_a[0][1] if played_a else None,
                   played_b[0][1] if played_b else None)


def _fmt(value: float | None, spec: str, unit: str = '') -> str:
    return 'n/a' if value is None else f'{value:{spec}}{unit}'


def _fall_text(fell: bool | None, fall_time_s: float | None) -> str:
    if fell is None:
        return 'unknown (no /ground_truth_odom)'
    if not fell:
        return 'did not fall'
    return f'fell at {fall_time_s:.3f} s'


def format_comparison(comparison: Comparison) -> str:
    """The text report, several lines, no trailing newline."""
    c = comparison
    lines = []
    for label, analysis, played in (('A', c.a, c.trajectory_a), ('B', c.b, c.trajectory_b)):
        trajectory = f': trajectory {played.describe()}' if played else ''
        lines.append(f'{label}: {analysis.data.path}{trajectory}')
    lines.append(f'Aligned on the {ALIGNED_ON}, {ALIGNED_ON_DETAIL}: A at {c.align_a_s:.3f} s, '
                 f'B at {c.align_b_s:.3f} s from bag start; times below are from it.')
    lines.append(f'Compared from {c.window_s[0]:.3f} s to {c.window_s[1]:.3f} s, at each of A\'s '
                 'joint states (B interpolated).')
    diff = c.fall_time_diff_s
    lines.append(f'Fall (pelvis below {FALL_HEIGHT_M} m): A {_fall_text(c.a.fell, c.fall_time_a_s)}'
                 f', B {_fall_text(c.b.fell, c.fall_time_b_s)}'
                 + ('' if diff is None else f'; B - A = {diff:+.3f} s'))
    lines.append(f'Pelvis height A - B: RMS {_fmt(c.pelvis_height_rms_diff_m, ".4f", " m")}, '
                 f'max {_fmt(c.pelvis_height_max_diff_m, ".4f", " m")}')
    if not c.moved:
        lines.append('Joints: none moved in either run.')
    else:
        width = max(len(name) for name in c.moved)
        lines.append('Joints that moved in either run, A - B (rad): measured RMS and max, '
                     'commanded RMS:')
        lines.append(f'  {"joint":<{width}}  {"RMS":>8}  {"max":>8}  {"cmd RMS":>8}')
        for name in c.moved:
            joint = c.joints[name]
            lines.append(f'  {name:<{width}}  {_fmt(joint.rms_diff_rad, "8.4f")}  '
                         f'{_fmt(joint.max_diff_rad, "8.4f")}  '
                         f'{_fmt(joint.command_rms_diff_rad, "8.4f")}')
    return '\n'.join(lines)


def comparison_to_json(comparison: Comparison) -> str:
    """The comparison as one strict JSON document."""
    return json.dumps(json_safe(comparison.to_dict()), indent=2, allow_nan=False)


def _decimate(t_s: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    step = max(1, len(t_s) // PLOT_MAX_POINTS)
    return t_s[::step], values[::step]


def plot_comparison(comparison: Comparison, path: Path | str) -> Path:
    """Overlay A and B (aligned) for the joints that moved, and the pelvis height.

    Raises:
        BagAnalysisError: the image cannot be written.
    """
    import matplotlib  # noqa: PLC0415 - only needed with --plot

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt  # noqa: PLC0415

    c, path = comparison, Path(path)
    runs = (('A', c.a, c.align_a_s, 'tab:blue'), ('B', c.b, c.align_b_s, 'tab:orange'))
    rows = len(c.moved) + 1
    fig, axes = plt.subplots(rows, 1, sharex=True, squeeze=False,
                             figsize=(PLOT_WIDTH_IN, PLOT_ROW_HEIGHT_IN * max(rows, 2) + 1.0))
    axes = list(axes[:, 0])
    for ax, name in zip(axes, c.moved):
        for label, analysis, align_s, color in runs:
            states = analysis.data.joint_states
            assert states is not None
            ax.plot(*_decimate(states.t_s - align_s, states.position[:, states.names.index(name)]),
                    color=color, linewidth=1.0, label=label)
        ax.set_ylabel(f'{name}\n(rad)', fontsize=8)
    ax = axes[-1]
    for label, analysis, align_s, color in runs:
        pelvis = analysis.data.pelvis
        if pelvis is not None:
            ax.plot(*_decimate(pelvis.t_s - align_s, pelvis.position_m[:, 2]), color=color,
                    label=f'{label} pelvis z')
    ax.axhline(FALL_HEIGHT_M, color='tab:red', linestyle=':', label='fall threshold')
    ax.set_ylabel('pelvis\nheight (m)', fontsize=8)
    for ax in axes:
        ax.axvline(0.0, color='gray', linestyle='--', linewidth=0.8)
    margin_s = PLOT_MARGIN * (c.window_s[1] - c.window_s[0])
    axes[-1].set_xlim(c.window_s[0] - margin_s, c.window_s[1] + margin_s)
    axes[0].legend(loc='upper right', fontsize=7)
    axes[-1].legend(loc='upper right', fontsize=7)
    axes[-1].set_xlabel(f'time from the {ALIGNED_ON} (s)')
    fig.suptitle(f'A: {c.a.data.path.name} vs B: {c.b.data.path.name}', y=0.995)
    return save_figure(fig, path)
