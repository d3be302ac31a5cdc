"""plot_topics.py's logic without ROS: rqt_plot's arguments, field paths checked against
message classes, values read from serialized messages, the rolling window, resets, and
the drawing shared by the window and the PNG (on Agg here).

Message classes are the generated ones (sensor_msgs, nav_msgs, rosgraph_msgs, std_msgs),
used as plot_topics.py gets them at run time: from a type name, messages as bytes.
"""

from __future__ import annotations

import io
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from support.plot_pixels import curve_extent, shows_status_note
from tutorial_atlas_control.plotting.fields import (
    FieldReader,
    FieldStep,
    PlotError,
    expand_arguments,
    parse_field_path,
    split_topic,
)
from tutorial_atlas_control.plotting.figure import PlotFigure, y_range
from tutorial_atlas_control.plotting.live import LivePlot
from tutorial_atlas_control.plotting.series import ClockWatch, RollingSeries

genpy = pytest.importorskip('genpy', reason='needs Debian\'s genpy (make setup)')
roslib_message = pytest.importorskip('roslib.message')
from nav_msgs.msg import Odometry  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import Float64  # noqa: E402

lookup = roslib_message.get_message_class
JOINTS = 28
TOPICS = {'/atlas/joint_states': 'sensor_msgs/JointState', '/ground_truth_odom':
          'nav_msgs/Odometry', '/clock': 'rosgraph_msgs/Clock', '/atlas': 'std_msgs/String'}


def serialized(message: object) -> bytes:
    buffer = io.BytesIO()
    message.serialize(buffer)
    return buffer.getvalue()


def joint_state(stamp_s: float, elbow: float) -> bytes:
    position = [0.1 * k for k in range(JOINTS)]
    position[19] = elbow
    message = JointState(name=[f'j{k}' for k in range(JOINTS)], position=position,
                         velocity=[0.0] * JOINTS, effort=[0.0] * JOINTS)
    message.header.stamp = genpy.Time.from_sec(stamp_s)
    return serialized(message)


# -- arguments ---------------------------------------------------------------------------
def test_rqt_plot_shorthands_are_written_out() -> None:
    assert expand_arguments(['/odom/pose/pose/position/x:y:z']) == [
        '/odom/pose/pose/position/x', '/odom/pose/pose/position/y',
        '/odom/pose/pose/position/z']
    assert expand_arguments(['/a/b,/c/d[2]', 'e/f']) == ['/a/b', '/c/d[2]', '/e/f']
    assert expand_arguments(['/atlas/joint_states/position[19]:velocity[19]']) == [
        '/atlas/joint_states/position[19]', '/atlas/joint_states/velocity[19]']


def test_a_colon_form_without_a_field_and_an_empty_list_are_refused() -> None:
    with pytest.raises(PlotError, match='^x:y: the FIELD1:FIELD2 form needs TOPIC/FIELD1'):
        expand_arguments(['x:y'])
    with pytest.raises(PlotError, match='^no TOPIC/FIELD to plot$'):
        expand_arguments([','])


def test_field_paths_parse_with_indexes_and_nesting() -> None:
    assert parse_field_path('position[19]') == (FieldStep('position', 19),)
    assert parse_field_path('pose/pose/position/z') == tuple(
        FieldStep(n) for n in ('pose', 'pose', 'position', 'z'))
    assert parse_field_path('a[0].b') == (FieldStep('a', 0), FieldStep('b'))
    assert str(FieldStep('position', 3)) == 'position[3]'


@pytest.mark.parametrize(('text', 'message'), [
    ('position[x]', "'position[x]' is not a field name, or NAME[N] with N >= 0"),
    ('position[-1]', "'position[-1]' is not a field name, or NAME[N] with N >= 0"),
    ('pose//x', "'pose//x' is not a field path (expected FIELD, FIELD[N] or FIELD/SUBFIELD)"),
    ('', "'' is not a field path (expected FIELD, FIELD[N] or FIELD/SUBFIELD)"),
    ('9lives', "'9lives' is not a field name, or NAME[N] with N >= 0"),
])
def test_bad_field_paths_are_named(text: str, message: str) -> None:
    with pytest.raises(PlotError) as refused:
        parse_field_path(text)
    assert str(refused.value) == message


def test_the_topic_is_the_longest_published_prefix() -> None:
    assert split_topic('/atlas/joint_states/position[19]', TOPICS) == (
        '/atlas/joint_states', 'position[19]')
    assert split_topic('/atlas/data', TOPICS) == ('/atlas', 'data')
    assert split_topic('/atlas/joint_statesX/a', TOPICS) == ('/atlas', 'joint_statesX/a')
    assert split_topic('/clock', TOPICS) == ('/clock', '')
    assert split_topic('/nothing/x', TOPICS) is None


# -- fields against message classes ------------------------------------------------------
def reader(message_class: type, path: str) -> FieldReader:
    return FieldReader.for_class(message_class, parse_field_path(path), lookup)


def test_numbers_nested_fields_and_times_are_read() -> None:
    state = JointState(position=[0.5, 1.5])
    state.header.stamp = genpy.Time(3, 250_000_000)
    state.header.seq = 7
    assert reader(JointState, 'position[1]').read(state) == 1.5
    assert reader(JointState, 'header/stamp').read(state) == 3.25
    assert reader(JointState, 'header/seq').read(state) == 7.0
    odometry = Odometry()
    odometry.pose.pose.position.z = 0.93
    assert reader(Odometry, 'pose/pose/position/z').read(odometry) == 0.93
    assert reader(Odometry, 'pose/covariance[35]').read(odometry) == 0.0


@pytest.mark.parametrize(('message_class', 'path', 'message'), [
    (JointState, 'positon', "sensor_msgs/JointState has no field 'positon' (its fields: "
                            'header, name, position, velocity, effort)'),
    (JointState, 'name[0]', 'name[0] is a string, not a number'),
    (JointState, 'position', 'position is an array (float64[]): give an element, e.g. '
                             'position[0]'),
    (JointState, 'header', 'header is a message (std_msgs/Header), not a number: name one of '
                           'its fields (its fields: seq, stamp, frame_id)'),
    (JointState, 'header/seq[2]', 'seq is uint32, not an array: no index'),
    (JointState, 'position[0]/x', "position[0] is a number (float64): it has no field 'x'"),
    (Odometry, 'pose/covariance[36]', 'covariance[36] is past the end of covariance '
                                      '(float64[36])'),
    (Clock, 'clock/secs', "clock is a number (time): it has no field 'secs'"),
])
def test_fields_that_are_not_numbers_are_refused_with_the_reason(
        message_class: type, path: str, message: str) -> None:
    with pytest.raises(PlotError) as refused:
        reader(message_class, path)
    assert str(refused.value) == message


def test_an_index_past_a_variable_array_s_end_is_refused_when_read() -> None:
    field = reader(JointState, 'position[40]')
    with pytest.raises(PlotError, match=r'^position\[40\] is past the end of position \(2 '):
        field.read(JointState(position=[0.0, 1.0]))


# -- the live plot -----------------------------------------------------------------------
def live(*arguments: str, window_s: float = 10.0) -> LivePlot:
    plot = LivePlot(list(arguments), window_s)
    topics, lines = plot.match_topics(TOPICS)
    assert lines == []
    return plot


def test_serialized_messages_give_the_fields_at_their_stamps() -> None:
    plot = live('/atlas/joint_states/position[19]', '/atlas/joint_states/position[2]')
    lines = plot.feed('/atlas/joint_states', 'sensor_msgs/JointState',
                      [(9.0, joint_state(1.0 + 0.001 * k, math.sin(k))) for k in range(100)],
                      lookup)
    assert lines == []
    elbow, other = plot.fields
    np.testing.assert_allclose(elbow.series.times_s, 1.0 + 0.001 * np.arange(100))
    np.testing.assert_allclose(elbow.series.values, np.sin(np.arange(100)))
    np.testing.assert_allclose(other.series.values, 0.2)
    assert elbow.samples == other.samples == 100


def test_messages_without_a_header_are_placed_at_their_receipt() -> None:
    plot = live('/atlas/data')
    plot.feed('/atlas', 'std_msgs/Float64', [(4.5, serialized(Float64(data=2.0)))], lookup)
    assert list(plot.fields[0].series.times_s) == [4.5]
    assert list(plot.fields[0].series.values) == [2.0]


def test_a_bad_field_gets_one_line_and_the_others_go_on() -> None:
    plot = live('/atlas/joint_states/positon[1]', '/atlas/joint_states/position[19]',
                '/atlas/joint_states/name[0]', '/atlas/joint_states/position[30]')
    batch = [(0.0, joint_state(0.5, 1.25))]
    lines = plot.feed('/atlas/joint_states', 'sensor_msgs/JointState', batch, lookup)
    assert lines == [
        "cannot plot /atlas/joint_states/positon[1]: /atlas/joint_states: sensor_msgs/JointState "
        "has no field 'positon' (its fields: header, name, position, velocity, effort)",
        'cannot plot /atlas/joint_states/name[0]: /atlas/joint_states: name[0] is a string, not '
        'a number',
        'cannot plot /atlas/joint_states/position[30]: /atlas/joint_states: position[30] is past '
        'the end of position (28 elements in the message)',
    ]
    assert [f.argument for f in plot.plotted()] == ['/atlas/joint_states/position[19]']
    assert list(plot.plotted()[0].series.values) == [1.25]
    # said once: the next messages add no line
    assert plot.feed('/atlas/joint_states', 'sensor_msgs/JointState', batch, lookup) == []
    assert list(plot.plotted()[0].series.values) == [1.25, 1.25]


def test_a_topic_itself_or_a_type_without_class_is_refused() -> None:
    plot = LivePlot(['/clock', '/atlas/joint_states/position[1]'], 10.0)
    _topics, lines = plot.match_topics(TOPICS)
    assert lines == ['cannot plot /clock: /clock is a topic (rosgraph_msgs/Clock), not a field '
                     'of one: add /FIELD']
    lines = plot.feed('/atlas/joint_states', 'no_such_msgs/Thing', [(0.0, b'')], lookup)
    assert lines == ['cannot plot /atlas/joint_states/position[1]: no message class for '
                     'no_such_msgs/Thing (is its package built and the workspace sourced?)']


def test_silent_arguments_are_named_once() -> None:
    plot = LivePlot(['/nothing/x', '/atlas/joint_states/position[1]'], 10.0)
    plot.match_topics(TOPICS)
    assert plot.silent_lines(3.0) == [
        'no data for /nothing/x: no topic it names is published (3.0 s of ROS time)',
        'no data for /atlas/joint_states/position[1]: no message on /atlas/joint_states in '
        '3.0 s of ROS time']
    assert plot.silent_lines(4.0) == []


def test_a_reset_of_sim_time_clears_the_plot_and_late_messages_are_dropped() -> None:
    plot = live('/atlas/joint_states/position[19]')
    feed = [(0.0, joint_state(t, t)) for t in (20.0, 20.5, 21.0)]
    assert not plot.advance(21.0)
    plot.feed('/atlas/joint_states', 'sensor_msgs/JointState', feed, lookup)
    assert len(plot.fields[0].series) == 3
    assert not plot.advance(21.5)  # reset_world keeps sim time: nothing happens
    assert plot.advance(0.002)      # reset_simulation: back to 0
    assert len(plot.fields[0].series) == 0 and plot.resets == 1
    # a message of the run before the reset, still in flight, is not plotted at 21 s
    plot.feed('/atlas/joint_states', 'sensor_msgs/JointState',
              [(0.0, joint_state(21.6, 1.0)), (0.0, joint_state(0.003, 2.0))], lookup)
    assert list(plot.fields[0].series.values) == [2.0]


# -- the rolling window ------------------------------------------------------------------
def test_the_window_keeps_the_last_seconds_and_one_sample_before() -> None:
    series = RollingSeries(2.0, capacity=4)
    series.extend(np.arange(10.0), np.arange(10.0) * 10)
    series.trim(9.0)
    assert list(series.times_s) == [7.0, 8.0, 9.0]  # 7.0: the window's left edge
    series.clear()
    assert len(series) == 0


@settings(deadline=None)  # a loaded machine is slow, not wrong: no 200 ms per example
@given(st.lists(st.lists(st.floats(0.0, 1.0), max_size=50), max_size=30),
       st.floats(0.05, 5.0))
def test_the_window_holds_what_a_plain_list_would(chunks: list[list[float]],
                                                  window_s: float) -> None:
    series = RollingSeries(window_s, capacity=2)
    kept: list[float] = []
    now = 0.0
    for chunk in chunks:
        times = [now + step for step in np.cumsum(chunk)]
        now = times[-1] if times else now
        series.extend(times, times)
        kept += times
        series.trim(now)
        first = next((i for i, t in enumerate(kept) if t > now - window_s), len(kept))
        kept = kept[max(0, first - 1):]
        assert list(series.times_s) == kept
        assert list(series.values) == kept


def test_the_clock_watch_sees_time_moving_back() -> None:
    watch = ClockWatch()
    assert [watch.moved_back(t) for t in (0.0, 5.0, 5.0, 7.0, 0.001, 0.5)] == [
        False, False, False, False, True, False]


def test_the_y_range_of_flat_and_missing_data() -> None:
    assert y_range([]) is None
    assert y_range([np.array([np.nan])]) is None
    assert y_range([np.array([1.0, 1.0])]) == (0.5, 1.5)
    assert y_range([np.array([100.0])]) == (90.0, 110.0)
    low, high = y_range([np.array([0.0, 1.0]), np.array([np.nan, 3.0])])
    assert low == pytest.approx(-0.15) and high == pytest.approx(3.15)


# -- the drawing (the PNG's; the window's is the same code on Tk) -----------------------
def draw(values_of_time: object, with_data: bool = True, paused: bool = False) -> np.ndarray:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    plot = live('/atlas/joint_states/position[19]', window_s=4.0)
    if with_data:
        times = np.arange(0.0, 6.0, 0.001)
        plot.feed('/atlas/joint_states', 'sensor_msgs/JointState',
                  [(0.0, joint_state(t, values_of_time(t))) for t in times[::5]], lookup)
    plot.advance(6.0)
    figure = Figure(figsize=(8.0, 4.5), dpi=100)
    canvas = FigureCanvasAgg(figure)
    PlotFigure(figure, plot, 'sim time (s)').update(paused=paused)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3].copy()


def test_a_sine_shows_as_a_curve_and_flat_or_empty_plots_do_not() -> None:
    sine = curve_extent(draw(lambda t: 1.0 + 0.5 * math.sin(2.0 * math.pi * t)))
    flat = curve_extent(draw(lambda t: 1.0))
    empty = curve_extent(draw(lambda t: 1.0, with_data=False))
    print(f'sine {sine}, flat {flat}, empty {empty}')
    assert sine.shows_a_curve()
    assert not flat.shows_a_curve() and flat.columns_fraction > 0.6  # across, but flat
    assert not empty.shows_a_curve()


def test_the_paused_note_is_seen_and_a_running_plot_has_none() -> None:
    """What the window test waits for after the pause key (the plotter draws no other red)."""
    def sine(t: float) -> float:
        return 1.0 + 0.5 * math.sin(2.0 * math.pi * t)

    assert shows_status_note(draw(sine, paused=True))
    assert not shows_status_note(draw(sine))
    assert not shows_status_note(draw(sine, with_data=False))


def test_the_time_axis_follows_ros_time_from_0() -> None:
    from matplotlib.figure import Figure

    plot = live('/atlas/joint_states/position[19]', window_s=4.0)
    view = PlotFigure(Figure(), plot, 'sim time (s)')
    plot.advance(1.0)
    view.update()
    assert view.axes.get_xlim() == (0.0, 4.0)
    plot.advance(10.5)
    view.update(paused=True, autoscale=False)
    assert view.axes.get_xlim() == (6.5, 10.5)
    assert view.status.get_text() == 'PAUSED  autoscale off'


# -- legends, units, the picture's window ------------------------------------------------
def test_a_joint_state_element_is_named_in_the_legend_with_units() -> None:
    from matplotlib.figure import Figure

    plot = live('/atlas/joint_states/position[19]', '/atlas/joint_states/velocity[2]',
                '/ground_truth_odom/pose/pose/position/z', '/clock/clock')
    plot.feed('/atlas/joint_states', 'sensor_msgs/JointState',
              [(0.0, joint_state(1.0, 0.5))], lookup)
    odom = Odometry()
    odom.header.stamp = genpy.Time.from_sec(1.0)
    plot.feed('/ground_truth_odom', 'nav_msgs/Odometry', [(0.0, serialized(odom))], lookup)
    elbow, speed, height, clock = plot.fields
    assert (elbow.label, speed.label) == ('/atlas/joint_states/position[19] (j19)',
                                          '/atlas/joint_states/velocity[2] (j2)')
    assert height.label == '/ground_truth_odom/pose/pose/position/z'  # no name list there
    assert (elbow.unit, speed.unit, height.unit) == ('rad', 'rad/s', 'm')
    assert clock.unit is None  # not matched yet (no message): no unit claimed
    view = PlotFigure(Figure(), plot, 'sim time (s)')
    view.update()
    legend = [text.get_text() for text in view.axes.get_legend().get_texts()]
    assert legend == ['/atlas/joint_states/position[19] (j19)',
                      '/atlas/joint_states/velocity[2] (j2)',
                      '/ground_truth_odom/pose/pose/position/z',
                      '/clock/clock (no data yet)']
    assert view.axes.get_ylabel() == 'm, rad, rad/s'


@pytest.mark.parametrize(('argv', 'window_s'), [
    (['x/y', '--png', 'a.png', '--duration', '5'], 5.0),  # the picture is all data
    (['x/y', '--png', 'a.png', '--duration', '5', '--window', '2'], 2.0),
    (['x/y', '--duration', '5'], 10.0),  # a window on screen keeps its default
    (['x/y'], 10.0),
])
def test_the_pictures_window_fits_its_duration(argv: list[str], window_s: float) -> None:
    from tutorial_atlas_control.cli import plot_topics as cli

    assert cli.window_s(cli.parse_args(argv)) == window_s
