"""The tutorial's metrics of a recorded run: fall, tracking, command timing, effort limits.

Works on the :class:`~tutorial_atlas_control.bags.reader.BagData` that reader.py extracts;
all times are seconds from the bag's start (run timeline). A bag with resets is cut into
tries (bags.tries): each try gets its own metrics, and the whole-run metrics never pair a
state with a command of another try.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from tutorial_atlas_control import topics
from tutorial_atlas_control.bags.course_terrain import (
    above_ground,
    is_course_run,
    terrain_heights,
)
from tutorial_atlas_control.bags.reader import (
    BagData,
    JointCommandSeries,
    JointStateSeries,
    PelvisSeries,
    read_bag,
)
from tutorial_atlas_control.bags.run_log import PlayedTrajectory
from tutorial_atlas_control.bags.tries import Try, find_tries, pick_try, window
from tutorial_atlas_control.errors import BagAnalysisError
from tutorial_atlas_control.fall_report import LoggedFall
from tutorial_atlas_control.joints import JOINT_INDEX, JOINT_NAMES
from tutorial_atlas_control.sim import FALL_HEIGHT_M, fallen_samples

__all__ = [
    'COMMAND_CHANGE_RAD',
    'EFFORT_LIMITS_NM',
    'EFFORT_LIMIT_TOLERANCE_NM',
    'MOVED_RANGE_RAD',
    'USER_MODE',
    'Analysis',
    'EffortSaturation',
    'JointTracking',
    'TryAnalysis',
    'analyze',
    'analyze_bag',
    'analyze_try',
    'first_applied_command_s',
    'input_timeline',
]

#: The control mode in which the simulator obeys /atlas/joint_commands.
USER_MODE = 'User'

#: A joint "moved" if its measured position spans more than this (rad) over the run...
MOVED_RANGE_RAD = 0.02
#: ...or if any commanded position differs from its first commanded value by more (rad).
COMMAND_CHANGE_RAD = 1e-6

#: A joint is at its effort limit when |effort| >= limit - this tolerance (N·m).
EFFORT_LIMIT_TOLERANCE_NM = 0.01

_LEG_LIMITS_NM = {'uhz': 110.0, 'mhx': 180.0, 'lhy': 260.0, 'kny': 220.0, 'uay': 220.0,
                  'lax': 90.0}
_ARM_LIMITS_NM = {'usy': 212.0, 'shx': 170.0, 'ely': 114.0, 'elx': 114.0, 'uwy': 114.0,
                  'mwx': 60.0}

#: Atlas v1 actuator effort limits (N·m) by bare joint name, in tutorial order
#: (the DRCSim atlas.urdf values; kept here so analysis needs no MuJoCo model).
EFFORT_LIMITS_NM: dict[str, float] = {
    'back_lbz': 124.016, 'back_mby': 206.843, 'back_ubx': 94.91, 'neck_ay': 5.0,
    **{f'{side}_leg_{joint}': limit for side in 'lr' for joint, limit in _LEG_LIMITS_NM.items()},
    **{f'{side}_arm_{joint}': limit for side in 'lr' for joint, limit in _ARM_LIMITS_NM.items()},
}
EFFORT_LIMITS_NM = {name: EFFORT_LIMITS_NM[name] for name in JOINT_NAMES}


@dataclass(frozen=True)
class JointTracking:
    """Tracking of one joint: RMS and max |command - measured| (rad) over `samples`."""

    rms_error_rad: float | None
    max_error_rad: float | None
    samples: int
    commanded: bool
    measured_range_rad: float | None


@dataclass(frozen=True)
class EffortSaturation:
    """Time a joint spent at its effort limit (s of sim time) and when it first did."""

    limit_nm: float
    duration_s: float
    first_time_s: float
    samples: int


#: /atlas/sim_inputs' input kinds -> the topic the input came from.
_INPUT_TOPICS = {'mode': topics.MODE, 'set_pose': topics.SET_POSE, 'cmd_vel': topics.CMD_VEL,
                 'pelvis_wrench': topics.APPLY_PELVIS_FORCE,
                 'joint_trajectory': topics.JOINT_TRAJECTORY}


def input_timeline(data: BagData) -> list[tuple[float, str]]:
    """(time from the bag's start (s), 'topic values') of each input the simulator applied
    (/atlas/sim_inputs: sim time of the step it first acted in); unreadable ones are shown
    as such."""
    timeline = []
    for t_s, text in data.sim_inputs:
        try:
            event = json.loads(text)
            item = dict(event['input'])
            t_s = int(event['time_ns']) / 1e9 - data.start_time_s
            kind = item.pop('kind')
        except (ValueError, KeyError, TypeError):
            timeline.append((t_s, f'{topics.SIM_INPUTS} (unreadable)'))
            continue
        if kind == 'joint_trajectory':
            values = (f'{len(item.get("joints", []))} joints, '
                      f'{len(item.get("positions", []))} points')
        else:
            values = ', '.join(f'{key}={value}' for key, value in item.items())
        timeline.append((t_s, f'{_INPUT_TOPICS.get(kind, kind)} {values}'))
    return timeline


@dataclass(frozen=True)
class Analysis:
    """The metrics of one run. Times are seconds from bag start; None = not available."""

    data: BagData
    fell: bool | None
    fall_time_s: float | None
    min_pelvis_height_m: float | None
    joints: dict[str, JointTracking]
    command_rate_hz: float | None
    command_age_mean_s: float | None
    command_age_max_s: float | None
    effort_saturation: dict[str, EffortSaturation] | None
    unavailable: dict[str, str]
    tries: list[TryAnalysis] = field(default_factory=list)
    #: The pelvis's heights (the fall, the lowest) are over the VRC course's terrain under
    #: it, not over z 0 (a course run: bags/course_terrain.is_course_run).
    over_terrain: bool = False

    @property
    def mode_timeline(self) -> list[tuple[float, str]]:
        return self.data.modes

    @property
    def input_timeline(self) -> list[tuple[float, str]]:
        """(time from the bag's start (s), description) of each applied VRCPlugin input."""
        return input_timeline(self.data)

    @property
    def warnings(self) -> list[str]:
        """The bag's warnings, and one when the run holds several tries."""
        extra = []
        if len(self.tries) > 1:
            starts = ', '.join(f'{t.window.cause} at {t.window.start_s:.3f} s'
                               for t in self.tries[1:])
            extra.append(f'the bag holds {len(self.tries)} tries ({starts}); the whole-run '
                         'figures span them all: see each try (--try N).')
        return list(self.data.warnings) + extra

    def first_fall(self) -> tuple[int | None, LoggedFall] | None:
        """(try number, figures) of the run's first fall (fall_report's figures); None if
        it did not fall."""
        for each in self.tries:
            if each.fall is not None:
                return each.window.number, each.fall
        if self.fall_time_s is None:
            return None
        return None, LoggedFall(self.data.sim_time_s(self.fall_time_s), None)

    def falls(self) -> list[float]:
        """The time (s) of every fall: one per try that fell."""
        if not self.tries:
            return [] if self.fall_time_s is None else [self.fall_time_s]
        return [t.analysis.fall_time_s for t in self.tries if t.analysis.fall_time_s is not None]

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict (see analyze_bag --help for the keys and units)."""
        data = self.data
        return {
            'bag': str(data.path),
            'start_time': data.start_time_s,
            'duration': data.duration_s,
            'topics': {name: {'type': topic.msgtype, 'count': topic.count,
                              'rate': topic.rate_hz} for name, topic in data.topics.items()},
            'mode_timeline': [{'time': t_s, 'mode': mode} for t_s, mode in data.modes],
            'inputs': [{'time': t_s, 'input': text} for t_s, text in input_timeline(data)],
            'fell': self.fell,
            'fall_time': self.fall_time_s,
            **_first_fall_dict(self.first_fall()),
            'min_pelvis_height': self.min_pelvis_height_m,
            'joints': {name: {'rms_error': joint.rms_error_rad, 'max_error': joint.max_error_rad,
                              'samples': joint.samples, 'commanded': joint.commanded,
                              'measured_range': joint.measured_range_rad}
                       for name, joint in self.joints.items()},
            'command_rate': self.command_rate_hz,
            'command_count': 0 if data.commands is None else len(data.commands.t_s),
            'command_age': (None if self.command_age_mean_s is None else
                            {'mean': self.command_age_mean_s, 'max': self.command_age_max_s}),
            'effort_saturation': (None if self.effort_saturation is None else {
                name: {'limit': sat.limit_nm, 'duration': sat.duration_s,
                       'first_time': sat.first_time_s, 'samples': sat.samples}
                for name, sat in self.effort_saturation.items()}),
            'thresholds': {'fall_height': FALL_HEIGHT_M,
                           'fall_height_over': 'terrain' if self.over_terrain else 'z 0',
                           'moved_range': MOVED_RANGE_RAD,
                           'command_change': COMMAND_CHANGE_RAD,
                           'effort_tolerance': EFFORT_LIMIT_TOLERANCE_NM},
            'unavailable': dict(self.unavailable),
            'warnings': self.warnings,
            'tries': [each.to_dict() for each in self.tries],
        }


def _first_fall_dict(first: tuple[int | None, LoggedFall] | None) -> dict[str, Any]:
    if first is None:
        return {'fall_sim_time': None, 'fall_after_command': None}
    return {'fall_sim_time': first[1].sim_time_s, 'fall_after_command': first[1].after_command_s}


def first_applied_command_s(data: BagData) -> float | None:
    """Time (s) of the first /atlas/joint_commands at or after the switch to User mode.

    The first command at all when the bag has no switch to User (None: no commands).
    """
    commands = data.commands
    if commands is None or not len(commands.t_s):
        return None
    user_s = next((t_s for t_s, mode in data.modes if mode == USER_MODE), None)
    if user_s is not None:
        after = np.flatnonzero(commands.t_s >= user_s)
        if len(after):
            return float(commands.t_s[after[0]])
    return float(commands.t_s[0])


@dataclass(frozen=True)
class TryAnalysis:
    """One try's metrics (`analysis` of the try's window) and what was played in it.

    `first_command_s`: the try's first applied command (s from bag start; None: none).
    """

    window: Try
    analysis: Analysis
    first_command_s: float | None
    trajectories: list[PlayedTrajectory]

    @property
    def fall(self) -> LoggedFall | None:
        """The try's fall in fall_report's figures (sim time, s after the try's first
        command): the simulator's own log line when the bag holds it (it saw the pelvis
        every step), else from the bag's odometry and commands. None: no fall."""
        if self.analysis.data.logged_falls:
            return self.analysis.data.logged_falls[0][1]
        fall_s = self.analysis.fall_time_s
        if fall_s is None:
            return None
        after_s = None if self.first_command_s is None else fall_s - self.first_command_s
        return LoggedFall(self.analysis.data.sim_time_s(fall_s), after_s)

    @property
    def fall_after_command_s(self) -> float | None:
        """Fall time from the try's first applied command (s); None: no fall or no command."""
        fall = self.fall
        return None if fall is None else fall.after_command_s

    def to_dict(self) -> dict[str, Any]:
        a, data = self.analysis, self.analysis.data
        return {
            'try': self.window.number,
            'start': self.window.start_s,
            'end': self.window.end_s,
            'sim_start': data.sim_time_s(self.window.start_s),
            'began_with': self.window.cause,
            'trajectory': (None if not self.trajectories else
                           {'file': self.trajectories[0].file, 'name': self.trajectories[0].name}),
            'trajectories': [{'file': p.file, 'name': p.name} for p in self.trajectories],
            'mode_timeline': [{'time': t_s, 'mode': mode} for t_s, mode in data.modes],
            'first_command': self.first_command_s,
            'fell': a.fell,
            'fall_time': a.fall_time_s,
            'fall_sim_time': None if self.fall is None else self.fall.sim_time_s,
            'fall_after_command': self.fall_after_command_s,
            'min_pelvis_height': a.min_pelvis_height_m,
            'command_count': 0 if data.commands is None else len(data.commands.t_s),
            'command_rate': a.command_rate_hz,
            'command_age': (None if a.command_age_mean_s is None else
                            {'mean': a.command_age_mean_s, 'max': a.command_age_max_s}),
            'joints': {name: {'rms_error': joint.rms_error_rad, 'max_error': joint.max_error_rad,
                              'samples': joint.samples, 'commanded': joint.commanded,
                              'measured_range': joint.measured_range_rad}
                       for name, joint in a.joints.items()},
        }


def _sample_durations_s(t_s: np.ndarray) -> np.ndarray:
    """How long each sample stands for: the gap to the next one (median gap for the last)."""
    if len(t_s) < 2:
        return np.zeros(len(t_s))
    gaps = np.diff(t_s)
    return np.append(gaps, np.median(gaps))


def _effort_saturation(states: JointStateSeries) -> dict[str, EffortSaturation]:
    durations_s = _sample_durations_s(states.t_s)
    result = {}
    for column, name in enumerate(states.names):
        limit = EFFORT_LIMITS_NM.get(name)
        if limit is None:
            continue
        with np.errstate(invalid='ignore'):
            hit = np.abs(states.effort[:, column]) >= limit - EFFORT_LIMIT_TOLERANCE_NM
        if hit.any():
            result[name] = EffortSaturation(limit, float(durations_s[hit].sum()),
                                            float(states.t_s[np.argmax(hit)]), int(hit.sum()))
    return result


def _nan_range(values: np.ndarray) -> float | None:
    finite = values[np.isfinite(values)]
    return float(finite.max() - finite.min()) if len(finite) else None


def _fall(pelvis: PelvisSeries, over_terrain: bool) -> tuple[bool, float | None, float]:
    """(fell, first time fallen or None, lowest pelvis height (m)): sim/fall.py's
    criterion, over the course's terrain under the pelvis on a course run (standing in the
    mud pit, 0.6 m down, is not a fall), else over z 0 (the empty world's plane)."""
    position_m = pelvis.position_m
    if over_terrain:
        position_m = above_ground(position_m, terrain_heights())
    height_m = position_m[:, 2]
    below = fallen_samples(height_m)
    fell = bool(below.any())
    return fell, float(pelvis.t_s[np.argmax(below)]) if fell else None, float(height_m.min())


def _command_rate_hz(commands: JointCommandSeries, starts_s: list[float]) -> float | None:
    """Commands per second while they arrive: intervals over time spanned, try by try."""
    segment = np.searchsorted(starts_s, commands.t_s, side='right')
    intervals, span_s = 0, 0.0
    for number in np.unique(segment):
        t_s = commands.t_s[segment == number]
        intervals += len(t_s) - 1
        span_s += float(t_s[-1] - t_s[0])
    return intervals / span_s if intervals and span_s > 0 else None


def _latest_command(states: JointStateSeries, commands: JointCommandSeries,
                    starts_s: list[float]) -> tuple[np.ndarray, float | None, float | None]:
    """Row of the latest command of the same try at each state (-1: none yet), and the mean
    and max command age (s) over the states while commands arrive: up to one command
    interval (the median) after the try's last command, not the idle time after it."""
    latest = np.searchsorted(commands.t_s, states.t_s, side='right') - 1
    state_try = np.searchsorted(starts_s, states.t_s, side='right')
    command_try = np.searchsorted(starts_s, commands.t_s, side='right')
    latest = np.where((latest >= 0) & (command_try[np.maximum(latest, 0)] == state_try),
                      latest, -1)
    last_command_s = np.full(len(starts_s) + 1, -np.inf)
    np.maximum.at(last_command_s, command_try, commands.t_s)
    same_try = np.diff(command_try) == 0
    interval_s = float(np.median(np.diff(commands.t_s)[same_try])) if same_try.any() else 0.0
    with_command = (latest >= 0) & (states.t_s <= last_command_s[state_try] + interval_s)
    if not with_command.any():
        return latest, None, None
    ages_s = states.t_s[with_command] - commands.t_s[latest[with_command]]
    return latest, float(ages_s.mean()), float(ages_s.max())


def _joint_tracking(name: str, measured: np.ndarray, commands: JointCommandSeries | None,
                    latest: np.ndarray) -> JointTracking | None:
    """Tracking of joint `name` at each state, or None if the joint did not move."""
    measured_range = _nan_range(measured)
    moved = measured_range is not None and measured_range > MOVED_RANGE_RAD
    index = JOINT_INDEX.get(name)
    commanded = False
    rms = max_error = None
    samples = 0
    if index is not None and commands is not None:
        sent = commands.position[:, index]
        sent = sent[np.isfinite(sent)]
        commanded = bool(len(sent))
        moved = moved or (commanded and bool(np.any(np.abs(sent - sent[0]) > COMMAND_CHANGE_RAD)))
        rows = latest >= 0
        errors = commands.held[latest[rows], index] - measured[rows]
        errors = errors[np.isfinite(errors)]
        samples = len(errors)
        if samples:
            rms = float(np.sqrt(np.mean(errors ** 2)))
            max_error = float(np.abs(errors).max())
    return JointTracking(rms, max_error, samples, commanded, measured_range) if moved else None


def _tracking(states: JointStateSeries, commands: JointCommandSeries | None,
              starts_s: list[float]) -> tuple[dict[str, JointTracking], float | None, float | None]:
    """Tracking of every joint that moved, and mean and max command age (s)."""
    age_mean_s = age_max_s = None
    latest = np.full(len(states.t_s), -1)
    if commands is not None:
        latest, age_mean_s, age_max_s = _latest_command(states, commands, starts_s)
    joints = {}
    for column, name in enumerate(states.names):
        joint = _joint_tracking(name, states.position[:, column], commands, latest)
        if joint is not None:
            joints[name] = joint
    return joints, age_mean_s, age_max_s


def _analyze(data: BagData, starts_s: list[float]) -> Analysis:
    """The metrics of `data`, whose tries begin at `starts_s` (s, after the first)."""
    unavailable: dict[str, str] = {}
    fell = fall_time_s = min_height_m = None
    over_terrain = is_course_run(data)
    if data.pelvis is None or not len(data.pelvis.t_s):
        unavailable['fall'] = f'no {topics.GROUND_TRUTH_ODOM} in the bag'
    else:
        fell, fall_time_s, min_height_m = _fall(data.pelvis, over_terrain)

    commands = data.commands
    command_rate_hz = None
    if commands is None or not len(commands.t_s):
        commands = None
        unavailable['commands'] = f'no {topics.JOINT_COMMANDS} in the bag'
    else:
        command_rate_hz = _command_rate_hz(commands, starts_s)

    states = data.joint_states
    joints: dict[str, JointTracking] = {}
    age_mean_s = age_max_s = saturation = None
    if states is None or not len(states.t_s):
        reason = f'no {topics.JOINT_STATES} in the bag'
        unavailable.update(joints=reason, command_age=reason, effort_saturation=reason)
    else:
        saturation = _effort_saturation(states)
        joints, age_mean_s, age_max_s = _tracking(states, commands, starts_s)
        if commands is None:
            unavailable['command_age'] = f'no {topics.JOINT_COMMANDS} in the bag'
    return Analysis(data, fell, fall_time_s, min_height_m, joints, command_rate_hz,
                    age_mean_s, age_max_s, saturation, unavailable, over_terrain=over_terrain)


def _analyze_try(data: BagData, each: Try) -> TryAnalysis:
    part = window(data, each.start_s, each.end_s)
    return TryAnalysis(each, _analyze(part, []), first_applied_command_s(part),
                       [played for _, played in part.played])


def analyze(data: BagData, start_s: float | None = None, end_s: float | None = None) -> Analysis:
    """Compute fall, tracking, command timing and effort saturation from `data`, for the
    whole run and for each of its tries; with `start_s`/`end_s` (s from bag start), only
    for that part of the run (the tries it overlaps, cut to it)."""
    tries = find_tries(data)
    if start_s is not None or end_s is not None:
        lower = -np.inf if start_s is None else start_s
        upper = np.inf if end_s is None else end_s
        tries = [replace(each, start_s=max(each.start_s, lower), end_s=min(each.end_s, upper))
                 for each in tries if each.start_s < upper and each.end_s > lower]
        if not tries:
            raise BagAnalysisError(f'{data.path}: nothing recorded from {lower:.3f} s to '
                                   f'{upper:.3f} s (the run spans 0 to {data.duration_s:.3f} s).')
        data = window(data, tries[0].start_s, tries[-1].end_s)
    whole = _analyze(data, [each.start_s for each in tries[1:]])
    return replace(whole, tries=[_analyze_try(data, each) for each in tries])


def analyze_bag(path: Path | str) -> Analysis:
    """:func:`~tutorial_atlas_control.bags.reader.read_bag` then :func:`analyze`."""
    return analyze(read_bag(path))


def analyze_try(data: BagData, number: int | None) -> Analysis:
    """:func:`analyze` of try `number` only (1-based, negative from the end, None: last).

    Raises:
        BagAnalysisError: the bag has no such try.
    """
    chosen = pick_try(find_tries(data), number, data.path)
    return analyze(data, chosen.start_s, chosen.end_s)
