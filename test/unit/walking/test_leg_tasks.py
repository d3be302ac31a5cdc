"""The legs' shared tasks on the Atlas model placed in DRCSim's Stand pose: the foot servo
asks of the leg the sole's acceleration its PD means, with the leg's inertia (so its gains
are per unit of inertia), damps the sole's velocity in the world and feeds the path's
acceleration forward, the CoM height's reference moves smoothly with its rate, and a
stance sole's pressure-centre clamp is the support polygon's."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.balance.estimator import BalanceState
from tutorial_atlas_control.balance.sole import box_corners
from tutorial_atlas_control.balance.stand import orientation_error
from tutorial_atlas_control.balance.stand_behaviour import StandBehaviour
from tutorial_atlas_control.balance.stand_pose import place_in_stand_pose
from tutorial_atlas_control.balance.support import clamp_into, convex_hull
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.walking.footsteps import Footstep
from tutorial_atlas_control.walking.leg_tasks import (
    LEG_OF_FOOT,
    LegGains,
    LegTasks,
    _clamp_to_sole,
    foot_pose,
)
from tutorial_atlas_control.walking.swing import SwingPath

LEFT, RIGHT = 0, 1


@pytest.fixture(scope='module')
def standing() -> tuple[StandBehaviour, mujoco.MjData]:
    atlas = atlas_model.load_model()
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    behaviour = StandBehaviour(atlas)
    behaviour.start(data)
    return behaviour, data


def _legs(standing: tuple[StandBehaviour, mujoco.MjData],
          gains: LegGains | None = None) -> LegTasks:
    behaviour, _ = standing
    assert behaviour.controller is not None
    return LegTasks(behaviour.controller, gains or LegGains(), 0.0)


@pytest.mark.parametrize('foot', [LEFT, RIGHT])
def test_the_foot_servo_asks_the_soles_pd_acceleration_of_that_leg_alone(
        standing: tuple[StandBehaviour, mujoco.MjData], foot: int) -> None:
    behaviour, data = standing
    gains = LegGains(ik_damping_m=0.0)  # undamped: exactly the PD's acceleration
    legs = _legs(standing, gains)
    state = behaviour.estimator.estimate(data.qpos, data.qvel)
    sole = state.sole_centres[foot]
    offset = np.array([0.01, -0.005, 0.02])  # 2.3 cm off, nothing moving
    joint_velocities = np.zeros(28)
    torque = legs.foot_servo(state, joint_velocities, foot, sole + offset, np.zeros(3),
                             0.0, 0.0)
    leg = LEG_OF_FOOT[foot]
    untouched = np.ones(28, dtype=bool)
    untouched[leg] = False
    assert not torque[untouched].any()
    # The leg's joint acceleration under that torque alone, and the sole's acceleration.
    acceleration = np.linalg.solve(state.joint_inertia(leg), torque[leg])
    sole_acceleration = state.sole_jacobians[foot][:, leg] @ acceleration
    np.testing.assert_allclose(sole_acceleration[0:3], gains.swing_kp * offset, rtol=1e-6)
    # Its turn: towards level, heading 0 (the placed sole is a little off both).
    turn = orientation_error(state.sole_rotations[foot], np.eye(3))
    np.testing.assert_allclose(sole_acceleration[3:6], gains.swing_kp * turn, atol=1e-6)
    # Damped (the walk's 2 cm), the nearly straight leg's up and down gives a little.
    damped = _legs(standing).foot_servo(state, joint_velocities, foot, sole + offset,
                                        np.zeros(3), 0.0, 0.0)
    acceleration = np.linalg.solve(state.joint_inertia(leg), damped[leg])
    sole_acceleration = state.sole_jacobians[foot][:, leg] @ acceleration
    np.testing.assert_allclose(sole_acceleration[0:3], gains.swing_kp * offset, rtol=0.1)


def _moving(standing: tuple[StandBehaviour, mujoco.MjData], dofs: slice | np.ndarray,
            speed: float) -> BalanceState:
    """The estimate with these velocities (qvel indices) at `speed`, the rest at rest."""
    behaviour, data = standing
    qvel = np.zeros_like(data.qvel)
    qvel[dofs] = speed
    return behaviour.estimator.estimate(data.qpos, qvel)


def test_the_swing_servo_damps_the_soles_velocity_in_the_world(
        standing: tuple[StandBehaviour, mujoco.MjData]) -> None:
    """The leg's own joints moving: damped as they move (undamped inverse: exactly). The
    pelvis moving, the leg still: the sole moves with it, and a swing foot's servo damps
    that too (damping the joints alone let the foot run ahead of its path by the pelvis's
    speed: 1 cm at 0.4 m/s)."""
    behaviour, data = standing
    legs = _legs(standing, LegGains(ik_damping_m=0.0))
    leg = LEG_OF_FOOT[LEFT]
    dofs = behaviour.atlas.dof_adr[leg]
    state = _moving(standing, dofs, 0.1)
    sole, yaw = state.sole_centres[LEFT], 0.0
    at_rest_state = behaviour.estimator.estimate(data.qpos, np.zeros_like(data.qvel))
    joint_velocities = np.zeros(28)
    joint_velocities[leg] = 0.1
    torque = legs.foot_servo(state, joint_velocities, LEFT, sole, np.zeros(3), yaw, 0.0,
                             world=True)
    at_rest = legs.foot_servo(at_rest_state, np.zeros(28), LEFT, sole, np.zeros(3), yaw, 0.0,
                              world=True)
    damping = np.linalg.solve(state.joint_inertia(leg), (torque - at_rest)[leg])
    np.testing.assert_allclose(damping, -LegGains().swing_kd * 0.1, rtol=1e-6)
    # The pelvis moving forward at 0.4 m/s, every joint still.
    free = int(behaviour.atlas.model.jnt_dofadr[
        behaviour.atlas.model.body_jntadr[behaviour.atlas.pelvis_body_id]])
    carried = _moving(standing, slice(free, free + 1), 0.4)
    torque = legs.foot_servo(carried, np.zeros(28), LEFT, sole, np.zeros(3), yaw, 0.0,
                             world=True)
    acceleration = np.linalg.solve(state.joint_inertia(leg), (torque - at_rest)[leg])
    sole_acceleration = state.sole_jacobians[LEFT][:, leg] @ acceleration
    np.testing.assert_allclose(sole_acceleration, [-LegGains().swing_kd * 0.4, 0, 0, 0, 0, 0],
                               atol=1e-6)
    # A foot put back down damps its leg's joints: the pelvis moving over it, none.
    held = legs.foot_servo(carried, np.zeros(28), LEFT, sole, np.zeros(3), yaw, 0.0)
    np.testing.assert_allclose(held, at_rest, atol=1e-9)


def test_the_foot_servo_feeds_the_paths_acceleration_forward(
        standing: tuple[StandBehaviour, mujoco.MjData]) -> None:
    behaviour, data = standing
    legs = _legs(standing, LegGains(ik_damping_m=0.0))
    state = behaviour.estimator.estimate(data.qpos, np.zeros_like(data.qvel))
    leg = LEG_OF_FOOT[RIGHT]
    sole, zeros = state.sole_centres[RIGHT], np.zeros(28)
    turn = orientation_error(state.sole_rotations[RIGHT], np.eye(3))
    asked = np.array([2.0, -0.5, 1.0])
    torque = legs.foot_servo(state, zeros, RIGHT, sole, np.zeros(3), 0.0, 0.0, asked, 3.0)
    acceleration = np.linalg.solve(state.joint_inertia(leg), torque[leg])
    sole_acceleration = state.sole_jacobians[RIGHT][:, leg] @ acceleration
    # The placed sole is a little off level: the PD's part on top of what was asked.
    expected = np.concatenate([asked, LegGains().swing_kp * turn + [0.0, 0.0, 3.0]])
    np.testing.assert_allclose(sole_acceleration, expected, atol=1e-6)


def test_the_height_moves_by_a_smoothstep_whose_rate_is_its_derivative(
        standing: tuple[StandBehaviour, mujoco.MjData]) -> None:
    legs = _legs(standing)
    start, _ = legs.height(0.0)
    legs.move_height(start - 0.05, 1.0, 0.6)
    assert legs.height(1.0) == (start, 0.0)
    assert legs.height(1.6) == (pytest.approx(start - 0.05), 0.0)
    for t in (1.1, 1.3, 1.5):
        (before, _), (now, rate), (after, _) = (legs.height(t + dt) for dt in (-1e-6, 0, 1e-6))
        assert rate == pytest.approx((after - before) / 2e-6, rel=1e-5)
        assert start - 0.05 < now < start
    # Moved again halfway: on from where it is, without a jump.
    halfway, _ = legs.height(1.3)
    legs.move_height(start, 1.3, 0.6)
    assert legs.height(1.3) == (pytest.approx(halfway), 0.0)
    assert legs.height(1.9)[0] == pytest.approx(start)


@pytest.mark.parametrize('foot', [LEFT, RIGHT])
def test_a_stance_soles_clamp_is_the_polygon_clamp_of_its_rectangle(
        standing: tuple[StandBehaviour, mujoco.MjData], foot: int) -> None:
    behaviour, data = standing
    state = behaviour.estimator.estimate(data.qpos, data.qvel)
    half_length, half_width = behaviour.estimator.sole_half_size_m
    polygon = convex_hull(box_corners(state.sole_centres[foot], state.sole_rotations[foot],
                                      (half_length, half_width, 0.0))[:, 0:2])
    centre = state.sole_centres[foot][0:2]
    rng = np.random.default_rng(7)
    for offset in rng.uniform(-0.3, 0.3, size=(200, 2)):
        point = centre + offset
        # The placed sole tilts a little: its corners' projection is a rectangle only to
        # some microns.
        reach = (half_length - 0.015, half_width - 0.015)
        np.testing.assert_allclose(_clamp_to_sole(state, foot, reach, point),
                                   clamp_into(polygon, point, 0.015), atol=2e-5)


def test_a_foot_is_flat_down_on_the_surface_of_its_pose(
        standing: tuple[StandBehaviour, mujoco.MjData]) -> None:
    """Flat down is judged against the surface the foot should stand on: on the ground the
    standing soles are; on a pose 5 cm up, or one tilted 0.1 rad, they are not; and a foot's
    pose carries its sole's height."""
    behaviour, data = standing
    legs = _legs(standing)
    state = behaviour.estimator.estimate(data.qpos, data.qvel)
    pose = foot_pose(state, LEFT)
    assert pose.z_m == pytest.approx(0.0, abs=2e-3)
    assert legs.flat_down(state, LEFT, pose)
    assert not legs.flat_down(state, LEFT, Footstep(0, LEFT, pose.x_m, pose.y_m, pose.yaw_rad,
                                                    z_m=pose.z_m - 0.05))
    tilted = (float(np.sin(0.1)), 0.0, float(np.cos(0.1)))
    assert not legs.flat_down(state, LEFT, Footstep(0, LEFT, pose.x_m, pose.y_m, pose.yaw_rad,
                                                    z_m=pose.z_m, normal=tilted))


def test_a_foot_put_down_aims_just_below_its_poses_surface(
        standing: tuple[StandBehaviour, mujoco.MjData]) -> None:
    """The put-down servo's target is the pose's height less press_m: a pose 0.1 m up asks
    the sole up, one on the ground asks it (slightly) down."""
    behaviour, data = standing
    gains = LegGains(ik_damping_m=0.0)
    legs = _legs(standing, gains)
    state = behaviour.estimator.estimate(data.qpos, data.qvel)
    pose = foot_pose(state, RIGHT)
    leg = LEG_OF_FOOT[RIGHT]
    jacobian = state.sole_jacobians[RIGHT][:, leg]
    for height_m, sign in ((0.1, 1.0), (pose.z_m, -1.0)):
        target = Footstep(0, RIGHT, pose.x_m, pose.y_m, pose.yaw_rad, z_m=height_m)
        torque = legs.put_down_torque(state, np.zeros(28), RIGHT, target)
        acceleration = np.linalg.solve(state.joint_inertia(leg), torque[leg])
        assert sign * float((jacobian @ acceleration)[2]) > 0.0


def test_a_swing_foot_is_asked_just_below_its_steps_surface_by_its_paths_end(
        standing: tuple[StandBehaviour, mujoco.MjData]) -> None:
    """At its path's end a swing sole still at rest on its step is asked swing_press_m
    down (the servo lags; a path ending on the surface left the sole 1.5 cm up when the
    next step loaded it); without the press, nothing."""
    behaviour, data = standing
    gains = LegGains(ik_damping_m=0.0, swing_feedforward=False)
    assert gains.swing_press_m > 0.0
    legs = _legs(standing, gains)
    state = behaviour.estimator.estimate(data.qpos, np.zeros_like(data.qvel))
    pose = foot_pose(state, RIGHT)
    sole = state.sole_centres[RIGHT].copy()
    path = SwingPath(sole, sole.copy(), pose.yaw_rad, pose.yaw_rad, 0.63)
    leg = LEG_OF_FOOT[RIGHT]
    jacobian = state.sole_jacobians[RIGHT][:, leg]
    torque = legs.swing_torque(state, np.zeros(28), RIGHT, path, path.duration_s)
    acceleration = jacobian @ np.linalg.solve(state.joint_inertia(leg), torque[leg])
    assert float(acceleration[2]) == pytest.approx(-gains.swing_kp * gains.swing_press_m,
                                                   rel=1e-6)
    unpressed = LegGains(ik_damping_m=0.0, swing_feedforward=False, swing_press_m=0.0)
    torque = _legs(standing, unpressed).swing_torque(state, np.zeros(28), RIGHT, path,
                                                      path.duration_s)
    acceleration = jacobian @ np.linalg.solve(state.joint_inertia(leg), torque[leg])
    assert abs(float(acceleration[2])) < 1e-6
