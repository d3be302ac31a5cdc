"""Send DRCSim's actionlib server (atlas/bdi_control) one WALK goal of N ego-centric steps of
STRIDE m (the last beside the one before, the feet 0.24 m apart), as its keyboard teleop did,
and print one JSON line: the pelvis's x, y when sent, the goal's final status and result,
and where the feet ended. Usage: walk_demo_goal.py N STRIDE"""

from __future__ import annotations

import json
import sys

import actionlib
import rospy
from actionlib_msgs.msg import GoalStatus
from atlas_msgs.msg import (
    AtlasBehaviorStepData,
    AtlasSimInterfaceState,
    WalkDemoAction,
    WalkDemoGoal,
)

HALF_WIDTH_M = 0.12


def main() -> int:
    count, stride_m = int(sys.argv[1]), float(sys.argv[2])
    rospy.init_node('walk_demo_goal', anonymous=True)
    client = actionlib.SimpleActionClient('atlas/bdi_control', WalkDemoAction)
    if not client.wait_for_server(rospy.Duration(60.0)):
        print('no atlas/bdi_control server', file=sys.stderr)
        return 1
    start = rospy.wait_for_message('/atlas/atlas_sim_interface_state', AtlasSimInterfaceState,
                                   timeout=30.0).pos_est.position
    goal = WalkDemoGoal(behavior=WalkDemoGoal.WALK)
    for k in range(1, count + 1):
        step = AtlasBehaviorStepData(step_index=k, foot_index=(k + 1) % 2, duration=0.63)
        step.pose.position.x = stride_m * (k if k < count else k - 1)
        step.pose.position.y = HALF_WIDTH_M if k % 2 else -HALF_WIDTH_M
        step.pose.orientation.w = 1.0
        goal.steps.append(step)
    client.send_goal(goal)
    client.wait_for_result(rospy.Duration(90.0))
    result = client.get_result()
    print(json.dumps({
        'start': [start.x, start.y],
        'succeeded': client.get_state() == GoalStatus.SUCCEEDED,
        'success': bool(result and result.success),
        'feet': [[f.position.x, f.position.y] for f in result.end_state.foot_pos_est]
        if result else None}))
    return 0


if __name__ == '__main__':
    sys.exit(main())
