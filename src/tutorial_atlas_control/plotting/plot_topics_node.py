"""plot_topics.py's ROS side: the master's topics, AnyMsg subscriptions, ROS time, the loop.

Cheap by construction, so that plotting 1 kHz topics does not slow the simulator: the
subscriber callbacks (rospy's receive threads) only append (receipt time, raw bytes, type)
to a bounded deque; the main thread decodes what arrived at most 20 times a second, keeps
the floats asked for and drops the messages; the process runs at niceness 10, so the
simulator's pace comes first on a busy machine. The window and the PNG share the drawing
(plotting/figure.py); what the plot does with the messages is plotting/live.py.
"""

from __future__ import annotations

import collections
import contextlib
import os
import signal
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import rosgraph
import roslib.message
import rospy
from rosgraph_msgs.msg import Clock

from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.plotting.figure import PlotFigure
from tutorial_atlas_control.plotting.live import LivePlot
from tutorial_atlas_control.plotting.series import BACKWARD_JUMP_S

__all__ = ['PlotOptions', 'PlotRefused', 'TopicTap', 'require_master', 'run_plot']

#: Frames are drawn at most this often (s): 20 frames a second.
FRAME_PERIOD_S = 0.05
#: The master's topic list is asked for at most this often (s, wall clock) while an
#: argument waits for its topic.
MASTER_POLL_S = 1.0
#: Raw messages held per topic between two frames; beyond it the oldest are dropped (a
#: stalled main thread, e.g. a window being dragged, must not grow the process).
RAW_QUEUE_LENGTH = 5000
#: rospy's own per-subscription queue (messages); the callback only appends, so it stays short.
SUBSCRIBER_QUEUE_SIZE = 1000
#: In the window, an argument with no sample after this much ROS time (s) gets its line.
SILENCE_NOTICE_S = 5.0
#: Wall time (s) without ROS time moving, under /use_sim_time, before saying so once.
CLOCK_NOTICE_S = 5.0
#: Drawing may take at most this share of the wall time: a frame that took longer delays
#: the next (a busy machine gets fewer than 20 frames a second, not a busier plotter).
DRAW_SHARE = 0.25
#: The plotter yields the CPU to the simulator (nice(2) increment).
NICENESS = 10
#: The picture's size (inches at DPI): the window's, and the PNG's.
FIGURE_SIZE_IN = (8.0, 4.5)
DPI = 100
WINDOW_TITLE = 'plot_topics.py'
#: Keys in the window: pause/resume, autoscale on/off (matplotlib's own keys stay).
PAUSE_KEY = ' '
AUTOSCALE_KEY = 'a'


class PlotRefused(AtlasControlError):
    """plot_topics.py cannot start: no master, no display, an unwritable PNG."""


@dataclass(frozen=True)
class PlotOptions:
    arguments: list[str]
    window_s: float
    png: Path | None = None
    duration_s: float | None = None


def require_master() -> str:
    """The master's URI; refuse to start without one (rospy would wait for it forever)."""
    try:
        uri = rosgraph.get_master_uri()
    except ValueError as err:
        raise PlotRefused(f'bad ROS master setting: {err}') from err
    if not rosgraph.is_master_online(uri):
        raise PlotRefused(f'no ROS master at {uri}: start one (roslaunch tutorial_atlas_control '
                          'atlas.launch, or roscore) or set ROS_MASTER_URI')
    return uri


def published_topics() -> dict[str, str]:
    """{topic: type} of every topic the master knows a publisher of."""
    master = rosgraph.Master(rospy.get_name())
    return dict(master.getPublishedTopics('/'))


@lru_cache(maxsize=None)
def message_class(type_name: str) -> object:
    """The generated class of `type_name`, or None when its package is not built."""
    try:
        return roslib.message.get_message_class(type_name)
    except (ValueError, ImportError):
        return None


class TopicTap:
    """AnyMsg subscriptions whose callbacks keep the raw messages for the main thread."""

    def __init__(self) -> None:
        self._queues: dict[str, collections.deque] = {}
        self._subscribers: list[rospy.Subscriber] = []

    def subscribe(self, topic: str) -> None:
        if topic in self._queues:
            return
        self._queues[topic] = collections.deque(maxlen=RAW_QUEUE_LENGTH)
        self._subscribers.append(rospy.Subscriber(
            topic, rospy.AnyMsg, self._received, callback_args=topic,
            queue_size=SUBSCRIBER_QUEUE_SIZE))

    def _received(self, message: object, topic: str) -> None:
        """rospy's receive thread: keep the raw bytes (decoded later, in the main thread).

        rospy decodes a topic this process already subscribes to with a class (/clock,
        under sim time) with that class, AnyMsg or not: that message is kept as it is.
        """
        raw = getattr(message, '_buff', None)
        if raw is not None:
            header = getattr(message, '_connection_header', None) or {}
            item = (rospy.get_rostime().to_sec(), raw, header.get('type', '*'))
        else:
            item = (rospy.get_rostime().to_sec(), message, str(getattr(message, '_type', '*')))
        self._queues[topic].append(item)

    def drain(self) -> list[tuple[str, str, list[tuple[float, object]]]]:
        """(topic, type, [(receipt s, bytes or message), ...]) of what arrived since the last
        call."""
        batches = []
        for topic, queue in self._queues.items():
            items = []
            while queue:
                items.append(queue.popleft())
            start = 0
            for end in range(1, len(items) + 1):
                if end == len(items) or items[end][2] != items[start][2]:
                    batches.append((topic, items[start][2],
                                    [(stamp, raw) for stamp, raw, _type in items[start:end]]))
                    start = end
        return batches

    def close(self) -> None:
        for subscriber in self._subscribers:
            subscriber.unregister()
        self._subscribers.clear()


class PlotSession:
    """The plot fed from ROS: one `step` per frame."""

    def __init__(self, options: PlotOptions, say: Callable[[str], None]) -> None:
        self.options = options
        self.say = say
        self.sim_time = bool(rospy.get_param('/use_sim_time', False))
        origin_s = 0.0 if self.sim_time else rospy.get_rostime().to_sec()
        self.plot = LivePlot(options.arguments, options.window_s, origin_s)
        self.tap = TopicTap()
        self.refusals = 0
        self._next_poll_s = 0.0
        self._start_s: float | None = None
        self.elapsed_s = 0.0
        self._last_s: float | None = None
        self._clock_wait_since = time.monotonic()
        self._clock_said = False
        self.interrupted = False
        # Sim time: every /clock message, in order, for its rewinds. Polling ROS time missed
        # a reset_simulation when the niced plotter was starved until sim time had passed
        # the time it last saw (make test, 2026-11-29).
        self._rewinds = self._rewinds_seen = 0
        self._clock_s: float | None = None
        self._clock_watch = (rospy.Subscriber('/clock', Clock, self._on_clock)
                             if self.sim_time else None)

    def _on_clock(self, message: Clock) -> None:
        """rospy's thread: count /clock going back (reset_simulation)."""
        now_s = message.clock.to_sec()
        if self._clock_s is not None and now_s < self._clock_s - BACKWARD_JUMP_S:
            self._rewinds += 1
        self._clock_s = now_s

    def interrupt(self, _signum: int, _frame: object) -> None:
        """SIGINT: end the loops at their next turn."""
        self.interrupted = True

    @property
    def time_label(self) -> str:
        return 'sim time (s)' if self.sim_time else 'ROS time since the start (s)'

    def _lines(self, lines: list[str]) -> None:
        for line in lines:
            self.say(line)

    def step(self) -> None:
        """Match topics (now and then), decode what arrived, follow ROS time."""
        if self.plot.unmatched() and time.monotonic() >= self._next_poll_s:
            self._next_poll_s = time.monotonic() + MASTER_POLL_S
            topics, lines = self.plot.match_topics(published_topics())
            self._lines(lines)
            for topic in topics:
                self.tap.subscribe(topic)
        for topic, type_name, items in self.tap.drain():
            self._lines(self.plot.feed(topic, type_name, items, message_class))
        now_s = rospy.get_rostime().to_sec()
        if self._last_s is not None and now_s > self._last_s:
            self.elapsed_s += now_s - self._last_s
        if self._last_s is None or now_s != self._last_s:
            self._clock_wait_since = time.monotonic()
        elif (self.sim_time and not self._clock_said
              and time.monotonic() - self._clock_wait_since > CLOCK_NOTICE_S):
            self._clock_said = True
            self.say('ROS time is not moving: /use_sim_time is set and no /clock arrives '
                     '(is the simulator running and unpaused?)')
        self._last_s = now_s
        rewinds = self._rewinds
        rewound = rewinds != self._rewinds_seen if self._clock_watch is not None else None
        self._rewinds_seen = rewinds
        if self.plot.advance(now_s, rewound):
            self.say(f'ROS time moved back to {now_s:.3f} s (a reset): plot cleared')

    def close(self) -> None:
        self.tap.close()
        if self._clock_watch is not None:
            self._clock_watch.unregister()


def _refused_count(plot: LivePlot) -> int:
    return sum(1 for f in plot.fields if not f.plotted or not f.samples)


def run_plot(options: PlotOptions, say: Callable[[str], None]) -> int:
    """Plot until the window closes (or --duration passes); with --png, write the picture
    after --duration of ROS time. Returns the number of arguments not plotted."""
    backend = _open_backend(options)  # before the node: no window, no node
    rospy.init_node('plot_topics', anonymous=True, disable_signals=True)
    with contextlib.suppress(OSError):  # a process may not be allowed to renice
        os.nice(NICENESS)
    session = PlotSession(options, say)
    # Ctrl-C while Tk's event loop runs would land in a Tk callback (printed, then ignored):
    # the loops check this flag instead, and KeyboardInterrupt is raised once out of them.
    previous = signal.signal(signal.SIGINT, session.interrupt)
    try:
        if options.png is not None:
            return _run_png(session, options)
        return _run_window(session, backend)
    finally:
        signal.signal(signal.SIGINT, previous)
        session.close()
        rospy.signal_shutdown('plot_topics.py done')
        if session.interrupted:
            raise KeyboardInterrupt


def _open_backend(options: PlotOptions) -> object:
    """matplotlib on Agg for --png, else on Tk with a window on $DISPLAY."""
    import matplotlib  # noqa: PLC0415 - the backend must be chosen before pyplot loads

    if options.png is not None:
        matplotlib.use('Agg')
        return None
    display = os.environ.get('DISPLAY', '')
    if not display:
        raise PlotRefused('no display: DISPLAY is not set; use --png OUT.png --duration S '
                          'to write a picture instead')
    try:
        import tkinter  # noqa: PLC0415
    except ImportError as err:
        raise PlotRefused(f'cannot open a window: {err} (Debian package python3-tk; run '
                          '`make setup`)') from None
    try:
        root = tkinter.Tk()
        root.destroy()
    except tkinter.TclError as err:
        raise PlotRefused(f'cannot open a window: no X server answers at DISPLAY={display} '
                          f'({err}); use --png OUT.png --duration S instead') from None
    matplotlib.use('TkAgg')
    import matplotlib.pyplot as plt  # noqa: PLC0415

    return plt


def _run_png(session: PlotSession, options: PlotOptions) -> int:
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: PLC0415
    from matplotlib.figure import Figure  # noqa: PLC0415

    figure = Figure(figsize=FIGURE_SIZE_IN, dpi=DPI)
    FigureCanvasAgg(figure)
    view = PlotFigure(figure, session.plot, session.time_label)
    duration_s = options.duration_s if options.duration_s is not None else options.window_s
    while session.elapsed_s < duration_s and not session.interrupted:
        session.step()
        time.sleep(FRAME_PERIOD_S)
    if session.interrupted:
        return _refused_count(session.plot)
    session.step()
    for line in session.plot.silent_lines(session.elapsed_s):
        session.say(line)
    if not any(f.samples for f in session.plot.plotted()):
        session.say(f'nothing to plot after {session.elapsed_s:.1f} s of ROS time: '
                    f'{options.png} not written')
        return _refused_count(session.plot)
    view.update()
    try:
        figure.savefig(options.png, dpi=DPI)
    except OSError as err:
        raise PlotRefused(f'cannot write {options.png}: {err.strerror or err}') from None
    return _refused_count(session.plot)


def _run_window(session: PlotSession, plt: object) -> int:
    figure = plt.figure(figsize=FIGURE_SIZE_IN, dpi=DPI)
    figure.canvas.manager.set_window_title(
        f'{WINDOW_TITLE} {" ".join(session.options.arguments)}')
    view = PlotFigure(figure, session.plot, session.time_label)
    figure.text(0.01, 0.01, 'space: pause/resume   a: autoscale on/off', fontsize='x-small',
                color='0.4')
    state = {'paused': False, 'autoscale': True, 'closed': False}

    def on_key(event: object) -> None:
        if event.key == PAUSE_KEY:
            state['paused'] = not state['paused']
        elif event.key == AUTOSCALE_KEY:
            state['autoscale'] = not state['autoscale']
        view.update(autoscale=state['autoscale'], paused=state['paused'])
        figure.canvas.draw_idle()

    def on_close(_event: object) -> None:
        state['closed'] = True

    figure.canvas.mpl_connect('key_press_event', on_key)
    figure.canvas.mpl_connect('close_event', on_close)
    plt.show(block=False)
    duration_s = session.options.duration_s
    next_draw_s = 0.0
    while (not state['closed'] and not session.interrupted
           and (duration_s is None or session.elapsed_s < duration_s)):
        frame_start = time.monotonic()
        session.step()
        if session.elapsed_s >= SILENCE_NOTICE_S:
            for line in session.plot.silent_lines(session.elapsed_s):
                session.say(line)
        if not state['paused'] and time.monotonic() >= next_draw_s:
            draw_start = time.monotonic()
            view.update(autoscale=state['autoscale'])
            figure.canvas.draw()
            next_draw_s = draw_start + max(FRAME_PERIOD_S,
                                           (time.monotonic() - draw_start) / DRAW_SHARE)
        remaining = min(next_draw_s, frame_start + FRAME_PERIOD_S) - time.monotonic()
        figure.canvas.start_event_loop(max(0.001, remaining))
    plt.close(figure)
    return _refused_count(session.plot)


def stderr_line(prog: str) -> Callable[[str], None]:
    def say(line: str) -> None:
        print(f'{prog}: {line}', file=sys.stderr, flush=True)
    return say
