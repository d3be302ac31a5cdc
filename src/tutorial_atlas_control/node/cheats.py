"""The simulator node's subscriptions to VRCPlugin's, gazebo_ros_force's and
gazebo_ros_joint_trajectory's topics (DRCSim's "cheats"): each message is checked whole
here (sim/vrc.py), then handed to the stepping loop, which applies it between two steps."""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

import rospy
from geometry_msgs.msg import Pose, Twist, Wrench
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from trajectory_msgs.msg import JointTrajectory

from tutorial_atlas_control import topics
from tutorial_atlas_control.sim import (
    AtlasSimulator,
    InputError,
    ModeInput,
    SimInput,
    TrajectoryMessage,
    cmd_vel_input,
    input_notes,
    parse_vrc_mode,
    pose_input,
    trajectory_input,
    wrench_input,
)

__all__ = ['WARN_THROTTLE_S', 'subscribe_cheats']

#: Seconds between repeats of the same refusal warning.
WARN_THROTTLE_S = 2.0


def subscribe_cheats(sim: AtlasSimulator, apply: Callable[[SimInput], None]) -> None:
    """Subscribe to each cheat topic; a checked input goes to `apply` (the loop's)."""
    lower, upper = sim.atlas.lower_rad, sim.atlas.upper_rad
    links = frozenset(sim.vrc.link_names)
    cheats: tuple[tuple[str, type, Callable[[Any], SimInput]], ...] = (
        (topics.MODE, String, lambda msg: ModeInput(parse_vrc_mode(msg.data))),
        (topics.SET_POSE, Pose, lambda msg: pose_input(
            (msg.position.x, msg.position.y, msg.position.z),
            (msg.orientation.x, msg.orientation.y, msg.orientation.z, msg.orientation.w))),
        (topics.CMD_VEL, Twist, lambda msg: cmd_vel_input(
            (msg.linear.x, msg.linear.y, msg.linear.z),
            (msg.angular.x, msg.angular.y, msg.angular.z))),
        (topics.APPLY_PELVIS_FORCE, Wrench, lambda msg: wrench_input(
            (msg.force.x, msg.force.y, msg.force.z),
            (msg.torque.x, msg.torque.y, msg.torque.z))),
        (topics.JOINT_TRAJECTORY, JointTrajectory, lambda msg: trajectory_input(
            TrajectoryMessage.from_ros(msg), lower, upper, links)),
    )
    for topic, msg_class, decode in cheats:
        rospy.Subscriber(topic, msg_class, _cheat_handler(topic, decode, apply),
                         queue_size=100)
    rospy.Subscriber(topics.CONFIGURATION, JointState, on_configuration, queue_size=10)


def _cheat_handler(topic: str, decode: Callable[[Any], SimInput],
                   apply: Callable[[SimInput], None]) -> Callable[[Any], None]:
    """A callback that checks the message whole, then hands it to `apply`."""
    def handle(msg: Any) -> None:
        try:
            item = decode(msg)
        except InputError as err:
            # Per message text: rospy's plain throttle is per call site, and would
            # hide a refusal on one topic behind another's.
            rospy.logwarn_throttle_identical(WARN_THROTTLE_S,
                                             f'refused {topic}: {err}; nothing applied')
            return
        for note in input_notes(item):  # what the check changed, once per message
            log = rospy.logwarn if note.level >= logging.WARNING else rospy.loginfo
            log(f'{topic}: {note.text}')
        apply(item)
    return handle


def on_configuration(_msg: JointState) -> None:
    """As VRCPlugin: planned but never implemented; said once per message."""
    rospy.logerr_throttle(WARN_THROTTLE_S, f'{topics.CONFIGURATION} is not implemented '
                          '(nor was it in DRCSim); nothing applied')
