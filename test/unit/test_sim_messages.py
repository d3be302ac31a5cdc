"""sim_messages: the simulator's sensor messages hold the named MuJoCo sensors, in ROS's order."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tutorial_atlas_control.msgs.sim_messages import SimMessages
from tutorial_atlas_control.sim import controller, model
from tutorial_atlas_control.sim.simulator import AtlasSimulator
from tutorial_atlas_control.trajectories.schedule import (
    parse_trajectory_log_line,
    trajectory_log_line,
)

GAINS = Path(__file__).resolve().parents[2] / 'config' / 'atlas_controller.yaml'


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
