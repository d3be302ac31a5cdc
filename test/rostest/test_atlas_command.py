#!/usr/bin/env python3
"""rostest: /atlas/atlas_command, /atlas/debug/test and /atlas/reset_controls, live.

Private parameter ~scenario:
  interface  k_effort 0 on one joint in User mode leaves it limp (BDI outputs nothing in
             User: DRCSim's law gives that joint (1 - 0) * 0 N m); reset_controls in each form;
             bad input on each new topic and the service: one warning line, nothing applied,
             the simulator keeps stepping.
  client     test/rostest/atlas_command_client.cpp (roscpp) answers every /atlas/atlas_state
             with an AtlasCommand stamped with the state's stamp: l_arm_elx tracks its sine.
"""

from __future__ import annotations

import threading
import unittest

import numpy as np
import rospy
import rostest
from atlas_msgs.msg import AtlasCommand, Test
from atlas_msgs.srv import ResetControls, ResetControlsRequest
from sim_probe import SimProbe, after_stalls

PKG = 'tutorial_atlas_control'
N = 28
#: Sim time after start before switching to User (the torso is pinned for 1 s).
UNPIN_WAIT_S = 1.5
#: l_arm_shx holds the arm out sideways against about 36 N m of its weight: limp, it falls.
LIMP_JOINT, OTHER_SHOULDER = 'l_arm_shx', 'r_arm_shx'
LIMP_FALL_RAD = 0.5
HELD_RAD = 0.05
#: The arm joint reset_controls' atlas_command moves, and where to.
MOVED_JOINT, MOVED_TARGET_RAD = 'l_arm_elx', 0.8
TRACKING_TOLERANCE_RAD = 0.1
#: The simulator's step (ns).
STEP_NS = 1_000_000

# -- the roscpp client (as test_command_age.py's) ----------------------------------------------
SINE_JOINT = 'l_arm_elx'
TRACKING_S = 4.0
SETTLE_S = 1.0
ANSWERED_SHARE = 0.8


def gains() -> dict[str, dict[str, float]]:
    return rospy.get_param('atlas_controller/gains')


class AtlasCommandTest(unittest.TestCase):
    def setUp(self) -> None:
        rospy.init_node('test_atlas_command', anonymous=True)
        self.lock = threading.Lock()
        self.commands: dict[int, AtlasCommand] = {}
        self.probe = SimProbe(keep_joint_states=True)
        self.command_pub = rospy.Publisher('/atlas/atlas_command', AtlasCommand, queue_size=10)
        self.test_pub = rospy.Publisher('/atlas/debug/test', Test, queue_size=10)
        rospy.Subscriber('/atlas/atlas_command', AtlasCommand, self._on_command, queue_size=5000)
        self.probe.wait_ready()
        self.probe.wait_until(lambda: self.command_pub.get_num_connections() > 0
                              and self.test_pub.get_num_connections() > 0,
                              'the simulator to subscribe to atlas_command and debug/test')
        self.probe.wait_sim(UNPIN_WAIT_S)
        self.names = list(self.probe.joint_state.name)

    def _on_command(self, msg: AtlasCommand) -> None:
        with self.lock:
            self.commands[msg.header.stamp.to_nsec()] = msg

    def index(self, joint: str) -> int:
        return self.names.index(joint)

    def positions(self) -> np.ndarray:
        self.probe.position(self.names[0])  # a fresh joint state
        return np.array(self.probe.joint_state.position)

    def hold_command(self, position: np.ndarray) -> AtlasCommand:
        """`position` held with the parameter gains, k_effort 255 on every joint."""
        table = gains()
        command = AtlasCommand()
        command.position = list(position)
        command.velocity = [0.0] * N
        command.effort = [0.0] * N
        command.kp_position = [table[name]['p'] for name in self.names]
        command.ki_position = [table[name]['i'] for name in self.names]
        command.kd_position = [table[name]['d'] for name in self.names]
        command.kp_velocity = [0.0] * N
        command.i_effort_min = [-table[name]['i_clamp'] for name in self.names]
        command.i_effort_max = [table[name]['i_clamp'] for name in self.names]
        command.k_effort = bytes([255] * N)
        command.header.stamp = rospy.Time.now()
        return command

    def test_scenario(self) -> None:
        getattr(self, f'scenario_{rospy.get_param("~scenario")}')()

    # -- interface ---------------------------------------------------------------------------
    def scenario_interface(self) -> None:
        self.k_effort_zero_in_user_mode()
        self.probe.restart_held()
        self.probe.wait_sim(UNPIN_WAIT_S)
        self.reset_controls_forms()
        self.bad_inputs()

    def k_effort_zero_in_user_mode(self) -> None:
        self.probe.set_mode('User')
        self.probe.wait_sim(0.2)
        held = self.positions()
        command = self.hold_command(held)
        k_effort = [255] * N
        k_effort[self.index(LIMP_JOINT)] = 0
        command.k_effort = bytes(k_effort)
        with self.probe.lock:
            kept_from = len(self.probe.joint_states)
        self.command_pub.publish(command)
        self.probe.wait_sim(1.5)
        with self.probe.lock:
            states = self.probe.joint_states[kept_from:]
        limp, other = self.index(LIMP_JOINT), self.index(OTHER_SHOULDER)
        # From the first state whose effort is 0 on the limp joint (the command applied):
        first = next(k for k, s in enumerate(states) if s.effort[limp] == 0.0)
        applied = states[first:]
        self.assertGreater(len(applied), 1000)
        self.assertEqual({s.effort[limp] for s in applied}, {0.0})
        self.assertGreater(np.mean([abs(s.effort[other]) for s in applied]), 20.0)
        final = np.array(applied[-1].position)
        self.assertGreater(abs(final[limp] - held[limp]), LIMP_FALL_RAD, 'the limp arm falls')
        self.assertLess(abs(final[other] - held[other]), HELD_RAD, 'the other arm is held')
        rospy.loginfo(f'k_effort 0 on {LIMP_JOINT} in User: effort 0.0 N m in {len(applied)} '
                      f'states; it fell {abs(final[limp] - held[limp]):.2f} rad, '
                      f'{OTHER_SHOULDER} moved {abs(final[other] - held[other]):.4f} rad')

    def call_reset_controls(self, **fields: object) -> tuple[bool, str]:
        rospy.wait_for_service('/atlas/reset_controls', timeout=60.0)
        response = rospy.ServiceProxy('/atlas/reset_controls', ResetControls)(
            ResetControlsRequest(**fields))
        return response.success, response.status_message

    def reset_controls_forms(self) -> None:
        """In Stand mode (the start-up mode): each form of the request, judged by the arm."""
        moved = self.index(MOVED_JOINT)
        start = self.positions()
        # 1. atlas_command loaded, with the PID state reset: k_effort 255 on the elbow only
        #    hands it to that command while the Stand hold keeps the rest of the robot.
        command = self.hold_command(np.zeros(N))
        command.position[moved] = MOVED_TARGET_RAD
        command.k_effort = bytes([255 if k == moved else 0 for k in range(N)])
        ok, status = self.call_reset_controls(reset_pid_controller=True, atlas_command=command)
        self.assertTrue(ok, status)
        self.assertEqual(status, 'PID state reset (integral terms and previous errors); '
                                 'atlas_command loaded: position, velocity, effort, '
                                 'kp_position, ki_position, kd_position, kp_velocity, '
                                 'k_effort, i_effort_min, i_effort_max')
        self.probe.wait_sim(1.5)
        after = self.positions()
        self.assertLess(abs(after[moved] - MOVED_TARGET_RAD), TRACKING_TOLERANCE_RAD)
        other_elbow = self.index('r_arm_elx')
        self.assertLess(abs(after[other_elbow] - start[other_elbow]), HELD_RAD,
                        'the Stand hold keeps the other elbow')
        self.assertGreater(self.probe.pelvis_z(), 0.8, 'the robot stands')
        # 2. gains reloaded from the parameter server: k_effort 255 everywhere, so the
        #    command's targets (the elbow at 0.8, the rest at 0) hold every joint.
        ok, status = self.call_reset_controls(reset_bdi_controller=True,
                                              reload_pid_from_ros=True)
        self.assertTrue(ok, status)
        self.assertEqual(status, 'reset_bdi_controller: there is no BDI controller in this '
                                 'simulator, nothing to reset; gains reloaded from '
                                 'atlas_controller/gains, k_effort 255 on every joint '
                                 '(atlas_command ignored)')
        self.probe.wait_sim(1.0)
        self.assertLess(abs(self.positions()[moved] - MOVED_TARGET_RAD), TRACKING_TOLERANCE_RAD)
        self.assertGreater(self.probe.pelvis_z(), 0.8, 'the robot stands')
        # 3. the PID state alone
        ok, status = self.call_reset_controls(reset_pid_controller=True)
        self.assertEqual((ok, status), (True, 'PID state reset (integral terms and previous '
                                              'errors); atlas_command has no array of 28: no '
                                              'field loaded'))

    def bad_inputs(self) -> None:
        """Each refused: one warning line, the elbow stays where reset_controls put it."""
        moved = self.index(MOVED_JOINT)
        bad_command = self.hold_command(np.zeros(N))
        bad_command.kp_position[3] = float('nan')
        wrong_length = self.hold_command(np.zeros(N))
        wrong_length.position = [0.0] * 27
        wrong_length.k_effort = b''
        bad_test = Test(damping=[0.1] * 27 + [-1.0])
        cases = (
            ('refused /atlas/atlas_command: kp_position[3] is nan (NaN/Inf are refused); '
             'previous command kept', lambda: self.command_pub.publish(bad_command)),
            ('/atlas/atlas_command: position (27 entries) not 28 long; that field keeps its '
             'previous values', lambda: self.command_pub.publish(wrong_length)),
            ('refused /atlas/debug/test: damping[27] is -1, outside 0..10000 N m s/rad; '
             'previous command kept', lambda: self.test_pub.publish(bad_test)),
        )
        for text, send in cases:
            send()
            self.probe.wait_until(lambda t=text: self.probe.warnings_containing(t),
                                  f'the warning {text!r}')
        bad_reset = self.hold_command(np.zeros(N))
        bad_reset.effort[0] = 1e9
        ok, status = self.call_reset_controls(reset_pid_controller=True,
                                              atlas_command=bad_reset)
        self.assertEqual((ok, status), (False, 'atlas_command refused: effort[0] is 1e+09, '
                                               'beyond the sane bound of 100000 in magnitude; '
                                               'nothing was done'))
        before_ns = self.probe.clock_ns
        self.probe.wait_sim(1.0)
        self.assertGreater(self.probe.clock_ns, before_ns)  # still stepping
        # wrong_length's other fields applied (its targets are the same zeros and 0.8 kept)
        self.assertLess(abs(self.positions()[moved] - MOVED_TARGET_RAD), TRACKING_TOLERANCE_RAD)
        self.assertGreater(self.probe.pelvis_z(), 0.8)
        for text, _send in cases:
            self.assertEqual(len(self.probe.warnings_containing(text)), 1, text)

    # -- the roscpp client -------------------------------------------------------------------
    def scenario_client(self) -> None:
        self.probe.wait_until(lambda: len(self.commands) > 100, 'the roscpp client to answer')
        self.probe.set_mode('User')
        start_ns = self.probe.clock_ns + int(SETTLE_S * 1e9)
        self.probe.wait_sim(SETTLE_S + TRACKING_S)
        end_ns = start_ns + int(TRACKING_S * 1e9)
        with self.probe.lock:
            states = [m for m in self.probe.joint_states
                      if start_ns <= m.header.stamp.to_nsec() <= end_ns]
        with self.lock:
            commands = dict(self.commands)
        self.assertGreater(len(states), TRACKING_S * 900)
        index = self.index(SINE_JOINT)
        answered = [(s, commands[s.header.stamp.to_nsec()]) for s in states
                    if s.header.stamp.to_nsec() in commands]
        # Tracking is judged where the client kept up: after a stall (a loaded host starved
        # it) the joint follows the last command it could send, a speed, not the law's doing.
        stalled = after_stalls([s.header.stamp.to_nsec() for s, _c in answered],
                               STEP_NS)
        timely = [(s, c) for s, c in answered if s.header.stamp.to_nsec() not in stalled]
        errors = np.array([abs(s.position[index] - c.position[index]) for s, c in timely])
        targets = np.array([c.position[index] for _s, c in answered])
        measured = np.array([s.position[index] for s, _c in answered])
        rospy.loginfo(f'AtlasCommand client: answered {len(answered)} of {len(states)} states '
                      f'({len(stalled)} in or just after a stall); {SINE_JOINT} target '
                      f'{targets.min():.2f}..{targets.max():.2f} rad, tracking error max '
                      f'{errors.max():.4f} rad, mean {errors.mean():.4f}')
        self.assertGreater(len(timely), ANSWERED_SHARE * len(states))
        self.assertEqual(set(answered[0][1].k_effort), {255})
        self.assertGreater(targets.max() - targets.min(), 0.7, 'the sine spans its 0.8 rad')
        self.assertGreater(measured.max() - measured.min(), 0.6, 'the joint moves with it')
        self.assertLess(errors.max(), TRACKING_TOLERANCE_RAD)


if __name__ == '__main__':
    rostest.rosrun(PKG, 'atlas_command', AtlasCommandTest)
