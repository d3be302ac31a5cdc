"""The analysis plot's first page (bags/overview_plot.py): what it shows, checked on the
figure's artists (texts, lines' positions) rather than on pixels, and its size as a PNG."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np
import pytest

from support.synthetic_bags import TrySpec, control_mode, tries_records, write_bag
from tutorial_atlas_control.bags.analysis import Analysis, analyze_bag
from tutorial_atlas_control.bags.overview_plot import (
    axis_shift_s,
    draw_overview,
    tracking_errors,
    waypoint_times,
)
from tutorial_atlas_control.bags.report import plot_run
from tutorial_atlas_control.trajectories.trajectory import load_trajectory

matplotlib.use('Agg')
TRAJECTORIES = Path(__file__).resolve().parents[3] / 'trajectories' / 'Traj_data2.yaml'


def session(tmp_path: Path, specs: list[TrySpec]) -> Analysis:
    records = tries_records(specs, file=str(TRAJECTORIES))
    at = next(index for index, record in enumerate(records) if record.t_s >= 0.3)
    records.insert(at, control_mode(0.3, 'user'))  # in the first try (a rewind follows)
    tmp_path.mkdir(exist_ok=True)
    return analyze_bag(write_bag(tmp_path / 'session.bag', records, in_given_order=True))


@pytest.fixture
def two_tries(tmp_path: Path) -> Analysis:
    return session(tmp_path, [TrySpec(None, 'step_and_fall', fall_s=3.0),
                              TrySpec('reset_world', 'touchdown')])


def texts(fig: object) -> list[str]:
    return [text.get_text() for ax in fig.axes for text in ax.texts]


def test_the_first_page_names_the_fall_the_tries_and_a_refused_mode(
        two_tries: Analysis) -> None:
    fig = draw_overview(two_tries, {'user'})
    shown = texts(fig)
    assert "try 1 fell at sim time 3.430 s, 2.430 s after the try's first command" in shown
    assert 'try 1: step_and_fall' in shown and 'try 2: touchdown' in shown
    assert 'user (refused)' in shown and 'User' in shown
    assert fig.axes[1].get_xlabel() == 'sim time (s), as the live log'
    legend = [text.get_text() for text in fig.axes[0].get_legend().get_texts()]
    assert legend == ['pelvis height', 'fall threshold', 'fall', 'start, waypoints due']
    # The fall marker sits at the sim time its label gives.
    marker = next(line for line in fig.axes[0].lines if line.get_label() == 'fall')
    assert marker.get_xdata()[0] == pytest.approx(3.430)


def test_waypoints_are_due_from_the_trajectorys_first_command(two_tries: Analysis) -> None:
    durations = [waypoint.duration_s for waypoint in load_trajectory(TRAJECTORIES,
                                                                     'step_and_fall')]
    first_s = two_tries.tries[0].first_command_s
    times = waypoint_times(two_tries.data)
    expected = [first_s, *(first_s + np.cumsum(durations))]
    assert times[:len(expected)] == pytest.approx(expected)
    assert max(times) <= two_tries.data.duration_s


def test_the_worst_tracked_joints_come_worst_first_each_try_on_its_own(
        two_tries: Analysis) -> None:
    errors = tracking_errors(two_tries)
    assert list(errors) == ['l_arm_shx']  # the only joint commanded
    t_s, error_rad = errors['l_arm_shx']
    assert np.isnan(error_rad[np.argmin(np.abs(t_s - 6.0))])  # no command held over a reset
    assert np.nanmax(error_rad) == pytest.approx(0.001, abs=1e-4)  # a 0.1 rad/s ramp, 10 ms late


def test_sim_time_on_the_axis_unless_it_went_back(tmp_path: Path, two_tries: Analysis) -> None:
    assert axis_shift_s(two_tries.data) == two_tries.data.start_time_s
    rewound = session(tmp_path / 'rewound', [TrySpec(None, 'step_and_fall'),
                                 TrySpec('reset_simulation', 'touchdown')])
    assert axis_shift_s(rewound.data) == 0.0
    assert draw_overview(rewound, set()).axes[1].get_xlabel().startswith(
        "time from the bag's start (s)")


def test_the_page_is_one_picture_of_1100_by_750_pixels(two_tries: Analysis,
                                                       tmp_path: Path) -> None:
    from PIL import Image

    path = plot_run(two_tries, tmp_path / 'run.png')
    with Image.open(path) as image:
        assert image.size == (1100, 750)
