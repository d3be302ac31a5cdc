"""Command line of bdi_control.py: DRCSim's actionlib front end to the AtlasSimInterface.

The action server atlas/bdi_control (atlas_msgs/WalkDemo) of DRCSim 2.7's
actionlib_server.cpp, in rospy, its decisions in asi/walk_demo.py: WALK goals of
ego-centric steps (turned into world poses by pos_est and the IMU's yaw) streamed to the
simulator as the walk needs them, then STAND; STEP, STAND and STAND_PREP goals. Started by
`atlas.launch bdi_control:=true`; it publishes /atlas/atlas_sim_interface_command and
listens to /atlas/atlas_sim_interface_state and /atlas/atlas_state. Options: -h/--help;
ROS remapping arguments (name:=value) are accepted.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Sequence

import actionlib
import rosgraph
import rospy
from atlas_msgs.msg import (
    AtlasSimInterfaceCommand,
    AtlasSimInterfaceState,
    AtlasState,
    WalkDemoAction,
    WalkDemoResult,
)

from tutorial_atlas_control import topics
from tutorial_atlas_control.asi import Decision, WalkDemoServer
from tutorial_atlas_control.cli.convention import (
    EXIT_INTERRUPTED,
    EXIT_REFUSED,
    node_arguments,
    print_error,
)

PROG = 'bdi_control.py'
NODE_NAME = 'atlas_bdi_control'
ACTION = 'atlas/bdi_control'
#: How long (s, wall) the server waits for the simulator to connect to its commands before it
#: takes goals: a goal's first command published before that connection is lost, and the goal
#: then waits for ever for a state that says what came of it.
SIMULATOR_WAIT_S = 60.0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of scripts/bdi_control.py (`argv` with the program name first)."""
    argv = list(sys.argv if argv is None else argv)
    refused = node_arguments(PROG, __doc__, rospy.myargv(argv)[1:])
    if refused is not None:
        return refused
    try:
        return _serve(argv)
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED


def _serve(argv: list[str]) -> int:
    uri = rosgraph.get_master_uri()
    if not rosgraph.is_master_online(uri):
        print_error(PROG, f'no ROS master at {uri}: start the simulator first')
        return EXIT_REFUSED
    rospy.init_node(NODE_NAME, argv=argv)
    server = WalkDemoServer(AtlasSimInterfaceCommand)
    lock = threading.Lock()
    commands = rospy.Publisher(topics.ASI_COMMAND, AtlasSimInterfaceCommand, queue_size=1,
                               tcp_nodelay=True)
    action = actionlib.SimpleActionServer(ACTION, WalkDemoAction, auto_start=False)

    def carry_out(decision: Decision) -> None:
        for command in decision.commands:
            commands.publish(command)
        if decision.succeeded or decision.aborted is not None:
            result = WalkDemoResult(success=decision.succeeded)
            if decision.end_state is not None:
                result.end_state = decision.end_state
            if decision.succeeded:
                rospy.loginfo(f'{ACTION}: goal succeeded')
                action.set_succeeded(result)
            else:
                rospy.loginfo(f'{ACTION}: aborting the goal: {decision.aborted}')
                action.set_aborted(result, text=decision.aborted or '')

    def on_goal() -> None:
        with lock:
            goal = action.accept_new_goal()
            rospy.loginfo(f'{ACTION}: new goal, behavior {goal.behavior}')
            carry_out(server.accept(goal))

    def on_preempt() -> None:
        with lock:
            server.preempted()
            action.set_preempted()

    def on_state(state: AtlasSimInterfaceState) -> None:
        with lock:
            carry_out(server.on_state(state))

    def on_atlas_state(state: AtlasState) -> None:
        o = state.orientation
        with lock:
            server.on_imu(o.x, o.y, o.z, o.w)

    action.register_goal_callback(on_goal)
    action.register_preempt_callback(on_preempt)
    rospy.Subscriber(topics.ATLAS_STATE, AtlasState, on_atlas_state, queue_size=1)
    rospy.Subscriber(topics.ASI_STATE, AtlasSimInterfaceState, on_state, queue_size=1)
    _wait_for_simulator(commands)
    action.start()
    rospy.loginfo(f'{ACTION}: ready (DRCSim\'s actionlib server, in Python)')
    rospy.spin()
    return 0


def _wait_for_simulator(commands: rospy.Publisher) -> None:
    """Until the simulator subscribes to `commands` (at most SIMULATOR_WAIT_S of wall time):
    a goal's first command published before that is lost."""
    deadline = time.monotonic() + SIMULATOR_WAIT_S
    while commands.get_num_connections() == 0 and not rospy.is_shutdown():
        if time.monotonic() > deadline:
            rospy.logwarn(f'{ACTION}: nothing subscribes to {topics.ASI_COMMAND} after '
                          f'{SIMULATOR_WAIT_S:.0f} s; taking goals all the same')
            return
        time.sleep(0.01)
