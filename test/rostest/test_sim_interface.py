#!/usr/bin/env python3
"""rostest: the simulator node speaks DRCSim's ROS interface (topics, commands, modes, services)."""

from __future__ import annotations

import time
import unittest

import numpy as np
import rosgraph
import rospy
import rostest
from rosgraph_msgs.msg import Clock
from sim_probe import SimProbe, messages_received  # beside this script, on its sys.path

from tutorial_atlas_control import topics
from tutorial_atlas_control.joints import JOINT_INDEX, JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.node.cheats import WARN_THROTTLE_S
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import gains_from_params
from tutorial_atlas_control.sim.simulator import AtlasSimulator, ControlMode

PKG = 'tutorial_atlas_control'
EXPECTED_TYPES = {topic: topics.MSG_TYPES[topic] for topic in (
    topics.CLOCK, topics.JOINT_STATES, topics.GROUND_TRUTH_ODOM, topics.IMU,
    topics.L_FOOT_CONTACT, topics.R_FOOT_CONTACT, topics.JOINT_COMMANDS, topics.CONTROL_MODE)}
STEP_NS = 1_000_000
#: A step command on the left elbow, with the tutorial's gains for that joint.
ELBOW = 'l_arm_elx'
MODE_TOPIC, COMMAND_TOPIC = '/atlas/control_mode', '/atlas/joint_commands'
#: Wall time (s) without a /clock that says the pause took effect, and the window the paused
#: clock must then stand still in.
CLOCK_QUIET_S = 0.1
PAUSE_WATCH_S = 0.5
ELBOW_TARGET_RAD = 0.8
#: Sim time (s) Stand is watched for from a reset: the 1 s pin, its release, and 4 s after.
STAND_WATCHED_S = 5.0
#: The AtlasSimInterface's behaviours (ASI.md).
ASI_STAND, ASI_WALK = 0, 4
#: control_mode Walk's feet: Stand takes the robot over (s of sim time), the walk's wall-time
#: bound (s), the stance after it watched (s of sim time); the issue's bounds on how far a
#: foot may slide (m) or turn (rad) there; a standing pelvis stays above this (m).
STAND_TAKE_OVER_S = 2.0
WALK_WALL_TIMEOUT_S = 60.0
STANCE_WATCHED_S = 10.0
FOOT_SLIDES_BELOW_M = 0.01
FOOT_TURNS_BELOW_RAD = 0.02
PELVIS_ABOVE_M = 0.8


class AsiStates:
    """The newest AtlasSimInterfaceState, and the lowest pelvis it reported since
    `watch_pelvis` (the recorder's copy of the state: 50 Hz and each change, not 1 kHz)."""

    def __init__(self) -> None:
        from atlas_msgs.msg import AtlasSimInterfaceState

        self.state: AtlasSimInterfaceState | None = None
        self.lowest_pelvis_m = float('inf')
        self._subscriber = rospy.Subscriber(topics.ASI_STATE_RECORDED, AtlasSimInterfaceState,
                                            self._on_state, queue_size=1)

    def _on_state(self, state: object) -> None:
        self.state = state
        self.lowest_pelvis_m = min(self.lowest_pelvis_m, state.pos_est.position.z)

    def watch_pelvis(self) -> None:
        self.lowest_pelvis_m = float('inf')

    def behaviour(self) -> int | None:
        return None if self.state is None else self.state.current_behavior

    def feet(self) -> np.ndarray:
        """Each foot's (x, y, yaw) from foot_pos_est (2, 3)."""
        assert self.state is not None
        rows = []
        for pose in self.state.foot_pos_est:
            q = pose.orientation
            yaw = np.arctan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
            rows.append((pose.position.x, pose.position.y, yaw))
        return np.array(rows)

    def close(self) -> None:
        self._subscriber.unregister()


class SimInterfaceTest(unittest.TestCase):
    probe: SimProbe

    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node('test_sim_interface')
        cls.probe = SimProbe()
        cls.probe.wait_ready()

    def restart(self, mode: str) -> None:
        """Sim time 0, robot at its initial pose, in `mode`."""
        self.probe.call('/gazebo/reset_simulation')
        self.probe.set_mode(mode)
        self.probe.wait_sim(0.05)

    def test_01_topics_types_and_joint_names(self) -> None:
        types = dict(rosgraph.Master('/test').getTopicTypes())
        for topic, expected in EXPECTED_TYPES.items():
            self.assertEqual(types.get(topic), expected, topic)
        self.assertEqual(tuple(self.probe.joint_state.name), JOINT_NAMES)

    def test_02_joint_states_every_step_stamped_with_sim_time(self) -> None:
        probe = self.probe
        clocks: list[int] = []
        with probe.lock:
            probe.joint_states.clear()
            probe.keep_joint_states = True
        start_ns = probe.clock_ns
        clock_sub = rospy.Subscriber('/clock', Clock, lambda m: clocks.append(m.clock.to_nsec()),
                                     queue_size=5000)
        probe.wait_sim(1.0)
        with probe.lock:
            probe.keep_joint_states = False
            states = list(probe.joint_states)
        clock_sub.unregister()
        stamps = np.array([s.header.stamp.to_nsec() for s in states
                           if s.header.stamp.to_nsec() > start_ns])
        self.assertGreater(len(stamps), 950, 'about 1000 joint states per second of sim time')
        steps = np.diff(stamps)
        self.assertEqual(int(np.median(steps)), STEP_NS)
        self.assertTrue(np.all(steps % STEP_NS == 0), 'stamps fall on physics steps')
        # /clock carries the latest sim time of each batch the node sends (every step when
        # paced; thinned at real_time_factor 0): every one of them stamps a joint state.
        clocks_in_window = np.array([c for c in clocks if stamps[0] <= c <= stamps[-1]])
        self.assertGreater(len(clocks_in_window), 10)
        on_states = np.isin(clocks_in_window, stamps)
        self.assertGreater(on_states.mean(), 0.95, '/clock times stamp joint states')

    def test_03_stands_without_commands(self) -> None:
        """The start's hold through the ROS path: the pin's release at 1 s and after it. How
        long it stands is judged offline (test_model.py: 30 s, the pelvis within 2 cm)."""
        probe = self.probe
        probe.restart_held('/gazebo/reset_simulation')
        probe.wait_sim(0.05)
        start_z = probe.pelvis_z()
        heights = []
        end_ns = probe.clock_ns + round(STAND_WATCHED_S * 1e9)
        while probe.clock_ns < end_ns:
            heights.append(probe.pelvis_z())
            probe.wait_sim(0.05)
        drift = float(np.max(np.abs(np.array(heights) - start_z)))
        rospy.loginfo(f'standing: max pelvis drift over {STAND_WATCHED_S:g} s = '
                      f'{drift * 100:.2f} cm')
        self.assertLess(drift, 0.02)

    def test_04_step_command_follows_the_law(self) -> None:
        """The node's response equals AtlasSimulator's, step for step (one code path)."""
        probe = self.probe
        gains = gains_from_params(rospy.get_param('atlas_controller/gains'))
        index = JOINT_INDEX[ELBOW]
        command = {'position': [ELBOW_TARGET_RAD], 'kp_position': [float(gains.p[index])],
                   'kd_position': [float(gains.d[index])]}
        probe.call('/gazebo/pause_physics')
        probe.call('/gazebo/reset_simulation')
        modes, commands = (messages_received(topic) for topic in (MODE_TOPIC, COMMAND_TOPIC))
        probe.set_mode('User')
        probe.send(['atlas::' + ELBOW], **command)
        # Both read by the simulator while physics is paused (then handed to its loop).
        probe.wait_until(lambda: messages_received(MODE_TOPIC) > modes
                         and messages_received(COMMAND_TOPIC) > commands,
                         'the simulator to read the mode and the command')
        with probe.lock:
            probe.joint_states.clear()
            probe.keep_joint_states = True
        probe.call('/gazebo/unpause_physics')
        probe.wait_sim(1.0)
        with probe.lock:
            probe.keep_joint_states = False
            recorded = {s.header.stamp.to_nsec() // STEP_NS: np.array(s.position)
                        for s in probe.joint_states}

        offline = AtlasSimulator(atlas_model.load_model(), gains,
                                 float(rospy.get_param('/atlas/time_to_unpin', 1.0)))
        offline.set_mode(ControlMode.USER)
        offline.receive_command(['atlas::' + ELBOW], command)
        predicted = {}
        for step in range(1, 1001):
            offline.step()
            predicted[step] = offline.joint_positions().copy()
        common = sorted(set(recorded) & set(predicted))
        self.assertGreater(len(common), 900)
        worst = max(float(np.max(np.abs(recorded[s] - predicted[s]))) for s in common)
        rospy.loginfo(f'step response: largest deviation from the law = {worst:.3g} rad')
        self.assertLess(worst, 1e-9)
        self.assertAlmostEqual(recorded[common[-1]][index], ELBOW_TARGET_RAD, delta=0.05)

    def test_05_bad_commands_are_refused_and_previous_command_stays(self) -> None:
        probe = self.probe
        self.restart('User')
        probe.send([ELBOW], position=[ELBOW_TARGET_RAD])
        probe.wait_sim(1.5)
        # P-gain slack: the elbow (p=200) sags a few hundredths of a radian under gravity.
        self.assertAlmostEqual(probe.position(ELBOW), ELBOW_TARGET_RAD, delta=0.1)
        bad = [
            ([], {'position': [0.0] * (NUM_JOINTS - 1)}, 'position has 27 entries'),
            ([ELBOW], {'position': [float('nan')]}, 'NaN/Inf'),
            (['atlas::l_arm_nope'], {'position': [0.0]}, 'unknown joint name'),
        ]
        for names, arrays, reason in bad:
            probe.send(names, **arrays)
            probe.wait_until(lambda r=reason: probe.warnings_containing(r), f'a warning: {reason}')
            # Refusals of a topic are throttled for WARN_THROTTLE_S of wall time (RosLog), not
            # sim time: a starved simulator catching up ran 2.1 s of sim time in less, and the
            # next refusal went unlogged.
            time.sleep(WARN_THROTTLE_S + 0.1)
        probe.wait_sim(0.5)
        # Still on the accepted command (the refused 27-entry one would send it to 0).
        self.assertAlmostEqual(probe.position(ELBOW), ELBOW_TARGET_RAD, delta=0.1)

    def test_06_names_with_prefix_and_shuffled_are_mapped(self) -> None:
        probe = self.probe
        self.restart('User')
        targets = {'r_arm_elx': -0.8, 'l_arm_shx': 0.4, 'r_arm_shx': -0.4}
        names = ['atlas::r_arm_shx', 'l_arm_shx', 'atlas::r_arm_elx']
        probe.send(names, position=[targets[n.replace('atlas::', '')] for n in names])
        probe.wait_sim(2.0)
        for joint, target in targets.items():
            self.assertAlmostEqual(probe.position(joint), target, delta=0.05, msg=joint)

    def test_07_modes_freeze_unknown_ragdoll(self) -> None:
        probe = self.probe
        self.restart('User')
        probe.send([ELBOW], position=[ELBOW_TARGET_RAD])
        probe.wait_sim(1.5)
        self.assertAlmostEqual(probe.position(ELBOW), ELBOW_TARGET_RAD, delta=0.1)
        probe.set_mode('Freeze')
        probe.wait_sim(0.1)
        frozen_rad = probe.position(ELBOW)
        probe.send([ELBOW], position=[0.0])  # stored, not applied while frozen
        probe.set_mode('Dance')
        probe.wait_until(lambda: probe.warnings_containing('valid modes: Stand, StandPrep, '
                                                           'Freeze, ragdoll, User, Walk'),
                         'the unknown-mode warning')
        probe.wait_sim(1.0)
        # Held near where it was frozen (the body still sways), not sent to the stored 0.
        self.assertAlmostEqual(probe.position(ELBOW), frozen_rad, delta=0.1)
        probe.set_mode('ragdoll')
        probe.wait_sim(3.0)
        self.assertLess(probe.pelvis_z(), 0.5, 'ragdoll: the robot collapses')

    def test_08_pin_release_reset_and_pause(self) -> None:
        probe = self.probe
        unpin_s = float(rospy.get_param('/atlas/time_to_unpin'))
        probe.set_mode('ragdoll')
        reset_ns = probe.reset('/gazebo/reset_world')
        probe.wait_sim(0.05)  # odometry from after the reset
        spawn_z = atlas_model.SPAWN_HEIGHT_M
        unpin_ns = reset_ns + int(unpin_s * 1e9)
        pinned_readings = 0
        while probe.clock_ns < unpin_ns - int(0.1 * 1e9):
            # Judged by when each reading was measured: when the probe lags, the wait for a
            # fresh one can pass the unpin, after which the limp robot first rises 2-20 mm.
            stamp_ns, z = probe.pelvis_z_stamped()
            if reset_ns <= stamp_ns < unpin_ns:
                self.assertAlmostEqual(z, spawn_z, delta=0.002,
                                       msg=f'pinned torso, {(stamp_ns - reset_ns) / 1e6:.0f} '
                                           'ms after the reset')
                pinned_readings += 1
            probe.wait_sim(0.02)
        self.assertGreaterEqual(pinned_readings, 5, 'readings of the pinned torso')
        probe.wait_sim(3.0)
        self.assertLess(probe.pelvis_z(), 0.5, 'released after time_to_unpin, ragdoll falls')
        self.assertGreater(probe.clock_ns, reset_ns, 'reset_world keeps sim time')

        self.assertEqual(probe.reset('/gazebo/reset_simulation'), 0,
                         'reset_simulation rewinds sim time to 0')
        probe.wait_sim(0.05)
        self.assertLess(probe.sim_time_s(), 0.5, 'reset_simulation rewinds sim time')
        self.assertAlmostEqual(probe.pelvis_z(), spawn_z, delta=0.002)

        # pause_physics answers once the node has stopped and sent every /clock of the steps
        # before it; those still on their way arrive, then none: wait until the clock stops,
        # then watch it stand still. Unpaused whatever happens, for the tests after this one.
        probe.call('/gazebo/pause_physics')
        try:
            def clock_stopped() -> bool:
                before_ns = probe.clock_ns
                time.sleep(CLOCK_QUIET_S)
                return probe.clock_ns == before_ns

            probe.wait_until(clock_stopped, 'the clock to stop after pause_physics')
            paused_ns = probe.clock_ns
            time.sleep(PAUSE_WATCH_S)  # the window it must stand still in, not a wait
            self.assertEqual(probe.clock_ns, paused_ns, 'paused physics: clock stands still')
        finally:
            probe.call('/gazebo/unpause_physics')
        probe.wait_sim(0.1)
        self.assertGreater(probe.clock_ns, paused_ns)
        probe.set_mode('Stand')

    def test_09_control_mode_walk_then_the_feet_stay_put_in_stand(self) -> None:
        """DRCSim's control_mode Walk from the balancing Stand: its queue walked without a
        fall and, back in Stand, each foot where the walk put it for STANCE_WATCHED_S."""
        probe = self.probe
        states = AsiStates()
        try:
            probe.reset('/gazebo/reset_simulation')
            probe.set_mode('Stand')  # from the default start's hold: the balancing Stand
            probe.wait_until(lambda: states.behaviour() == ASI_STAND
                             and not any(states.state.k_effort), 'the balancing Stand')
            states.watch_pelvis()
            probe.wait_sim(STAND_TAKE_OVER_S)
            probe.set_mode('Walk')
            probe.wait_until(lambda: states.behaviour() == ASI_WALK, 'Walk')
            probe.wait_until(lambda: states.behaviour() == ASI_STAND, 'Walk back to Stand',
                             timeout_s=WALK_WALL_TIMEOUT_S)
            probe.wait_sim(1.0)  # the last foot down and settled
            before = states.feet()
            probe.wait_sim(STANCE_WATCHED_S)
            after = states.feet()
            self.assertEqual(states.behaviour(), ASI_STAND)
            slid = np.hypot(*(after[:, :2] - before[:, :2]).T)
            turned = np.abs(np.angle(np.exp(1j * (after[:, 2] - before[:, 2]))))
            rospy.loginfo(f'control_mode Walk, then Stand: in {STANCE_WATCHED_S:g} s the feet '
                          f'slid {slid} m and turned {turned} rad; lowest pelvis '
                          f'{states.lowest_pelvis_m:.3f} m')
            self.assertTrue((slid < FOOT_SLIDES_BELOW_M).all(), f'the feet slid {slid} m')
            self.assertTrue((turned < FOOT_TURNS_BELOW_RAD).all(), f'the feet turned {turned}')
            self.assertGreater(float(before[0, 0] + before[1, 0]) / 2.0, 0.5,
                               f'the feet walked ahead: {before}')
            self.assertGreater(states.lowest_pelvis_m, PELVIS_ABOVE_M, 'a fall')
        finally:
            states.close()


if __name__ == '__main__':
    rostest.rosrun(PKG, 'sim_interface', SimInterfaceTest)
