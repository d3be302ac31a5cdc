#!/usr/bin/env python3
"""rostest: DRCSim's /atlas/atlas_state, /atlas/force_torque_sensors and debug foot contacts,
live: every step, genpy's types (rospy checks the MD5s), the joint state's numbers, and a
standing robot's forces and IMU, also on the port's own /atlas/imu and ankle topics.

The launch starts paused; the test subscribes, waits for its connections, unpauses and
keeps every message of the first WATCH_S of sim time.
"""

from __future__ import annotations

import threading
import time
import unittest

import numpy as np
import rospy
import rostest
from atlas_msgs.msg import AtlasState, ForceTorqueSensors
from geometry_msgs.msg import WrenchStamped
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, JointState
from std_srvs.srv import Empty

from tutorial_atlas_control import topics
from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.sim.controller import gains_from_params

PKG = 'tutorial_atlas_control'
STEP_NS = 1_000_000
#: Sim time (s) watched; the last STANDING_S of it is judged as standing (pin off at 1 s).
WATCH_S = 3.0
STANDING_S = 0.5
GRAVITY_MPS2 = 9.81
#: Atlas v1 (90.6 kg) weighs this much (N): the feet's contacts carry it all.
WEIGHT_N = 889.0
#: What the legs carry above the ankles (N): the weight less the two feet's
#: (docs/ros_interface.md: 857 N).
ABOVE_ANKLES_N = 857.0
WALL_TIMEOUT_S = 120.0


def vector(v) -> np.ndarray:  # geometry_msgs Vector3 or Point
    return np.array([v.x, v.y, v.z])


def wrench(w) -> np.ndarray:  # geometry_msgs/Wrench
    return np.r_[vector(w.force), vector(w.torque)]


class DrcsimStateTest(unittest.TestCase):
    messages: dict[str, dict[int, object]]

    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node('test_drcsim_state')
        cls.lock = threading.Lock()
        cls.messages = {}
        cls.latest_ns = {}
        cls.clock_ns = 0
        subscribers = [
            rospy.Subscriber(topic, msg_class, cls._keep, callback_args=topic, queue_size=20000)
            for topic, msg_class in (
                (topics.ATLAS_STATE, AtlasState), (topics.FORCE_TORQUE_SENSORS, ForceTorqueSensors),
                (topics.DEBUG_L_FOOT_CONTACT, WrenchStamped),
                (topics.DEBUG_R_FOOT_CONTACT, WrenchStamped),
                (topics.JOINT_STATES, JointState), (topics.IMU, Imu),
                (topics.L_FOOT_CONTACT, WrenchStamped), (topics.R_FOOT_CONTACT, WrenchStamped))]
        rospy.Subscriber(topics.CLOCK, Clock, cls._on_clock, queue_size=10)
        cls._wait(lambda: all(s.get_num_connections() >= 1 for s in subscribers),
                  'the simulator\'s connections')
        rospy.wait_for_service(topics.UNPAUSE_PHYSICS_SERVICE, timeout=WALL_TIMEOUT_S)
        rospy.ServiceProxy(topics.UNPAUSE_PHYSICS_SERVICE, Empty)()
        # Each topic's messages come in order on its connection: once one stamped past the
        # watch has arrived, every message of the watch has.
        watched = [s.resolved_name for s in subscribers]
        cls._wait(lambda: all(cls.latest_ns.get(topic, -1) > WATCH_S * 1e9 for topic in watched),
                  f'a message stamped after {WATCH_S} s on each of {watched}')

    @classmethod
    def _wait(cls, predicate, what: str) -> None:
        deadline = time.monotonic() + WALL_TIMEOUT_S
        while not predicate():
            if time.monotonic() > deadline or rospy.is_shutdown():
                raise AssertionError(f'timed out after {WALL_TIMEOUT_S} s waiting for {what}')
            time.sleep(0.01)

    @classmethod
    def _on_clock(cls, msg: Clock) -> None:
        cls.clock_ns = msg.clock.to_nsec()

    @classmethod
    def _keep(cls, msg, topic: str) -> None:
        stamp_ns = msg.header.stamp.to_nsec()
        with cls.lock:
            cls.latest_ns[topic] = max(stamp_ns, cls.latest_ns.get(topic, -1))
            if stamp_ns <= WATCH_S * 1e9:
                cls.messages.setdefault(topic, {})[stamp_ns] = msg

    def _standing(self, topic: str) -> list:
        start_ns = (WATCH_S - STANDING_S) * 1e9
        return [msg for stamp, msg in sorted(self.messages[topic].items()) if stamp >= start_ns]

    def test_every_step_from_the_start(self) -> None:
        """AtlasState at each step's end, the sensors at each step's start (AtlasState's
        stamp 0, the state before the first step, goes out as the node starts: seen or not,
        by when the test subscribed)."""
        steps = int(WATCH_S * 1e9) // STEP_NS
        self.assertEqual(sorted(set(self.messages[topics.ATLAS_STATE]) - {0}),
                         [k * STEP_NS for k in range(1, steps + 1)])
        self.assertEqual(sorted(self.messages[topics.FORCE_TORQUE_SENSORS]),
                         [k * STEP_NS for k in range(steps + 1)])

    def test_atlas_state_repeats_the_joint_state(self) -> None:
        for stamp_ns, state in self.messages[topics.ATLAS_STATE].items():
            joint_state = self.messages[topics.JOINT_STATES][stamp_ns]
            for field in ('position', 'velocity', 'effort'):
                np.testing.assert_array_equal(
                    np.float32(getattr(state, field)), np.float32(getattr(joint_state, field)))

    def test_standing_gains_and_k_effort(self) -> None:
        gains = gains_from_params(rospy.get_param(topics.GAINS_PARAM))
        for state in self._standing(topics.ATLAS_STATE):
            np.testing.assert_array_equal(np.float32(state.kp_position), np.float32(gains.p))
            np.testing.assert_array_equal(np.float32(state.kd_position), np.float32(gains.d))
            self.assertEqual(list(bytearray(state.k_effort)), [255] * NUM_JOINTS)

    def test_standing_ankles_and_imu(self) -> None:
        for state in self._standing(topics.ATLAS_STATE):
            for foot in (wrench(state.l_foot), wrench(state.r_foot)):
                self.assertTrue(-460.0 < foot[2] < -400.0, foot)
                self.assertEqual((foot[0], foot[1], foot[5]), (0.0, 0.0, 0.0))
            self.assertAlmostEqual(state.linear_acceleration.z, GRAVITY_MPS2, delta=0.1)

    def test_force_torque_sensors_are_atlas_state_s(self) -> None:
        """Both from the same step: AtlasState is stamped at its end, the sensors at its start."""
        states = self.messages[topics.ATLAS_STATE]
        for stamp_ns, sensors in self.messages[topics.FORCE_TORQUE_SENSORS].items():
            state = states.get(stamp_ns + STEP_NS)
            if state is None:  # the last step's, past WATCH_S
                continue
            for name in ('l_foot', 'r_foot', 'l_hand', 'r_hand'):
                np.testing.assert_array_equal(wrench(getattr(sensors, name)),
                                              wrench(getattr(state, name)))

    def test_debug_contacts_carry_the_robot(self) -> None:
        left = self._standing(topics.DEBUG_L_FOOT_CONTACT)
        right = {msg.header.stamp.to_nsec(): msg
                 for msg in self._standing(topics.DEBUG_R_FOOT_CONTACT)}
        self.assertEqual(len(left), round(STANDING_S * 1000) + 1)  # every step: feet down
        weights = [msg.wrench.force.z + right[msg.header.stamp.to_nsec()].wrench.force.z
                   for msg in left]
        self.assertTrue(all(msg.header.frame_id == 'l_foot' for msg in left))
        self.assertAlmostEqual(float(np.mean(weights)), WEIGHT_N, delta=0.03 * WEIGHT_N)

    def test_the_ports_imu_and_ankle_topics_standing(self) -> None:
        """/atlas/imu: +g up; /atlas/{l,r}_foot_contact: in the foot frames, each leg pushing
        its foot down (Fz < 0), the two Fz summing to the weight above the ankles (2 %: the
        robot sways slowly; the unit test derives the figure from the model's masses)."""
        imu = self._standing(topics.IMU)
        self.assertEqual(len(imu), round(STANDING_S * 1000) + 1)  # every step
        for msg in imu:
            self.assertAlmostEqual(msg.linear_acceleration.z, GRAVITY_MPS2, delta=0.1)
        left = self._standing(topics.L_FOOT_CONTACT)
        right = {msg.header.stamp.to_nsec(): msg for msg in self._standing(topics.R_FOOT_CONTACT)}
        self.assertEqual(len(left), round(STANDING_S * 1000) + 1)
        for msg in left:
            other = right[msg.header.stamp.to_nsec()]
            self.assertEqual((msg.header.frame_id, other.header.frame_id), ('l_foot', 'r_foot'))
            self.assertTrue(msg.wrench.force.z < 0.0 and other.wrench.force.z < 0.0)
            self.assertAlmostEqual(msg.wrench.force.z + other.wrench.force.z, -ABOVE_ANKLES_N,
                                   delta=0.02 * ABOVE_ANKLES_N)


if __name__ == '__main__':
    rostest.rosrun(PKG, 'drcsim_state', DrcsimStateTest)
