"""One way to say when the robot fell, for every tool: sim time, and seconds after the
first command of the try (a try starts at the launch or at a reset).

The simulator's live log line, `make demo`'s and run_offline.py's summaries, analyze_bag.py
and its plots all write a fall with :func:`fall_when`, so their figures can be compared
without arithmetic. The simulator's line, recorded on /rosout, is read back by the bag
tools (:func:`parse_fall_line`), so a live bag reports the figures the log showed: the
simulator sees the pelvis every step, the bag only at /ground_truth_odom's 100 Hz.
"""

from __future__ import annotations

import re
from typing import NamedTuple

__all__ = ['LoggedFall', 'fall_line', 'fall_when', 'parse_fall_line']

#: What the fall lines start with (the simulator's, and the summaries').
FALL_LINE_PREFIX = 'the robot fell: '
_FALL_LINE = re.compile(
    r'^the robot fell: pelvis below (?P<height>[0-9.]+) m at sim time (?P<sim>[0-9.]+) s'
    r'(?:, (?P<after>-?[0-9.]+) s after the try\'s first command|, before any command of '
    r'the try)$')


class LoggedFall(NamedTuple):
    """A fall as the simulator logged it: sim time (s), s after the try's first command."""

    sim_time_s: float
    after_command_s: float | None


def fall_when(sim_time_s: float, after_command_s: float | None) -> str:
    """'at sim time 36.983 s, 1.943 s after the try's first command' (ms resolution)."""
    when = f'at sim time {sim_time_s:.3f} s'
    if after_command_s is None:
        return when + ', before any command of the try'
    return when + f", {after_command_s:.3f} s after the try's first command"


def fall_line(height_m: float, sim_time_s: float, after_command_s: float | None) -> str:
    """The simulator's line (and the summaries'): 'the robot fell: pelvis below ...'."""
    return f'{FALL_LINE_PREFIX}pelvis below {height_m} m {fall_when(sim_time_s, after_command_s)}'


def parse_fall_line(text: str) -> LoggedFall | None:
    """The figures of a :func:`fall_line`, None if `text` is not one."""
    match = _FALL_LINE.match(text)
    if match is None:
        return None
    after = match.group('after')
    return LoggedFall(float(match.group('sim')), None if after is None else float(after))
