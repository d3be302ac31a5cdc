"""bags/behaviours.py: a recorded state's change as a line of the timeline."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tutorial_atlas_control.bags.behaviours import (
    WALK_ENDS_AFTER_S,
    BehaviourChange,
    behaviour_lines,
    plot_behaviours,
    walk_windows,
)


def test_each_change_says_the_behaviour_its_status_and_what_was_asked() -> None:
    lines = behaviour_lines([BehaviourChange(1.5, 1, 0, 0), BehaviourChange(2.25, 1, 8, 4),
                             BehaviourChange(3.0, 0, 2, 0), BehaviourChange(9.0, 0, 128, 0),
                             BehaviourChange(9.5, 9, 0, 0)])
    assert lines == [
        "Behaviours (the AtlasSimInterface's state; times from bag start):",
        '      1.500 s  USER',
        '      2.250 s  USER  FAILED_TRANS_ILLEGAL_BEHAVIOR (WALK asked for)',
        '      3.000 s  STAND  TRANSITION_SUCCESS (STAND asked for)',
        '      9.000 s  STAND  WARNING_AUTO_TRANS',
        '      9.500 s  9']


def test_a_recorded_topic_without_states_says_so() -> None:
    assert behaviour_lines([]) == [
        'Behaviours: /atlas/asi_state_recorded recorded, but no state in it']


def test_each_walk_has_its_window_from_the_change_before_it() -> None:
    changes = [BehaviourChange(0.1, 1, 0, 0), BehaviourChange(2.0, 0, 2, 0),
               BehaviourChange(5.0, 4, 2, 4), BehaviourChange(5.001, 4, 0, 0),
               BehaviourChange(8.0, 0, 128, 0), BehaviourChange(9.0, 0, 1, 4),
               BehaviourChange(10.0, 4, 2, 4)]
    assert walk_windows(changes) == [(2.0, 8.0 + WALK_ENDS_AFTER_S),
                                     (9.0, float('inf'))]


def test_a_walk_soon_after_another_ends_the_first_ones_window() -> None:
    changes = [BehaviourChange(1.7, 0, 2, 0), BehaviourChange(4.49, 4, 2, 4),
               BehaviourChange(8.212, 0, 128, 0), BehaviourChange(9.067, 4, 2, 4),
               BehaviourChange(12.794, 0, 2, 0)]
    assert walk_windows(changes) == [(1.7, 8.212), (8.212, 12.794 + WALK_ENDS_AFTER_S)]


def test_the_behaviours_are_plotted_over_the_pelvis_height(tmp_path: Path) -> None:
    changes = [BehaviourChange(0.0, 1, 0, 0), BehaviourChange(1.0, 1, 8, 4),
               BehaviourChange(2.0, 0, 2, 0), BehaviourChange(3.0, 4, 2, 4),
               BehaviourChange(6.0, 0, 128, 0)]
    t_s = np.linspace(0.0, 8.0, 801)
    path = plot_behaviours(changes, t_s, 0.9 - 0.05 * (t_s > 3.0), tmp_path / 'b.png')
    assert path.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
    assert path.stat().st_size > 10_000
