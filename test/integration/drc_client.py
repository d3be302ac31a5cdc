#!/usr/bin/env python
"""A DRC-era Python client in miniature, as DRCSim's tutorials wrote them: `#!/usr/bin/env
python`, roslib.load_manifest of its own package, tf.transformations' Euler angles,
tf_conversions.posemath with PyKDL, and actionlib.

test_drc_clients.py copies it into a throw-away package (drc_client_probe) and runs it with
rosrun and directly; each line it prints is checked. It needs no master.
"""

import roslib

roslib.load_manifest('drc_client_probe')

import math  # noqa: E402 - the DRC-era order: load_manifest first, then the imports
import sys  # noqa: E402

import actionlib  # noqa: E402
import PyKDL  # noqa: E402
import rospy  # noqa: E402
from geometry_msgs.msg import Pose  # noqa: E402
from tf.transformations import euler_from_quaternion, quaternion_from_euler  # noqa: E402
from tf_conversions import posemath  # noqa: E402


def main() -> None:
    # A quarter turn in yaw, as walk.py computed its step orientations.
    quat = quaternion_from_euler(0.0, 0.0, math.pi / 2)
    print('quaternion_from_euler(0, 0, pi/2):', ' '.join(f'{v:.6f}' for v in quat))
    print('euler_from_quaternion:', ' '.join(f'{v:.6f}' for v in euler_from_quaternion(quat)))
    # A foot 0.25 m ahead in the robot's frame, the robot at (1, 2, 0) turned by that quarter
    # turn: in the world, 0.25 m along y (demo.py's posemath and PyKDL frames).
    foot = Pose()
    foot.position.x, foot.orientation.w = 0.25, 1.0
    robot = PyKDL.Frame(PyKDL.Rotation.Quaternion(*quat), PyKDL.Vector(1.0, 2.0, 0.0))
    world = posemath.toMsg(robot * posemath.fromMsg(foot)).position
    print(f'posemath foot in world: {world.x:.6f} {world.y:.6f} {world.z:.6f}')
    print('actionlib:', actionlib.SimpleActionClient.__name__, 'rospy:', rospy.get_name())
    print(f'python {sys.version_info[0]}.{sys.version_info[1]} at {sys.executable}')


if __name__ == '__main__':
    main()
