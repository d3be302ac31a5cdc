"""DRCSim's animate-joints tutorial's trajectory, for the tests, and its client in Python 3.

The tutorial's client published one trajectory_msgs/JointTrajectory on /joint_trajectory:
header.frame_id atlas::pelvis, the 28 joints as atlas:: names in its own order, 1500 points
each with time_from_start 0.01 s, each joint on one of two ±0.5 rad sines (many past their
joint's limits). `python3 -m support.joint_animation` (from test/, after `source env.sh`)
publishes it once, stamped now, as that client did (once the simulator has subscribed, which
the tutorial left to chance), then spins until interrupted.
"""

from __future__ import annotations

import math

import numpy as np

#: The tutorial's joint order (legs listed outside in, arms alphabetically), not DRCSim's.
TUTORIAL_ORDER = (
    'back_lbz', 'back_mby', 'back_ubx', 'neck_ay',
    'l_leg_uhz', 'l_leg_mhx', 'l_leg_lhy', 'l_leg_kny', 'l_leg_uay', 'l_leg_lax',
    'r_leg_lax', 'r_leg_uay', 'r_leg_kny', 'r_leg_lhy', 'r_leg_mhx', 'r_leg_uhz',
    'l_arm_elx', 'l_arm_ely', 'l_arm_mwx', 'l_arm_shx', 'l_arm_usy', 'l_arm_uwy',
    'r_arm_elx', 'r_arm_ely', 'r_arm_mwx', 'r_arm_shx', 'r_arm_usy', 'r_arm_uwy',
)
FRAME_ID = 'atlas::pelvis'
TUTORIAL_POINTS = 1500
TUTORIAL_DT_NS = 10_000_000
SINE_AMPLITUDE_RAD = 0.5
SINE_HZ = 0.05
#: The node the trajectory is for, and the guard (s of ROS time) for its connection.
SIMULATOR = '/atlas_sim'
SUBSCRIBER_TIMEOUT_S = 60.0


def tutorial_sines(t_s: np.ndarray) -> np.ndarray:
    """Each of TUTORIAL_ORDER's joints (columns) at times `t_s` (rows), before clamping:
    the slow sine on even columns, the fast one, negated, on odd ones."""
    theta = 2.0 * math.pi * SINE_HZ * t_s
    slow, fast = SINE_AMPLITUDE_RAD * np.sin(theta), -SINE_AMPLITUDE_RAD * np.sin(2.0 * theta)
    return np.stack([fast if column % 2 else slow for column in range(len(TUTORIAL_ORDER))],
                    axis=1)


def tutorial_positions() -> np.ndarray:
    """The points' positions (rad), (TUTORIAL_POINTS, 28), as sent."""
    return tutorial_sines(np.arange(TUTORIAL_POINTS) * TUTORIAL_DT_NS / 1e9)


def main() -> None:
    """Publish the tutorial's trajectory once, when the simulator has subscribed; spin."""
    import genpy
    import rospy
    from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

    rospy.init_node('joint_control', anonymous=True)
    publisher = rospy.Publisher('/joint_trajectory', JointTrajectory, queue_size=1)
    deadline = rospy.get_rostime().to_sec() + SUBSCRIBER_TIMEOUT_S
    # the simulator's connection itself: the recorder subscribes too, and may connect first
    while SIMULATOR not in {connection.endpoint_id for connection in publisher.impl.connections}:
        if rospy.is_shutdown() or rospy.get_rostime().to_sec() > deadline:
            raise SystemExit(f'joint_animation: {SIMULATOR} did not connect to /joint_trajectory')
        rospy.sleep(0.1)
    msg = JointTrajectory(joint_names=['atlas::' + name for name in TUTORIAL_ORDER])
    msg.header.stamp, msg.header.frame_id = rospy.Time.now(), FRAME_ID
    msg.points = [JointTrajectoryPoint(positions=list(row),
                                       time_from_start=genpy.Duration(0, TUTORIAL_DT_NS))
                  for row in tutorial_positions()]
    publisher.publish(msg)
    print(f'published {len(msg.points)} points at t={msg.header.stamp.to_sec():.3f} s',
          flush=True)
    rospy.spin()  # as the tutorial's client: until interrupted


if __name__ == '__main__':
    main()
