#!/usr/bin/env python3
"""The gazebo_tutorials Atlas walking tutorial's client over ROS, as test/support's
walking_tutorial describes it: `static N` streams a STEP on every
/atlas/atlas_sim_interface_state until N static steps are down, `dynamic N` a WALK window
until N steps are walked. It prints one JSON line: the steps taken, each static landing's
distance (m) and turn (rad) from its pose, the lowest pelvis (m) and whether the robot fell
(ERROR_FALLING, or the pelvis below 0.6 m). Exit 0 when it took its N steps, 1 otherwise.

test_drc_tutorial_clients.py runs it against atlas.launch.
"""

from __future__ import annotations

import json
import math
import sys
import threading
from pathlib import Path

import numpy as np
import rospy
from atlas_msgs.msg import (
    AtlasBehaviorStepData,
    AtlasSimInterfaceCommand,
    AtlasSimInterfaceState,
)

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from support.walking_tutorial import (
    DynamicCircleClient,
    StaticCircleClient,
    landing_errors,
)
from tutorial_atlas_control.asi import Behavior, Status
from tutorial_atlas_control.msgs.atlas_sim_interface import StepData

FALLEN_PELVIS_M = 0.6
STEPPING = 2
TIMEOUT_S = 600.0


def step_message(step: StepData) -> AtlasBehaviorStepData:
    message = AtlasBehaviorStepData()
    message.step_index, message.foot_index = step.step_index, step.foot_index
    message.duration, message.swing_height = step.duration_s, step.swing_height_m
    message.pose.position.x, message.pose.position.y, message.pose.position.z = step.position_m
    orientation = message.pose.orientation
    orientation.x, orientation.y, orientation.z, orientation.w = step.orientation_xyzw
    return message


class TutorialClient:
    def __init__(self, mode: str, steps: int) -> None:
        self.mode, self.steps = mode, steps
        self.static = StaticCircleClient()
        self.dynamic = DynamicCircleClient()
        self.taken = 0
        self.landings: list[tuple[float, float]] = []
        self.lowest_pelvis_m = math.inf
        self.fell = False
        self.done = threading.Event()
        self._previous_flags = 0
        self.publisher = rospy.Publisher('/atlas/atlas_sim_interface_command',
                                         AtlasSimInterfaceCommand, queue_size=10)

    def on_state(self, state: AtlasSimInterfaceState) -> None:
        if self.done.is_set():
            return
        pelvis = (state.pos_est.position.x, state.pos_est.position.y)
        self.lowest_pelvis_m = min(self.lowest_pelvis_m, state.pos_est.position.z)
        if state.behavior_feedback.status_flags == Status.ERROR_FALLING \
                or state.pos_est.position.z < FALLEN_PELVIS_M:
            self.fell = True
            self.done.set()
            return
        command = AtlasSimInterfaceCommand()
        command.header.stamp = rospy.Time.now()
        if self.mode == 'static':
            flags = state.step_feedback.status_flags
            command.behavior = Behavior.STEP
            command.step_params.desired_step = step_message(
                self.static.desired_step(pelvis, flags))
            if self._previous_flags == STEPPING and flags != STEPPING:
                feet = np.array([[f.position.x, f.position.y, f.position.z, f.orientation.x,
                                  f.orientation.y, f.orientation.z, f.orientation.w]
                                 for f in state.foot_pos_est])
                assert self.static.origin_xy is not None
                self.landings.append(landing_errors(feet, self.static.counter - 2,
                                                    self.static.origin_xy))
                self.taken = len(self.landings)
            self._previous_flags = flags
        else:
            command.behavior = Behavior.WALK
            queue = self.dynamic.step_queue(pelvis, state.walk_feedback.next_step_index_needed)
            for slot, step in enumerate(queue):
                command.walk_params.step_queue[slot] = step_message(step)
            self.taken = max(self.taken, state.walk_feedback.current_step_index)
        if self.taken >= self.steps:
            self.done.set()
            return
        self.publisher.publish(command)


def main() -> int:
    mode, steps = sys.argv[1], int(sys.argv[2])
    rospy.init_node('walking_tutorial_client', anonymous=True)
    client = TutorialClient(mode, steps)
    rospy.Subscriber('/atlas/atlas_sim_interface_state', AtlasSimInterfaceState,
                     client.on_state, queue_size=1)
    client.done.wait(TIMEOUT_S)
    print(json.dumps({'mode': mode, 'taken': client.taken, 'landings': client.landings,
                      'lowest_pelvis_m': client.lowest_pelvis_m, 'fell': client.fell}))
    return 0 if client.taken >= steps and not client.fell else 1


if __name__ == '__main__':
    sys.exit(main())
