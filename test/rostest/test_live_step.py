#!/usr/bin/env python3
"""rostest: trajectories/Stepping.yaml's step_and_stand, live, with the real traj_yaml.py.

atlas.launch with config/stepping_gains.yaml, User mode, then traj_yaml.py, as Stepping.yaml's
header says. The checks are the step's goals: the right foot lifts, lands at least 0.15 m further
forward, and the robot stands the 5 s after with the pelvis above 0.8 m. The feet are placed
by forward kinematics from /ground_truth_odom and the joint states of the same stamp.
"""

from __future__ import annotations

import subprocess
import unittest
from pathlib import Path

import mujoco
import numpy as np
import rospy
import rostest
from nav_msgs.msg import Odometry
from osrf_msgs.msg import JointCommands
from sim_probe import SimProbe  # beside this script, on its sys.path

from tutorial_atlas_control.sim import model as atlas_model

PKG = 'tutorial_atlas_control'
TRAJECTORY_FILE = Path(__file__).resolve().parents[2] / 'trajectories' / 'Stepping.yaml'
#: The issue's goals.
FORWARD_M = 0.15
STAND_S = 5.0
PELVIS_ABOVE_M = 0.8
#: Lifted, not slid: the foot's highest point above where it stood (m).
LIFTED_M = 0.03
#: Put down: the foot's height at the end against where it started (m; it may rest on an
#: edge, 7-9 mm up offline), and the force through its ankle (standing: about 425 N a foot;
#: the lifted foot's own weight: 16 N).
DOWN_WITHIN_M = 0.02
BEARING_N = 150.0
#: Sim time after start before switching to User (the torso is pinned for 1 s).
UNPIN_WAIT_S = 1.5
#: The port's command period (s): the trajectory ends one period after its last command.
COMMAND_PERIOD_S = 0.02


class Poses:
    """Pelvis poses by stamp (ns), and the commands' stamps, as they arrive."""

    def __init__(self) -> None:
        self.odom: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        self.command_ns: list[int] = []
        rospy.Subscriber('/ground_truth_odom', Odometry, self._on_odom, queue_size=1000)
        rospy.Subscriber('/atlas/joint_commands', JointCommands, self._on_command,
                         queue_size=500)

    def _on_odom(self, msg: Odometry) -> None:
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        self.odom[msg.header.stamp.to_nsec()] = (np.array([p.x, p.y, p.z]),
                                                 np.array([q.w, q.x, q.y, q.z]))

    def _on_command(self, msg: JointCommands) -> None:
        self.command_ns.append(msg.header.stamp.to_nsec())


class LiveStepTest(unittest.TestCase):
    def setUp(self) -> None:
        rospy.init_node('test_live_step', anonymous=True)
        self.trajectory = rospy.get_param('~trajectory', 'step_and_stand')
        self.probe = SimProbe(keep_joint_states=True)
        self.poses = Poses()
        self.probe.wait_ready()
        self.probe.wait_sim(UNPIN_WAIT_S)
        self.atlas = atlas_model.load_model()
        self.data = mujoco.MjData(self.atlas.model)

    def feet(self, start_ns: int, end_ns: int) -> list[tuple[int, float, np.ndarray]]:
        """(stamp, pelvis height, right foot position) at each odometry stamp in the window
        that has a joint state of the same stamp."""
        foot = self.atlas.model.body('r_foot').id
        with self.probe.lock:
            states = {m.header.stamp.to_nsec(): m.position for m in self.probe.joint_states}
        rows = []
        for t_ns, (position, quat) in sorted(list(self.poses.odom.items())):
            if start_ns <= t_ns <= end_ns and t_ns in states:
                rows.append((t_ns, float(position[2]), atlas_model.body_position_in_pose(
                    self.atlas, self.data, foot, position, quat, states[t_ns])))
        return rows

    def test_step_and_stand(self) -> None:
        self.probe.set_mode('User')
        self.probe.wait_sim(0.1)
        result = subprocess.run(
            ['rosrun', PKG, 'traj_yaml.py', str(TRAJECTORY_FILE), self.trajectory],
            capture_output=True, text=True, timeout=300, check=False)
        self.assertEqual(result.returncode, 0, f'traj_yaml.py failed:\n{result.stderr}')
        self.probe.wait_sim(STAND_S + 0.1)
        self.assertTrue(self.poses.command_ns, 'no command heard')
        stamps_ns = sorted(self.poses.command_ns)
        rospy.loginfo(f'{self.trajectory} live: {len(stamps_ns)} commands, longest gap between '
                      f'stamps {max(np.diff(stamps_ns)) / 1e6:.0f} ms of sim time (planned 20)')
        first_ns = min(self.poses.command_ns)
        end_ns = max(self.poses.command_ns) + int(COMMAND_PERIOD_S * 1e9)
        stand_until_ns = end_ns + int(STAND_S * 1e9)
        force = self.probe.contacts['r'].wrench.force
        bearing_n = float(np.linalg.norm([force.x, force.y, force.z]))
        rows = self.feet(first_ns, stand_until_ns)
        self.assertGreater(len(rows), (stand_until_ns - first_ns) / 1e9 * 50,
                           'too few poses with their joint states')
        start, last = rows[0][2], rows[-1][2]
        lift = max(foot[2] for t, _, foot in rows if t <= end_ns) - start[2]
        pelvis_min = min(z for _, z, _ in rows)
        forward, down = last[0] - start[0], last[2] - start[2]
        rospy.loginfo(f'{self.trajectory} live: right foot lifted {lift:.3f} m, landed '
                      f'{forward:.3f} m forward ({last[1] - start[1]:+.3f} m sideways, '
                      f'{down:+.4f} m up, bearing {bearing_n:.0f} N); lowest pelvis '
                      f'{pelvis_min:.3f} m until '
                      f'{(rows[-1][0] - end_ns) / 1e9:.2f} s after the trajectory')
        self.assertGreater(lift, LIFTED_M, 'the right foot lifted')
        self.assertGreaterEqual(forward, FORWARD_M, 'the right foot landed further forward')
        self.assertLess(abs(down), DOWN_WITHIN_M, 'the right foot is down at the end')
        self.assertGreater(bearing_n, BEARING_N, 'the right foot bears weight at the end')
        self.assertGreater(pelvis_min, PELVIS_ABOVE_M, 'the robot stood')
        self.assertGreaterEqual(rows[-1][0], stand_until_ns - int(0.05e9),
                                'poses up to 5 s after the trajectory')


if __name__ == '__main__':
    rostest.rosrun(PKG, 'test_live_step', LiveStepTest)
