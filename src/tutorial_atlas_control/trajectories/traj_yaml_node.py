"""ROS glue of ``scripts/traj_yaml.py``: the DRCSim tutorial's trajectory player, ported.

Same command line, topics, parameters, message and motion as the tutorial's
``traj_yaml.py``: each waypoint moves linearly from the measured joint positions to the
waypoint's, published at 50 Hz in ROS time. Unlike the tutorial, it validates the file
before anything starts, waits (bounded) for the simulator before the first command, reads
joint states by name and stamps each command. File handling and interpolation live in
:mod:`tutorial_atlas_control.trajectories.trajectory`; this module only talks to ROS.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable, Iterable, Sequence
from typing import Generic, TypeVar

import numpy as np
import rosgraph
import rospy
from sensor_msgs.msg import JointState
from std_msgs.msg import String

from tutorial_atlas_control import topics
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import ATLAS_PREFIX, JOINT_NAMES, NUM_JOINTS, joint_index
from tutorial_atlas_control.sim import LOAD_HINT, Gains, GainsError, gains_from_params
from tutorial_atlas_control.trajectories.schedule import (
    TimeWentBackError,
    done_line,
    playing_line,
    run_trajectory,
    trajectory_log_line,
)
from tutorial_atlas_control.trajectories.trajectory import Waypoint
from tutorial_atlas_control.units import finite_number

__all__ = [
    'JointStateCache',
    'TrajYamlError',
    'build_command',
    'joint_commands_type',
    'linger',
    'play',
    'positions_by_name',
    'read_gains',
    'require_master',
    'run_trajectory',
    'wait_for_joint_state',
    'wait_for_log_readers',
    'wait_for_ros_time',
    'wait_for_subscribers',
    'wait_until_handed_over',
    'mode_warning',
]

#: The tutorial's node name.
NODE_NAME = 'tutorial_atlas_control'
JOINT_STATES_TOPIC = topics.JOINT_STATES
JOINT_COMMANDS_TOPIC = topics.JOINT_COMMANDS
LAUNCH_HINT = 'roslaunch tutorial_atlas_control atlas.launch'

#: Default wait (s, wall clock) for the first message on /atlas/joint_states.
JOINT_STATE_TIMEOUT_S = 10.0
#: Private parameter overriding JOINT_STATE_TIMEOUT_S, e.g. `_joint_state_timeout:=30`.
JOINT_STATE_TIMEOUT_PARAM = '~joint_state_timeout'
#: Default wait (s, wall clock) for every subscriber of /atlas/joint_commands (the simulator,
#: a recorder) to connect before the first command: rospy drops what is published before a
#: subscriber connects, and a busy host can take seconds to connect (see wait_for_subscribers).
SUBSCRIBER_TIMEOUT_S = 10.0
#: Private parameter overriding SUBSCRIBER_TIMEOUT_S, e.g. `_subscriber_timeout:=30`.
SUBSCRIBER_TIMEOUT_PARAM = '~subscriber_timeout'
#: Polling interval (s, wall clock) of the waits above.
POLL_PERIOD_S = 0.01
#: The master's subscriber list is asked for at most this often (s, wall clock).
MASTER_POLL_PERIOD_S = 0.1
#: Longest wait (s, wall clock), before a command is published, for rospy's writer threads to
#: take the previous one off the publisher's queue (see wait_until_handed_over). Above the
#: worst starvation seen on a loaded host (29 ms, then over 50 ms beside the parallel test
#: suite); it delays the schedule only while the writers are starved, and a subscriber that
#: stops reading costs it once (its connection is then not waited for).
HANDOVER_WAIT_S = 0.5
#: Polling interval (s, wall clock) of that wait.
HANDOVER_POLL_S = 0.0005
#: Wall time (s) the port stays up after its last command and line, so that a slow
#: subscriber reads them. rospy's shutdown first tells the master the port is gone, and a
#: roscpp subscriber then drops the connection at once, bytes it has not read included: a
#: recorder starved for a moment (it runs niced) lost the last 3 commands and the done line
#: of a fresh clone's demo while the simulator got them all. Cut short by Ctrl-C.
EXIT_GRACE_S = 0.5
#: Longest wait (s, wall clock) for the simulator's latched mode once it is connected; a
#: simulator that does not publish it (an older one, a stand-in) gets no mode check.
MODE_WAIT_S = 1.0
#: The mode in which the simulator applies the commands.
USER_MODE = 'User'


_T = TypeVar('_T')
_M = TypeVar('_M')


class TrajYamlError(AtlasControlError):
    """traj_yaml.py cannot run: no workspace, no master, no simulator, bad joint states."""


def read_gains(get_param: Callable[..., object] = rospy.get_param) -> Gains:
    """Read the tutorial's gains, ``atlas_controller/gains/<joint>/{p,i,d,i_clamp}``.

    Args:
        get_param: ``rospy.get_param`` or a stand-in; called once, with the gains
            namespace and a default of None (one round trip instead of 112).

    Raises:
        GainsError: a parameter is missing or not a finite number; the message names
            it and says how to load the gains.
    """
    tree = get_param(topics.GAINS_PARAM, None)
    if tree is None:
        raise GainsError(f'parameter {topics.GAINS_PARAM} is not set; {LOAD_HINT}')
    return gains_from_params(tree)


def positions_by_name(names: Sequence[str], positions: Sequence[float]) -> np.ndarray:
    """Joint positions (rad) of a JointState, reordered into the tutorial's joint order.

    Names may be bare (``back_lbz``) or prefixed (``atlas::back_lbz``); joints that
    are not Atlas's 28 are ignored.

    Raises:
        TrajYamlError: the arrays differ in length, a joint is missing or named
            twice, or a position is not finite.
    """
    if len(names) != len(positions):
        raise TrajYamlError(
            f'{JOINT_STATES_TOPIC}: the message has {len(names)} names '
            f'but {len(positions)} positions'
        )
    result = np.full(NUM_JOINTS, np.nan)
    seen = np.zeros(NUM_JOINTS, dtype=bool)
    for name, position in zip(names, positions):
        index = joint_index(name)
        if index is None:
            continue
        if seen[index]:
            raise TrajYamlError(f'{JOINT_STATES_TOPIC}: joint {JOINT_NAMES[index]} is named twice')
        seen[index] = True
        result[index] = position
    if not seen.all():
        missing = [JOINT_NAMES[index] for index in np.flatnonzero(~seen)]
        raise TrajYamlError(
            f'{JOINT_STATES_TOPIC}: the message lacks {len(missing)} Atlas joint(s): '
            f'{", ".join(missing)}'
        )
    if not np.isfinite(result).all():
        bad = int(np.flatnonzero(~np.isfinite(result))[0])
        raise TrajYamlError(
            f'{JOINT_STATES_TOPIC}: the position of {JOINT_NAMES[bad]} is {result[bad]}')
    return result


class LatestMessage(Generic[_M]):
    """The latest message of a topic, filled by a subscriber callback (another thread)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._message: _M | None = None

    def callback(self, message: _M) -> None:
        with self._lock:
            self._message = message

    def latest(self) -> _M | None:
        with self._lock:
            return self._message


class JointStateCache(LatestMessage[JointState]):
    """The latest JointState, filled by a subscriber callback (another thread)."""

    def positions(self) -> np.ndarray:
        """The latest joint positions in tutorial order (rad); see :func:`positions_by_name`."""
        message = self.latest()
        if message is None:
            raise TrajYamlError(f'no message received on {JOINT_STATES_TOPIC}')
        return positions_by_name(message.name, message.position)


def wait_for_joint_state(
    cache: JointStateCache,
    timeout_s: float = JOINT_STATE_TIMEOUT_S,
    is_shutdown: Callable[[], bool] = rospy.is_shutdown,
) -> JointState:
    """Wait (wall clock) until `cache` holds a joint state, and return it.

    Raises:
        TrajYamlError: nothing arrived within `timeout_s`; the message says to start the simulator.
        rospy.ROSInterruptException: the node was shut down while waiting.
    """
    return _poll(cache.latest, timeout_s, is_shutdown, 'joint states',
                 f'no simulator is publishing {JOINT_STATES_TOPIC}: '
                 f'nothing arrived within {timeout_s:g} s; '
                 f'start it with `{LAUNCH_HINT}`')


def wait_for_ros_time(
    timeout_s: float,
    ros_time: Callable[[], float] = rospy.get_time,
    is_shutdown: Callable[[], bool] = rospy.is_shutdown,
) -> float:
    """Wait (wall clock) until ROS time has started, and return it (s).

    With ``/use_sim_time`` rospy's time is 0 until the first /clock message, which comes
    over its own connection, maybe after the joint states: a trajectory started then would
    stamp its first command 0 and schedule from 0. With wall-clock time it returns at once.

    Raises:
        TrajYamlError: still 0 after `timeout_s`: /use_sim_time is set but nothing publishes /clock.
        rospy.ROSInterruptException: the node was shut down while waiting.
    """
    return _poll(lambda: ros_time() or None, timeout_s, is_shutdown, topics.CLOCK,
                 f'/use_sim_time is set but no /clock arrived within {timeout_s:g} s; '
                 f'start the simulator with `{LAUNCH_HINT}`')


def _poll(value: Callable[[], _T | None], timeout_s: float, is_shutdown: Callable[[], bool],
          what: str, timeout_error: str) -> _T:
    """Poll `value` (wall clock) until it is not None, and return it.

    Raises:
        TrajYamlError: `timeout_error`, after `timeout_s`.
        rospy.ROSInterruptException: the node was shut down while waiting for `what`.
    """
    deadline = time.monotonic() + timeout_s
    while (result := value()) is None:
        if is_shutdown():
            raise rospy.ROSInterruptException(f'shut down while waiting for {what}')
        if time.monotonic() >= deadline:
            raise TrajYamlError(timeout_error)
        time.sleep(POLL_PERIOD_S)
    return result


def mode_warning(mode: str | None) -> str | None:
    """The start-up warning for the simulator's control mode `mode` (None: unknown).

    The tutorial has the user switch to User first; forgotten, the robot does not move and
    nothing else says why. traj_yaml.py does not switch itself: that step is the tutorial's.
    """
    if mode is None or mode == USER_MODE:
        return None
    return (f'the simulator is in {mode} mode, which does not apply these commands: the robot '
            f'will not move; switch to User mode first: {topics.SWITCH_TO_USER}')


def build_command(
    message_type: Callable[[], object], positions: Iterable[float], gains: Gains, stamp: object
) -> object:
    """A JointCommands for all 28 joints as the tutorial sent it, plus a header stamp.

    Names carry the ``atlas::`` prefix; kp/ki/kd_position are the gains p/i/d; velocity,
    effort and kp_velocity are zero; ``i_effort_min = -i_clamp``, ``i_effort_max = i_clamp``.

    Args:
        message_type: ``osrf_msgs.msg.JointCommands`` (a parameter so tests need no workspace).
        positions: the 28 commanded positions (rad), tutorial order.
        gains: from :func:`read_gains`.
        stamp: the header stamp, ``rospy.Time.now()``.
    """
    command = message_type()
    command.header.stamp = stamp
    command.name = [ATLAS_PREFIX + name for name in JOINT_NAMES]
    command.position = [float(value) for value in positions]
    zeros = [0.0] * NUM_JOINTS
    command.velocity = list(zeros)
    command.effort = list(zeros)
    command.kp_position = gains.p.tolist()
    command.ki_position = gains.i.tolist()
    command.kd_position = gains.d.tolist()
    command.kp_velocity = list(zeros)
    command.i_effort_min = (0.0 - gains.i_clamp).tolist()  # 0.0 - x: no -0.0 in the message
    command.i_effort_max = gains.i_clamp.tolist()
    return command


def play(waypoints: Sequence[Waypoint], message_type: Callable[[], object], path: str,
         name: str) -> None:
    """Play `waypoints` on the running node: wait for the simulator, then send the schedule."""
    gains = read_gains()
    cache = JointStateCache()
    rospy.Subscriber(JOINT_STATES_TOPIC, JointState, cache.callback, queue_size=1)
    mode: LatestMessage[String] = LatestMessage()
    rospy.Subscriber(topics.CURRENT_CONTROL_MODE, String, mode.callback, queue_size=1)
    publisher = rospy.Publisher(JOINT_COMMANDS_TOPIC, message_type, queue_size=1)
    joint_state_timeout_s = _timeout_param(JOINT_STATE_TIMEOUT_PARAM, JOINT_STATE_TIMEOUT_S)
    subscriber_timeout_s = _timeout_param(SUBSCRIBER_TIMEOUT_PARAM, SUBSCRIBER_TIMEOUT_S)
    first_state = wait_for_joint_state(cache, joint_state_timeout_s)
    wait_for_ros_time(joint_state_timeout_s)
    _wait_for_simulator(publisher, first_state, subscriber_timeout_s)
    warning = mode_warning(_current_mode(mode))
    if warning is not None:
        rospy.logwarn(warning)

    stalled: set[int] = set()  # connections not waited for (wait_until_handed_over)

    def send(positions: np.ndarray) -> None:
        if rospy.is_shutdown():  # on wall time rospy.sleep does not raise on Ctrl-C
            raise rospy.ROSInterruptException('shut down')
        # Waits for the previous command only now: rospy's writer threads had the whole
        # interval to take it, so the wait delays the schedule only when they were starved.
        wait_until_handed_over(publisher, HANDOVER_WAIT_S, stalled)
        publisher.publish(build_command(message_type, positions, gains, rospy.Time.now()))

    # How analyze_bag.py tells which trajectory a bag played: logged once the recorder reads
    # our /rosout (latched one message deep: a reader connecting later gets only the last).
    late_readers = wait_for_log_readers(_log_readers_connected, _log_readers_registered,
                                        subscriber_timeout_s)
    if late_readers:
        rospy.logwarn(f'not connected to {topics.ROSOUT} in time: '
                      f'{", ".join(sorted(late_readers))} may miss the trajectory line below')
    rospy.loginfo(trajectory_log_line(os.path.abspath(path), name))
    rospy.loginfo(playing_line(name, waypoints))
    run_trajectory(waypoints, cache.positions, send, _sleep, rospy.loginfo, rospy.get_time)
    wait_until_handed_over(publisher, HANDOVER_WAIT_S, stalled)  # the last, before shutdown
    rospy.loginfo(done_line(name))
    linger(EXIT_GRACE_S)


def linger(duration_s: float,
           shutting_down: Callable[[], bool] = rospy.core.is_shutdown_requested) -> None:
    """Stay up `duration_s` of wall time (EXIT_GRACE_S), less once shutdown is requested."""
    deadline = time.monotonic() + duration_s
    while not shutting_down() and (left_s := deadline - time.monotonic()) > 0.0:
        time.sleep(min(POLL_PERIOD_S, left_s))


def _sleep(duration_s: float) -> None:
    """rospy.sleep in sim time; sim time going back under it raises TimeWentBackError."""
    before_s = rospy.get_time()
    try:
        rospy.sleep(duration_s)
    except rospy.ROSTimeMovedBackwardsException:
        raise TimeWentBackError(before_s, rospy.get_time()) from None


def _wait_for_simulator(publisher: rospy.Publisher, first_state: JointState,
                        timeout_s: float) -> None:
    """wait_for_subscribers for our publisher; the simulator is the sender of `first_state`."""
    simulator = (getattr(first_state, '_connection_header', None) or {}).get('callerid')
    started = time.monotonic()
    missing = wait_for_subscribers(lambda: _connected_subscribers(publisher.impl),
                                   _registered_subscribers, simulator, timeout_s)
    connected = ', '.join(sorted(_connected_subscribers(publisher.impl)))
    rospy.loginfo(f'{JOINT_COMMANDS_TOPIC}: subscribers connected after '
                  f'{time.monotonic() - started:.2f} s: '
                  f'{connected} (simulator: {simulator or "unknown"})')
    if missing:
        rospy.logwarn(f'not connected to {JOINT_COMMANDS_TOPIC} in time, '
                      'so missing the first commands: ' + ', '.join(sorted(missing)))


def _current_mode(cache: LatestMessage[String]) -> str | None:
    """The simulator's mode (its latched /atlas/current_control_mode), waited for at most
    MODE_WAIT_S; None if it says nothing."""
    deadline = time.monotonic() + MODE_WAIT_S
    while (message := cache.latest()) is None:
        if rospy.is_shutdown():
            raise rospy.ROSInterruptException('shut down while waiting for the mode')
        if time.monotonic() >= deadline:
            return None
        time.sleep(POLL_PERIOD_S)
    return str(message.data)


def _timeout_param(name: str, default: float) -> float:
    value = rospy.get_param(name, default)
    seconds = finite_number(value)
    if seconds is None or seconds <= 0.0:
        raise TrajYamlError(f'parameter {name} must be a positive number of seconds, got {value!r}')
    return seconds


def _registered_subscribers(topic: str = JOINT_COMMANDS_TOPIC) -> set[str] | None:
    """The nodes the master lists as subscribers of `topic` (None: it cannot tell)."""
    try:
        _publishers, subscribers, _services = rosgraph.Master(rospy.get_name()).getSystemState()
    except Exception:  # noqa: BLE001 - an unreachable master is asked again at the next poll
        return None
    return next((set(nodes) for name, nodes in subscribers if name == topic), set())


def _log_readers_registered() -> set[str] | None:
    """The nodes the master lists as readers of /rosout, this node aside."""
    nodes = _registered_subscribers(topics.ROSOUT)
    return None if nodes is None else nodes - {rospy.get_name()}


def _log_readers_connected() -> set[str]:
    """The nodes connected to this node's /rosout publisher (rospy's own, made at init)."""
    return _connected_subscribers(rospy.topics.get_topic_manager().get_publisher_impl(
        topics.ROSOUT))


def _connections(impl: object | None) -> list[object]:
    """A snapshot of a publisher's subscriber connections, from its rospy implementation
    (`Publisher.impl`; none once it is closed)."""
    return list(impl.connections) if impl is not None else []


def _connected_subscribers(impl: object | None) -> set[str]:
    """The nodes connected to a publisher (rospy names each connection by its subscriber)."""
    return {connection.endpoint_id for connection in _connections(impl)}


class _MasterList:
    """The master's subscribers of a topic, asked at most every MASTER_POLL_PERIOD_S; its
    last answer is kept while it does not reply (None until it first does)."""

    def __init__(self, registered: Callable[[], set[str] | None]) -> None:
        self.registered = registered
        self.listed: set[str] | None = None
        self._next_poll_s = 0.0

    def latest(self) -> set[str] | None:
        if time.monotonic() >= self._next_poll_s:
            answer = self.registered()
            if answer is not None:
                self.listed = answer
            self._next_poll_s = time.monotonic() + MASTER_POLL_PERIOD_S
        return self.listed


def wait_for_subscribers(
    connected: Callable[[], set[str]],
    registered: Callable[[], set[str] | None],
    simulator: str | None,
    timeout_s: float,
    is_shutdown: Callable[[], bool] = rospy.is_shutdown,
) -> set[str]:
    """Wait (wall clock, bounded) until every subscriber of /atlas/joint_commands is connected.

    A command published before a subscriber connects never reaches it. For the simulator
    that is no lost sample: it holds its pose, then jumps to the first command that does
    arrive, and the robot can fall.

    Args:
        connected: the nodes connected to our publisher now.
        registered: the nodes the master lists as subscribers (None when it cannot tell).
        simulator: the node that published the first joint state, if known.
        timeout_s: the bound, s of wall clock.

    Returns:
        The listed subscribers that had not connected at the timeout (none of them the
        simulator; the caller warns about them); empty when every one is connected.

    Raises:
        TrajYamlError: at the timeout nothing is connected, or the simulator subscribes
            but has not connected: the trajectory would start without it.
        rospy.ROSInterruptException: the node was shut down while waiting.
    """
    deadline = time.monotonic() + timeout_s
    master = _MasterList(registered)
    while True:
        listed = master.latest()
        now_connected = connected()
        missing = (listed or set()) - now_connected
        if now_connected and listed is not None and not missing:
            return set()
        if is_shutdown():
            raise rospy.ROSInterruptException('shut down while waiting for subscribers')
        if time.monotonic() >= deadline:
            if not now_connected:
                raise TrajYamlError(
                    f'nothing subscribed to {JOINT_COMMANDS_TOPIC} within {timeout_s:g} s: '
                    f'the commands would reach no simulator; start it with `{LAUNCH_HINT}`')
            if simulator in missing:
                raise TrajYamlError(
                    f'the simulator {simulator} subscribes to {JOINT_COMMANDS_TOPIC} but did not '
                    f'connect within {timeout_s:g} s; it would miss the start of the trajectory '
                    f'(a busy host? raise {SUBSCRIBER_TIMEOUT_PARAM})')
            return missing
        time.sleep(POLL_PERIOD_S)


def wait_for_log_readers(
    connected: Callable[[], set[str]],
    registered: Callable[[], set[str] | None],
    timeout_s: float,
    is_shutdown: Callable[[], bool] = rospy.is_shutdown,
) -> set[str]:
    """Wait (wall clock, bounded) until every reader of /rosout (rosout, a recorder) is
    connected to this node's /rosout publisher; return those that were not in time.

    rospy latches /rosout one message deep: a reader that connects after two lines gets
    only the second. The master tells a reader of a new publisher at once, but the reader
    connects when it gets the CPU (the recorder runs niced), seconds later on a busy host.

    Raises:
        rospy.ROSInterruptException: the node was shut down while waiting.
    """
    deadline = time.monotonic() + timeout_s
    master = _MasterList(registered)
    while True:
        listed = master.latest()
        missing = (listed or set()) - connected()
        if listed is not None and not missing:
            return set()
        if is_shutdown():
            raise rospy.ROSInterruptException('shut down while waiting for /rosout readers')
        if time.monotonic() >= deadline:
            return missing
        time.sleep(POLL_PERIOD_S)


def wait_until_handed_over(publisher: rospy.Publisher, timeout_s: float,
                           stalled: set[int] | None = None) -> bool:
    """Wait (bounded, wall clock) until rospy has taken the last message off its queues.

    With the tutorial's ``queue_size=1``, rospy 1.15 hands each message to one writer
    thread per subscriber (``QueuedConnection``) and drops a message still queued when the
    next is published; on a busy host the writer thread can be starved for longer than the
    20 ms between commands. Waiting here keeps every command while the publisher keeps the
    tutorial's queue size.

    `stalled` (ids of connections, kept by the caller across calls): a connection still
    queued when a wait times out is added, and later waits skip it until its queue empties
    (a subscriber that stopped reading would otherwise delay every command).
    Returns whether every queue but the stalled ones emptied within `timeout_s`.
    """
    skipped = stalled if stalled is not None else set()
    deadline = time.monotonic() + timeout_s
    while True:
        queued = {id(connection) for connection in _connections(publisher.impl)
                  if getattr(connection, '_queue', None)}
        skipped.intersection_update(queued)  # one that caught up is waited for again
        if not queued - skipped:
            return True
        if time.monotonic() >= deadline:
            skipped.update(queued)
            return False
        time.sleep(HANDOVER_POLL_S)


def joint_commands_type() -> Callable[[], object]:
    """osrf_msgs/JointCommands, from the built workspace."""
    try:
        from osrf_msgs.msg import JointCommands  # noqa: PLC0415 - unbuilt workspace: one line
    except ImportError as err:
        raise TrajYamlError(
            f'cannot import osrf_msgs.msg.JointCommands ({err}): '
            'build the workspace with `make setup` and `source ./env.sh`'
        ) from err
    return JointCommands


def require_master() -> None:
    """Refuse to start without a ROS master (rospy would wait for one forever)."""
    try:
        uri = rosgraph.get_master_uri()
    except ValueError as err:
        raise TrajYamlError(f'bad ROS master setting: {err}') from err
    if not rosgraph.is_master_online(uri):
        raise TrajYamlError(f'no ROS master at {uri}: start the simulator with `{LAUNCH_HINT}`')
