"""sim_messages: the simulator's sensor messages hold the named MuJoCo sensors, in ROS's order."""

from __future__ import annotations

import struct
from pathlib import Path

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.msgs.atlas_command import decode_atlas_command, encode_atlas_command
from tutorial_atlas_control.sim import controller, model
from tutorial_atlas_control.sim.sim_messages import SimMessages
from tutorial_atlas_control.sim.simulator import AtlasSimulator, ControlMode
from tutorial_atlas_control.trajectories.schedule import (
    parse_trajectory_log_line,
    trajectory_log_line,
)

GAINS = Path(__file__).resolve().parents[3] / 'config' / 'atlas_controller.yaml'


@pytest.fixture(scope='module')
def stepped() -> AtlasSimulator:
    sim = AtlasSimulator(model.load_model(), controller.load_gains_yaml(GAINS))
    for _ in range(1200):  # past the pin: the robot sways, every sensor reads something
        sim.step()
    return sim


def test_imu_and_contacts_are_the_named_sensors(stepped: AtlasSimulator) -> None:
    messages = SimMessages(stepped)
    messages.fill_plan(('imu', 'l', 'r'))()
    sensor = {name: stepped.data.sensor(name).data.copy() for name in (
        'imu_orientation', 'imu_angular_velocity', 'imu_linear_acceleration',
        'l_foot_force', 'l_foot_torque', 'r_foot_force', 'r_foot_torque')}
    imu = messages.imu_wire
    w, x, y, z = sensor['imu_orientation']
    assert np.array_equal(imu.orientation_xyzw, [x, y, z, w])
    assert np.array_equal(imu.angular_velocity, sensor['imu_angular_velocity'])
    assert np.array_equal(imu.linear_acceleration, sensor['imu_linear_acceleration'])
    assert np.count_nonzero(imu.floats) == 10  # covariances stay 0
    for side in 'lr':
        contact = messages.contact_wires[side]
        assert np.array_equal(contact.force, sensor[f'{side}_foot_force'])
        assert np.array_equal(contact.torque, sensor[f'{side}_foot_torque'])
    assert abs(messages.contact_wires['l'].force[2]) > 1.0  # the feet carry the robot


def test_joint_state_and_odometry(stepped: AtlasSimulator) -> None:
    messages = SimMessages(stepped)
    messages.fill_plan(('joint_state',))()
    messages.fill_odometry()
    state = messages.joint_state_wire
    assert np.array_equal(state.position, stepped.joint_positions())
    assert np.array_equal(state.velocity, stepped.joint_velocities())
    assert np.array_equal(state.effort, stepped.torque_nm)
    odom = messages.odometry_wire
    body = stepped.atlas.pelvis_body_id
    assert np.array_equal(odom.position, stepped.data.xpos[body])
    w, x, y, z = stepped.data.xquat[body]
    assert np.array_equal(odom.orientation_xyzw, [x, y, z, w])


def test_trajectory_log_line_round_trip() -> None:
    line = trajectory_log_line('/a b/Traj "2".yaml', 'touch down')
    assert line.startswith('trajectory: {')
    assert parse_trajectory_log_line(line) == {'file': '/a b/Traj "2".yaml', 'name': 'touch down'}
    for other in ('playing trajectory x', 'trajectory: not json', 'trajectory: {"file": 1}',
                  'trajectory: ["a"]'):
        assert parse_trajectory_log_line(other) is None, other


# -- DRCSim's AtlasState, ForceTorqueSensors and debug foot contacts ---------------------

#: Standing 3 s (2 s after the pin is released): the robot is still, on both feet.
STANDING_STEPS = 3000
GRAVITY_MPS2 = 9.81


@pytest.fixture(scope='module')
def standing() -> AtlasSimulator:
    sim = AtlasSimulator(model.load_model(), controller.load_gains_yaml(GAINS))
    for _ in range(STANDING_STEPS):
        sim.step()
    return sim


def _mass_kg(sim: AtlasSimulator, body: str) -> float:
    return float(sim.model.body_mass[sim.model.body(body).id])


def test_standing_ankles_carry_the_robot_as_drcsim_reports_it(standing: AtlasSimulator) -> None:
    """Fz of each ankle is the leg's push on the foot: about -(weight above the feet) / 2,
    i.e. -430 N; DRCSim's other three components are 0."""
    messages = SimMessages(standing)
    assert messages.fill_atlas_state()
    state = messages.atlas_state_wire
    total_kg = float(standing.model.body_subtreemass[standing.atlas.pelvis_body_id])
    above_feet_n = (total_kg - _mass_kg(standing, 'l_foot') - _mass_kg(standing, 'r_foot')) \
        * GRAVITY_MPS2
    l_foot, r_foot = state.wrenches['l_foot'], state.wrenches['r_foot']
    for foot in (l_foot, r_foot):
        assert -460.0 < foot[2] < -400.0
        assert foot[0] == foot[1] == foot[5] == 0.0  # Fx, Fy, Mz: not reported, as DRCSim
        assert abs(foot[3]) < 20.0 and abs(foot[4]) < 20.0  # N m: the feet are flat
    assert l_foot[2] + r_foot[2] == pytest.approx(-above_feet_n, rel=0.02)
    # They are the ankle force-torque sensors' readings (foot frame, at the ankle joint).
    for side, foot in (('l', l_foot), ('r', r_foot)):
        assert foot[2] == standing.data.sensor(f'{side}_foot_force').data[2]
        assert np.array_equal(foot[3:5], standing.data.sensor(f'{side}_foot_torque').data[:2])


def test_standing_imu_reads_gravity_up(standing: AtlasSimulator) -> None:
    messages = SimMessages(standing)
    messages.fill_atlas_state()
    state = messages.atlas_state_wire
    assert state.linear_acceleration[2] == pytest.approx(GRAVITY_MPS2, abs=0.05)
    assert np.abs(state.linear_acceleration[:2]).max() < 0.5
    assert np.abs(state.angular_velocity).max() < 0.05
    assert state.orientation_xyzw[3] == pytest.approx(1.0, abs=0.01)  # upright
    messages.fill_plan(('imu',))()
    assert np.array_equal(state.floats[:10], np.r_[messages.imu_wire.orientation_xyzw,
                                                   messages.imu_wire.angular_velocity,
                                                   messages.imu_wire.linear_acceleration])


def test_atlas_state_joints_gains_and_k_effort(standing: AtlasSimulator) -> None:
    """The joint fields as /atlas/joint_states (in float32), the gains of the command the
    law applied, k_effort from the simulator's hook."""
    messages = SimMessages(standing)
    messages.fill_atlas_state()
    arrays = messages.atlas_state_wire.arrays
    f32 = np.float32
    assert np.array_equal(arrays['position'], standing.joint_positions().astype(f32))
    assert np.array_equal(arrays['velocity'], standing.joint_velocities().astype(f32))
    assert np.array_equal(arrays['effort'], standing.torque_nm.astype(f32))
    gains = controller.load_gains_yaml(GAINS)
    assert np.array_equal(arrays['kp_position'], gains.p.astype(f32))  # Stand: the params
    assert np.array_equal(arrays['kd_position'], gains.d.astype(f32))
    assert np.array_equal(arrays['i_effort_max'], gains.i_clamp.astype(f32))
    assert np.array_equal(arrays['kp_velocity'], np.zeros(len(gains.p), f32))
    assert set(messages.atlas_state_wire.k_effort) == {255}
    # An AtlasCommand handing neck_ay to its PID at 7/255 in Stand: that PID's gains and k.
    k_effort = [0] * len(gains.p)
    k_effort[3] = 7
    command = decode_atlas_command(encode_atlas_command(
        0, {'k_effort': k_effort, 'kp_position': [5.0] * len(gains.p)}))
    try:
        standing.receive_updates([command.update])
        messages.fill_atlas_state()
        assert list(messages.atlas_state_wire.k_effort) == k_effort
        assert set(arrays['kp_position']) == {5.0}
    finally:
        standing.commands.user_command = None


def test_hands_carry_what_the_last_wrist_joint_transmits(standing: AtlasSimulator) -> None:
    """The hand link hangs on l_arm_mwx / r_arm_mwx: the joint's force holds its weight."""
    messages = SimMessages(standing)
    messages.fill_force_torque_sensors()
    wrenches = messages.force_torque_wire.wrenches
    for side in 'lr':
        hand = standing.model.body(f'{side}_hand').id
        weight_n = float(standing.model.body_subtreemass[hand]) * GRAVITY_MPS2
        force_world = standing.data.xmat[hand].reshape(3, 3) @ wrenches[f'{side}_hand'][:3]
        assert force_world == pytest.approx([0.0, 0.0, weight_n], abs=0.05 * weight_n)
    # The same transformation reads the ankle sensors exactly.
    for side in 'lr':
        foot = standing.model.body(f'{side}_foot').id
        wrench = messages.body_wrench(standing.data.cfrc_int[foot], f'{side}_foot')
        assert np.allclose(wrench, np.r_[standing.data.sensor(f'{side}_foot_force').data,
                                         standing.data.sensor(f'{side}_foot_torque').data],
                           rtol=1e-12, atol=1e-9)
    messages.fill_atlas_state()
    assert np.array_equal(messages.atlas_state_wire.wrench_floats,
                          messages.force_torque_wire.floats)


def test_debug_foot_contacts_are_the_ground_push_and_stop_in_the_air(
        standing: AtlasSimulator) -> None:
    messages = SimMessages(standing)
    total_n = float(standing.model.body_subtreemass[standing.atlas.pelvis_body_id]) \
        * GRAVITY_MPS2
    assert messages.fill_debug_contact('l') and messages.fill_debug_contact('r')
    l_force = messages.debug_contact_wires['l'].force
    r_force = messages.debug_contact_wires['r'].force
    assert l_force[2] > 400.0 and r_force[2] > 400.0  # up on the foot, foot frame
    assert l_force[2] + r_force[2] == pytest.approx(total_n, rel=0.02)
    airborne = AtlasSimulator(model.load_model(), controller.load_gains_yaml(GAINS))
    airborne.data.qpos[2] += 1.0  # the free joint's z: a metre above the ground
    mujoco.mj_forward(airborne.model, airborne.data)
    assert not SimMessages(airborne).fill_debug_contact('l')


def _frame_id(wire: object) -> str:
    """The header's frame_id of a stamped wire message (after length, seq and stamp)."""
    (length,) = struct.unpack_from('<I', wire.buf, 16)
    return bytes(wire.buf[20:20 + length]).decode()


def test_the_ports_imu_and_ankle_topics_mean_gravity_and_the_weight(
        standing: AtlasSimulator) -> None:
    """/atlas/imu and /atlas/{l,r}_foot_contact (the port's own) against physics, standing.

    The accelerometer reads the ground's push, +g up; the legs push each foot down with half
    the weight above the ankles (the model's masses less the feet's), docs/ros_interface.md's
    "Fz about -430 N", in the foot frame about the ankle; horizontally the two pushes cancel
    (the robot is still). Tolerances: 2 % of the weight (the robot sways slowly), as above.
    """
    gravity_mps2 = -float(standing.model.opt.gravity[2])
    messages = SimMessages(standing)
    messages.fill_plan(('imu', 'l', 'r'))()
    imu = messages.imu_wire
    assert imu.linear_acceleration[2] == pytest.approx(gravity_mps2, abs=0.05)
    assert np.abs(imu.linear_acceleration[:2]).max() < 0.5
    assert np.abs(imu.angular_velocity).max() < 0.05
    assert abs(imu.orientation_xyzw[3]) == pytest.approx(1.0, abs=0.01)  # upright
    total_kg = float(standing.model.body_subtreemass[standing.atlas.pelvis_body_id])
    above_ankles_n = (total_kg - _mass_kg(standing, 'l_foot') - _mass_kg(standing, 'r_foot')) \
        * gravity_mps2
    pushes_world = np.zeros(3)
    for side in 'lr':
        contact = messages.contact_wires[side]
        assert _frame_id(contact) == f'{side}_foot'
        assert contact.force[2] == pytest.approx(-above_ankles_n / 2, rel=0.02)  # down: < 0
        assert np.abs(contact.torque[:2]).max() < 20.0  # N m about the ankle: flat feet
        foot = standing.model.body(f'{side}_foot').id
        pushes_world += standing.data.xmat[foot].reshape(3, 3) @ contact.force
    assert pushes_world == pytest.approx([0.0, 0.0, -above_ankles_n], abs=0.02 * above_ankles_n)


def _atlas_state_as_before(messages: SimMessages) -> bytes:
    """AtlasState filled as the node did before its fill was trimmed: gains row by row from
    the PID command, each hand's wrench through MjData's attributes read afresh."""
    sim, data = messages.sim, messages.sim.data
    messages._atlas_state_plan()
    rows, command = messages._joint_rows, sim.commands.pid_command()
    for row, name in enumerate(('kp_position', 'ki_position', 'kd_position', 'kp_velocity',
                                'i_effort_min', 'i_effort_max'), start=3):
        rows[row] = getattr(command, name)
    state = messages.atlas_state_wire
    state.joints[:] = rows
    state.k_effort[:] = sim.active_k_effort()
    spatial = np.zeros(6)
    for field, body_name in (('l_hand', 'l_hand'), ('r_hand', 'r_hand')):
        body = sim.model.body(body_name).id
        mujoco.mju_transformSpatial(spatial, data.cfrc_int[body], 1, data.xpos[body],
                                    data.subtree_com[sim.model.body_rootid[body]],
                                    data.xmat[body])
        wrench = np.r_[spatial[3:], spatial[:3]]
        state.wrenches[field][:] = wrench
    return bytes(state.stamped(0))[16:]  # after the length prefix and the header's seq


def test_atlas_state_bytes_equal_the_untrimmed_fill_step_by_step() -> None:
    """A controller's full AtlasCommands at every step (the gains one block), then Stand
    (the hold's command, no block): the wire's bytes equal the field-by-field fill's."""
    sim = AtlasSimulator(model.load_model(), controller.load_gains_yaml(GAINS))
    for _ in range(1100):
        sim.step()
    messages = SimMessages(sim)
    rng = np.random.default_rng(5)
    n = len(sim.torque_nm)
    gains = {'kp_position': rng.uniform(50, 200, n), 'ki_position': rng.uniform(0, 1, n),
             'kd_position': rng.uniform(1, 5, n), 'kp_velocity': rng.uniform(0, 2, n),
             'i_effort_min': -rng.uniform(0, 5, n), 'i_effort_max': rng.uniform(0, 5, n),
             'k_effort': rng.integers(0, 256, n)}
    for step in range(60):
        if step == 30:
            sim.set_mode(ControlMode.STAND)
        elif step < 30:
            targets = sim.joint_positions() + rng.normal(0.0, 0.01, n)
            update = decode_atlas_command(encode_atlas_command(
                sim.sim_time_ns, {'position': targets, **gains})).update
            sim.receive_updates([update])
        sim.step()
        blocked = sim.commands.pid_command().rows_block() is not None
        assert blocked == (step < 30)  # both ways of filling the gains are taken
        messages.fill_atlas_state()
        trimmed = bytes(messages.atlas_state_wire.stamped(0))[16:]
        assert trimmed == _atlas_state_as_before(messages), f'step {step}'


def test_render_state_is_the_whole_qpos_a_renderer_places_the_head_with(
        standing: AtlasSimulator) -> None:
    """/atlas/render_state, decoded as sensor_msgs/JointState, puts the cameras' copy of the
    model in the simulated pose: its head where the simulator's head is."""
    from sensor_msgs.msg import JointState

    from tutorial_atlas_control.stereo import StereoRenderer, camera_model

    messages = SimMessages(standing)
    wire, fill = messages.on_demand['render_state']
    assert fill()
    msg = JointState()
    msg.deserialize(bytes(wire.stamped(standing.sim_time_ns))[4:])
    assert msg.header.stamp.to_nsec() == standing.sim_time_ns
    assert len(msg.name) == len(msg.velocity) == len(msg.effort) == 0
    posed = mujoco.MjData(standing.model)  # the simulated model at the state sent
    posed.qpos[:] = standing.data.qpos
    mujoco.mj_kinematics(standing.model, posed)
    with StereoRenderer(camera_model(str(model.MODEL_PATH))) as renderer:
        renderer.set_state(np.asarray(msg.position))
        head = renderer.data.xpos[renderer.model.body('head').id]
        assert np.allclose(head, posed.xpos[standing.model.body('head').id], atol=1e-12)
        assert head[2] > 1.5  # standing
