#!/usr/bin/env python3
"""rostest: atlas.launch behaviour:=examples/arm_wave.py:ArmWave serves the user's own Stand:
asked for with /atlas/control_mode Stand, the robot stands (the pelvis never below
PELVIS_ABOVE_M) while its right arm rises and the forearm waves."""

from __future__ import annotations

import unittest

import rospy
import rostest
from sim_probe import SimProbe  # beside this script, on its sys.path

PKG = 'tutorial_atlas_control'
#: How long the wave is watched (s of sim time) and how often (s).
WATCH_S = 4.0
SAMPLE_S = 0.05
#: The pelvis stays above this (m; the balancing Stand holds it at about 0.91 m).
PELVIS_ABOVE_M = 0.85
#: The raised shoulder (r_arm_shx: 1.30 rad in the Stand pose, 0.8 raised) comes below this
#: (rad); the elbow's wave (0.4 rad either way) spans at least this.
SHOULDER_RAISED_BELOW_RAD = 0.9
ELBOW_SPAN_RAD = 0.5


class UserBehaviourTest(unittest.TestCase):
    def test_the_users_stand_balances_and_waves(self) -> None:
        probe = SimProbe()
        probe.wait_ready()
        probe.wait_sim(1.2)  # the start's pin released at 1 s
        probe.set_mode_applied('Stand')
        start_s = probe.sim_time_s()
        pelvis, shoulder, elbow = [], [], []
        while probe.sim_time_s() < start_s + WATCH_S:
            probe.wait_sim(SAMPLE_S)
            pelvis.append(probe.pelvis_z())
            shoulder.append(probe.position('r_arm_shx'))
            elbow.append(probe.position('r_arm_elx'))
        self.assertGreater(min(pelvis), PELVIS_ABOVE_M)
        self.assertLess(min(shoulder), SHOULDER_RAISED_BELOW_RAD)
        late = elbow[len(elbow) // 2:]  # the arm raised: waving
        self.assertGreater(max(late) - min(late), ELBOW_SPAN_RAD)


if __name__ == '__main__':
    rospy.init_node('user_behaviour_probe')
    rostest.rosrun(PKG, 'user_behaviour', UserBehaviourTest)
