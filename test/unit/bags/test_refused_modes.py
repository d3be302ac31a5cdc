"""A refused /atlas/control_mode string is marked as refused in analyze_bag.py's timeline
(and on the plot: test_overview_plot.py); the modes are DRCSim 2.5's, case-sensitive."""

from __future__ import annotations

from pathlib import Path

from support.synthetic_bags import clock, control_mode, write_bag
from tutorial_atlas_control.bags.analysis import analyze_bag
from tutorial_atlas_control.bags.report import format_summary
from tutorial_atlas_control.control_modes import VALID_CONTROL_MODES, is_refused_mode


def test_the_modes_are_drcsims() -> None:
    assert VALID_CONTROL_MODES == ('Stand', 'StandPrep', 'Freeze', 'ragdoll', 'User', 'Walk')
    assert is_refused_mode('user') and not is_refused_mode('User')


def test_the_timeline_marks_a_refused_mode(tmp_path: Path) -> None:
    bag = write_bag(tmp_path / 'run.bag', [clock(0.0), control_mode(0.5, 'user'),
                                           control_mode(1.0, 'User'), clock(2.0)])
    lines = format_summary(analyze_bag(bag)).splitlines()
    assert '      0.500 s  user  (refused: not a control mode; the mode did not change)' in lines
    assert '      1.000 s  User' in lines
