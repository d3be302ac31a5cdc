"""sim/velocity_damping.py: the velocity gain passed through to the joints' damping, as
DRCSim 2.7 did, and what it does to the robot: no torque that chatters."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tutorial_atlas_control.command import JointCommandArrays
from tutorial_atlas_control.joints import JOINT_INDEX, NUM_JOINTS
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.sim.simulator import AtlasSimulator, ControlMode
from tutorial_atlas_control.sim.velocity_damping import MAX_DAMPING_PER_LIMIT, VelocityDamping

CONFIG = Path(__file__).resolve().parents[3] / 'config' / 'atlas_controller.yaml'
ADR = np.arange(NUM_JOINTS) + 6
MODEL = np.full(NUM_JOINTS, 0.1)
EFFORT = np.full(NUM_JOINTS, 100.0)
VELOCITY = np.full(NUM_JOINTS, 12.0)


def damping() -> tuple[VelocityDamping, np.ndarray]:
    dof_damping = np.zeros(NUM_JOINTS + 6)
    dof_damping[ADR] = MODEL
    return VelocityDamping(dof_damping, ADR, EFFORT, VELOCITY), dof_damping


def gains(kp_velocity: float, k_effort: float = 1.0) -> JointCommandArrays:
    command = JointCommandArrays.zeros()
    command.kp_velocity[:] = kp_velocity
    command.k_effort[:] = k_effort
    return command


def test_a_gain_is_the_joints_damping_within_the_model_and_the_most() -> None:
    passing, dof_damping = damping()
    most = 100.0 / 12.0 * MAX_DAMPING_PER_LIMIT  # 416.7 N m s/rad
    passing.apply(gains(50.0))
    np.testing.assert_array_equal(dof_damping[ADR], 50.0)
    assert passing.passing and not dof_damping[:6].any()  # the free joint untouched
    passing.apply(gains(1000.0))
    np.testing.assert_allclose(dof_damping[ADR], most)
    passing.apply(gains(-3.0))  # below the model: the model's
    np.testing.assert_array_equal(dof_damping[ADR], MODEL)


def test_the_pids_share_of_the_gain_is_what_a_joint_gets() -> None:
    passing, dof_damping = damping()
    passing.apply(gains(50.0, k_effort=0.5))
    np.testing.assert_allclose(dof_damping[ADR], 0.1 + 0.5 * (50.0 - 0.1))
    passing.apply(gains(50.0, k_effort=0.0))  # a behaviour's joints: the model's
    np.testing.assert_array_equal(dof_damping[ADR], MODEL)


def test_without_a_gain_the_models_damping_comes_back() -> None:
    passing, dof_damping = damping()
    passing.apply(gains(50.0))
    passing.apply(gains(0.0))
    np.testing.assert_array_equal(dof_damping[ADR], MODEL)
    assert not passing.passing
    passing.apply(gains(50.0))
    passing.apply(None)  # a behaviour alone, or a recorded torque
    np.testing.assert_array_equal(dof_damping[ADR], MODEL)


def test_the_models_damping_set_by_the_test_topic_is_the_floor() -> None:
    passing, dof_damping = damping()
    passing.set_model(np.full(NUM_JOINTS, 80.0))
    np.testing.assert_array_equal(dof_damping[ADR], 80.0)
    passing.apply(gains(50.0))  # below the new model damping
    np.testing.assert_array_equal(dof_damping[ADR], 80.0)


def _user_hold(kp_velocity: float) -> tuple[float, float]:
    """The free robot from the hold under the user's PID at zeros, kd 0 and `kp_velocity`
    for 0.5 s: the mean change of the ankles' and wrists' torques per 1 ms step (N m) and
    how far the pelvis slid (m)."""
    sim = AtlasSimulator(atlas_model.load_model(), load_gains_yaml(CONFIG), time_to_unpin_s=0.0)
    sim.set_mode(ControlMode.USER)
    command = JointCommandArrays.zeros()
    command.kp_position[:] = sim.gains.p
    command.kp_velocity[:] = kp_velocity
    sim.commands.receive_command(list(JOINT_INDEX), {
        name: getattr(command, name) for name in ('position', 'kp_position', 'kp_velocity')})
    watched = [JOINT_INDEX[name] for name in ('l_leg_uay', 'r_leg_uay', 'l_arm_mwx',
                                              'r_arm_mwx')]
    start = sim.data.qpos[:2].copy()
    torques = []
    for _ in range(500):
        sim.step()
        torques.append(sim.torque_nm[watched].copy())
    jumps = np.abs(np.diff(np.array(torques), axis=0)).mean()
    return float(jumps), float(np.hypot(*(sim.data.qpos[:2] - start)))


@pytest.mark.parametrize('kp_velocity', [0.0, 50.0])
def test_a_velocity_gain_of_50_does_not_shake_the_robot(kp_velocity: float) -> None:
    """2.5.2's explicit term gave 383 N m of change per step at the ankles and slid the
    robot 0.47 m in 2 s; passed through to the damping the torques stay smooth."""
    jumps_nm, slid_m = _user_hold(kp_velocity)
    assert jumps_nm < 5.0, jumps_nm
    assert slid_m < 0.02, slid_m
