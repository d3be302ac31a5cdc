"""A walking client's link to the AtlasSimInterface: what walk_client.py and vrc_walker.py share.

Connecting (a master, the first state, the simulator subscribed to the commands), STAND
from the start's hold, and streamed walks: every /atlas/atlas_sim_interface_state answered
by the current walk's WalkClient (asi/walk_client.py), until the walk has ended, the states
stop coming for STATE_SILENCE_S or a wall-clock bound passes.
"""

from __future__ import annotations

import math
import threading
import time

import rosgraph
import rospy
from atlas_msgs.msg import (
    AtlasBehaviorStepData,
    AtlasSimInterfaceCommand,
    AtlasSimInterfaceState,
)

from tutorial_atlas_control import topics
from tutorial_atlas_control.asi import Behavior, WalkClient, refusal_hint, yaw_of_quaternion
from tutorial_atlas_control.walking import Footstep, feet_origin

__all__ = ['CONNECT_TIMEOUT_S', 'STATE_SILENCE_S', 'AsiLink', 'Refused', 'step_message',
           'walk_command']

#: How long (s, wall time) to wait for the first state, and for the simulator to subscribe.
CONNECT_TIMEOUT_S = 30.0
#: How long (s, wall time) to wait for the other subscribers the master lists (a recorder).
LISTED_CONNECT_TIMEOUT_S = 2.0
#: A walk is given up when no state came for this long (s, wall time): the simulator
#: stopped, died or was paused.
STATE_SILENCE_S = 2.0
#: How long (s, wall time) the STAND sent from the start's hold may take to be reported.
STAND_TIMEOUT_S = 10.0


class Refused(Exception):
    """No master, no simulator, or a walk that did not end well."""


class AsiLink:
    """One client node's commands and states: `connect`, then `stand_first` if the state
    says User, then `walk` as often as needed."""

    def __init__(self, prog: str) -> None:
        self.prog = prog
        self.last: AtlasSimInterfaceState | None = None
        self._client: WalkClient | None = None
        self._ended = threading.Event()
        self._ended.set()
        self._heard = time.monotonic()
        self._publisher: rospy.Publisher | None = None

    def connect(self, node_name: str) -> AtlasSimInterfaceState:
        """The node started, the first state read, the simulator (and for a while every other
        listed subscriber: a recorder gets the first steps too) subscribed to the commands."""
        uri = rosgraph.get_master_uri()
        if not rosgraph.is_master_online(uri):
            raise Refused(f'no ROS master at {uri}: start the simulator first')
        rospy.init_node(node_name, anonymous=True, disable_signals=True)
        try:
            self.last = rospy.wait_for_message(topics.ASI_STATE, AtlasSimInterfaceState,
                                               timeout=CONNECT_TIMEOUT_S)
        except rospy.ROSException:
            raise Refused(f'no {topics.ASI_STATE} within {CONNECT_TIMEOUT_S:.0f} s: is the '
                          'simulator running?') from None
        self._publisher = rospy.Publisher(topics.ASI_COMMAND, AtlasSimInterfaceCommand,
                                          queue_size=1, tcp_nodelay=True)
        self._wait_for_subscribers()
        rospy.Subscriber(topics.ASI_STATE, AtlasSimInterfaceState, self._on_heard,
                         queue_size=1, tcp_nodelay=True)
        return self.last

    def feet(self) -> tuple[tuple[float, float], float]:
        """The last state's feet (foot_pos_est): their midpoint and mean heading."""
        assert self.last is not None  # connected
        left, right = ((foot.position.x, foot.position.y,
                        yaw_of_quaternion(foot.orientation.x, foot.orientation.y,
                                          foot.orientation.z, foot.orientation.w))
                       for foot in self.last.foot_pos_est)
        return feet_origin(left, right)

    def stand_first(self, planned: int | None = None) -> None:
        """The start's hold (User): STAND, then wait until the state says Stand; a refusal
        says that none of the `planned` steps (None: no plan yet) were taken."""
        assert self._publisher is not None  # connected
        print(f'{self.prog}: the robot is in User (the tutorial\'s hold): sending STAND first',
              flush=True)
        command = AtlasSimInterfaceCommand()
        command.header.stamp = rospy.Time.now()
        command.behavior = Behavior.STAND
        self._publisher.publish(command)
        deadline = time.monotonic() + STAND_TIMEOUT_S
        while self.last is None or self.last.current_behavior != Behavior.STAND:
            if time.monotonic() > deadline:
                state = self.last
                hint = '' if state is None else refusal_hint(
                    state.behavior_feedback.status_flags, state.current_behavior)
                taken = '' if planned is None else f'; 0 of {planned} steps taken'
                raise Refused(f'STAND was not taken within {STAND_TIMEOUT_S:g} s '
                              f'({hint}){taken}')
            if time.monotonic() - self._heard > STATE_SILENCE_S:
                raise Refused(f'no {topics.ASI_STATE} after STAND: is the simulator running?')
            time.sleep(0.01)

    def hold(self, sim_s: float) -> None:
        """Until the states' stamps are `sim_s` (s of sim time) past the last one's;
        Refused when they stop for STATE_SILENCE_S."""
        assert self.last is not None  # connected
        until = self.last.header.stamp.to_sec() + sim_s
        while self.last.header.stamp.to_sec() < until:
            if time.monotonic() - self._heard > STATE_SILENCE_S:
                raise Refused(f'no {topics.ASI_STATE} for {STATE_SILENCE_S:g} s: the '
                              'simulator stopped or is paused')
            time.sleep(0.01)

    def walk(self, client: WalkClient, timeout_s: float) -> None:
        """Stream `client`'s walk until it ends; Refused when the states stop for
        STATE_SILENCE_S or at `timeout_s` (wall time)."""
        self._heard = time.monotonic()
        self._client = client
        self._ended.clear()
        planned = len(client.plan)
        deadline = time.monotonic() + timeout_s
        try:
            while not self._ended.wait(0.05):
                now = time.monotonic()
                if now - self._heard > STATE_SILENCE_S:
                    raise Refused(f'no {topics.ASI_STATE} for {STATE_SILENCE_S:g} s: the '
                                  'simulator stopped or is paused '
                                  f'({client.steps_taken} of {planned} steps taken)')
                if now > deadline:
                    raise Refused(f'the walk did not end within {timeout_s:g} s '
                                  f'({client.steps_taken} of {planned} steps taken)')
        finally:
            self._ended.set()  # however it ended, the state callback sends nothing more

    def close(self, reason: str) -> None:
        """The node shut down (its topics closed) for `reason`."""
        rospy.signal_shutdown(reason)

    def _on_heard(self, state: AtlasSimInterfaceState) -> None:
        self._heard = time.monotonic()
        self.last = state
        client = self._client
        if self._ended.is_set() or client is None:  # between walks: nothing to answer
            return
        steps = client.on_state(state.current_behavior, state.behavior_feedback.status_flags,
                                state.walk_feedback.current_step_index,
                                state.walk_feedback.next_step_index_needed)
        if client.outcome is not None:
            self._ended.set()
        elif steps is not None:
            self._send(walk_command(steps))

    def _send(self, command: AtlasSimInterfaceCommand) -> None:
        """Publish from the state callback; a state read just as the client stopped (rospy
        closing its topics on the way out) sends nothing and says nothing."""
        assert self._publisher is not None  # connected
        try:
            self._publisher.publish(command)
        except rospy.ROSException:
            if not self._ended.is_set():
                raise

    def _wait_for_subscribers(self) -> None:
        publisher = self._publisher
        assert publisher is not None  # connected
        deadline = time.monotonic() + CONNECT_TIMEOUT_S
        while publisher.get_num_connections() == 0:
            if time.monotonic() > deadline or rospy.is_shutdown():
                raise Refused(f'the simulator did not subscribe to {topics.ASI_COMMAND}')
            time.sleep(0.01)
        deadline = time.monotonic() + LISTED_CONNECT_TIMEOUT_S
        while publisher.get_num_connections() < _listed_subscribers(topics.ASI_COMMAND) \
                and time.monotonic() < deadline and not rospy.is_shutdown():
            time.sleep(0.01)


def _listed_subscribers(topic: str) -> int:
    """How many nodes the master lists as subscribers of `topic` (0 if it cannot say)."""
    try:
        _, subscribers, _ = rosgraph.Master(rospy.get_name()).getSystemState()
    except (rosgraph.MasterException, OSError):
        return 0
    return next((len(nodes) for name, nodes in subscribers if name == topic), 0)


def step_message(step: Footstep) -> AtlasBehaviorStepData:
    """A footstep as atlas_msgs/AtlasBehaviorStepData (x, y, yaw; z and swing height 0)."""
    data = AtlasBehaviorStepData(step_index=step.step_index, foot_index=step.foot_index,
                                 duration=step.duration_s)
    data.pose.position.x, data.pose.position.y = step.x_m, step.y_m
    half = 0.5 * step.yaw_rad
    data.pose.orientation.z, data.pose.orientation.w = math.sin(half), math.cos(half)
    return data


def walk_command(steps: list[Footstep]) -> AtlasSimInterfaceCommand:
    """An AtlasSimInterfaceCommand WALK of `steps` (empty slots after them)."""
    command = AtlasSimInterfaceCommand()
    command.behavior = command.WALK
    for slot, step in enumerate(steps[:len(command.walk_params.step_queue)]):
        command.walk_params.step_queue[slot] = step_message(step)
    return command
