"""One line from the simulator when the run stops being recorded.

A recorder killed (SIGKILL, OOM) or stopped by a full disk leaves the simulator running
with nobody recording, and nothing in the simulator's output would say so. The simulator
sees the recorder's connection to /atlas/joint_states go. A killed recorder never
unregisters: the master still lists it as a subscriber, and the line comes at once. One
that unregistered stopped of itself: on Ctrl-C roslaunch signals every node at once and the
recorder may close its bag before the simulator is down, so the line comes only if the
simulator is still running GRACE_S later (a full disk: the recorder has said why). Nothing
is said once the simulator's own shutdown has begun: it unregisters its publishers before
rospy reports it shut down, and the master then tells the recorder, which drops its
connections while still listed as a subscriber, as a killed one would be.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

import rosgraph
import rospy

from tutorial_atlas_control import topics
from tutorial_atlas_control.node.transport import subscriber_names

__all__ = ['GRACE_S', 'RECORDER_NODE', 'RecorderWatch', 'start_recorder_watch', 'stopped_line']

#: The recorder's node name in atlas.launch (record_run.sh gives it to either recorder).
RECORDER_NODE = '/recorder'
#: Wall seconds between a recorder that unregistered leaving and the line.
GRACE_S = 10.0
#: Wall seconds between looks at the subscribers.
POLL_S = 0.5


def stopped_line(sim_s: float) -> str:
    """What the simulator logs when the recorder is gone."""
    return (f'the recorder ({RECORDER_NODE}) stopped at sim time {sim_s:.1f} s: this run is no '
            'longer recorded (the simulation goes on); if it was killed or its disk is full, its '
            'bag is left as atlas_<date-time>.bag.active: `rosbag reindex` it to read it')


class RecorderWatch:
    """The recorder's comings and goings, from the subscribers seen (no ROS: testable)."""

    def __init__(self, grace_s: float = GRACE_S) -> None:
        self.grace_s = grace_s
        self.recording = False
        self._left: tuple[float, float] | None = None  # (wall s, sim s) when it went

    def update(self, subscribers: set[str], wall_s: float, sim_s: float,
               still_registered: Callable[[], bool]) -> str | None:
        """The line to log now, if any, given the subscribers seen at `wall_s`.

        `still_registered` (asked once, when the recorder's connection goes): does the
        master still list the recorder as a subscriber? Then it was killed.
        """
        if RECORDER_NODE in subscribers:
            self.recording, self._left = True, None
            return None
        if not self.recording:
            return None
        if self._left is None:
            self._left = (wall_s, sim_s)
            if still_registered():
                return self._said()
        if wall_s - self._left[0] >= self.grace_s:
            return self._said()
        return None

    def _said(self) -> str:
        assert self._left is not None
        line, self._left, self.recording = stopped_line(self._left[1]), None, False
        return line


def _registered(topic: str) -> bool:
    """Does the master list RECORDER_NODE as a subscriber of `topic`? (False if unreachable.)"""
    try:
        _, subscribers, _ = rosgraph.Master(rospy.get_name()).getSystemState()
    except Exception:  # noqa: BLE001 - no master, or a refusal: say nothing early
        return False
    return any(name == topic and RECORDER_NODE in nodes for name, nodes in subscribers)


def _shutting_down() -> bool:
    """Has this node's shutdown begun? (rospy.is_shutdown() turns True only after the
    shutdown hooks that unregister the node's topics and close its connections.)"""
    return rospy.core.is_shutdown_requested() or rospy.is_shutdown()


def start_recorder_watch(publisher: rospy.Publisher, sim_s: Callable[[], float],
                         clock: Callable[[], float],
                         registered: Callable[[], bool] | None = None,
                         shutting_down: Callable[[], bool] = _shutting_down,
                         say: Callable[[str], None] = rospy.logwarn,
                         poll_s: float = POLL_S) -> threading.Event:
    """Watch `publisher`'s subscribers from a daemon thread until the returned event is set
    (the node's spin() sets it when the loop ends) or the node's shutdown begins.

    `registered` (default: ask the master): is the recorder still listed as a subscriber?
    """
    still_registered = registered or (lambda: _registered(topics.JOINT_STATES))
    watch = RecorderWatch()
    stop = threading.Event()

    def run() -> None:
        while not stop.wait(poll_s) and not shutting_down():
            line = watch.update(subscriber_names(publisher), clock(), sim_s(), still_registered)
            if line is not None and not stop.is_set() and not shutting_down():
                say(line)

    threading.Thread(target=run, name='recorder_watch', daemon=True).start()
    return stop
