"""fall_report.py: one way to say when the robot fell, and a live bag's own figures.

The simulator's /rosout line is read back by the bag tools, so analyze_bag.py and the
demo's summary give the figures the live log gave, not the 100 Hz odometry's.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from support.synthetic_bags import (
    clock,
    control_mode,
    joint_commands,
    odometry,
    rosout,
    write_bag,
)
from tutorial_atlas_control.bags.analysis import analyze_bag
from tutorial_atlas_control.bags.report import format_summary, short_summary
from tutorial_atlas_control.fall_report import LoggedFall, fall_line, parse_fall_line
from tutorial_atlas_control.joints import NUM_JOINTS


@pytest.mark.parametrize(('after_s', 'line'), [
    (1.943, "the robot fell: pelvis below 0.5 m at sim time 36.983 s, 1.943 s after the "
            "try's first command"),
    (None, 'the robot fell: pelvis below 0.5 m at sim time 36.983 s, before any command of '
           'the try'),
])
def test_the_line_and_its_figures_round_trip(after_s: float | None, line: str) -> None:
    assert fall_line(0.5, 36.9834, after_s) == line
    assert parse_fall_line(line) == LoggedFall(36.983, after_s)
    assert parse_fall_line('the robot fell: somehow') is None
    assert parse_fall_line('first /atlas/joint_commands since the start') is None


def falling_run(path: Path, logged: str | None) -> Path:
    """Sim time 30-33 s: User at 30.5 s, a command every 20 ms from 31.0 s, the pelvis
    sinking from 0.9 m at 0.5 m/s from 32.0 s (odometry at 100 Hz), the simulator's line."""
    records = [control_mode(30.5, 'User')]
    for k in range(300):
        t_s = 30.0 + 0.01 * k
        records += [clock(t_s), odometry(t_s, 0.9 - 0.5 * max(0.0, t_s - 32.0))]
    records += [joint_commands(31.0 + 0.02 * k, np.zeros(NUM_JOINTS)) for k in range(50)]
    if logged is not None:
        records.append(rosout(32.802, logged, node='/atlas_sim'))
    return write_bag(path, records)


def test_a_live_bag_reports_the_simulators_figures_everywhere(tmp_path: Path) -> None:
    logged = fall_line(0.5, 32.801, 1.801)  # the simulator saw it 9 ms before the odometry
    analysis = analyze_bag(falling_run(tmp_path / 'live.bag', logged))
    assert analysis.fall_time_s == pytest.approx(2.81)  # from the bag's start, 100 Hz
    figures = "at sim time 32.801 s, 1.801 s after the try's first command"
    assert short_summary(analysis).splitlines()[1] == logged
    assert f'Fall:     FELL {figures} (try 1, 2.810 s from bag start' in format_summary(analysis)
    doc = analysis.to_dict()
    assert (doc['fall_sim_time'], doc['fall_after_command']) == (32.801, 1.801)
    assert (doc['tries'][0]['fall_sim_time'], doc['tries'][0]['fall_after_command']) == (
        32.801, 1.801)


def test_a_bag_without_the_line_reports_its_own_figures_the_same_way(tmp_path: Path) -> None:
    analysis = analyze_bag(falling_run(tmp_path / 'offline.bag', None))
    assert short_summary(analysis).splitlines()[1] == (
        "the robot fell: pelvis below 0.5 m at sim time 32.810 s, 1.810 s after the try's "
        'first command')


def test_the_demo_summary_is_a_few_lines_the_table_on_request(tmp_path: Path) -> None:
    from support.synthetic_bags import write_run_bag

    analysis = analyze_bag(write_run_bag(tmp_path / 'run.bag', 3.0, with_imu=False,
                                         fall_time_s=1.5))
    tracked = sorted(((joint.rms_error_rad, name) for name, joint in analysis.joints.items()
                      if joint.rms_error_rad is not None), reverse=True)
    assert len(tracked) >= 2
    short = short_summary(analysis).splitlines()
    assert len(short) == 3 and short[1].startswith('the robot fell: ')
    assert short[2] == (f'worst tracking (RMS |commanded - measured|, of {len(tracked)} joints '
                        'that moved): ' + ', '.join(f'{name} {rms:.3f} rad'
                                                     for rms, name in tracked[:3])
                        + '; --table lists them all')
    table = short_summary(analysis, table=True).splitlines()
    assert [row.split()[0] for row in table[3:]] == [name for _, name in tracked]
    assert len(table) == 3 + len(tracked)


def test_a_walks_summary_has_no_tracking_line(tmp_path: Path) -> None:
    from support.synthetic_bags import write_run_bag

    analysis = analyze_bag(write_run_bag(tmp_path / 'run.bag', 3.0, with_imu=False,
                                         fall_time_s=1.5))
    short = short_summary(analysis, tracking=False).splitlines()
    assert short == ['=== summary ===', short_summary(analysis).splitlines()[1]]
