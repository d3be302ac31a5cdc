"""The head's sensors without ROS: the frames' geometry, the laser's rays against known
shapes, its seeded noise, the spindle's ramp and limits, and its wire messages."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.sensors import (
    HEAD_HOKUYO_FRAME,
    HOKUYO,
    MAX_SPINDLE_SPEED,
    HeadSensors,
    HokuyoLaser,
    Spindle,
    frame_in_head,
    spindle_command,
)

#: A head 1.5 m over a floor, a 0.2 m box 2 m in front of it (its near face at 1.9 m), the
#: head's own box around the laser (which the rays must not see), a wall 40 m away (beyond
#: range_max) and a visual-only geom (group 1) 1 m to the left. The head's principal axes
#: are not its frame's (as Atlas's links'): the IMU must read the frame's.
WORLD = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="0 0 1"/>
    <geom name="box" type="box" size="0.1 1 3" pos="2 0 0"/>
    <geom name="far_wall" type="box" size="0.1 50 50" pos="-40 0 0"/>
    <geom name="ghost" type="box" size="0.1 0.1 3" pos="0 1 0" group="1"/>
    <body name="head" pos="0 0 1.5">
      <inertial pos="0 0 0" mass="1" fullinertia="0.01 0.02 0.03 0.005 0 0"/>
      <joint name="pitch" type="hinge" axis="0 1 0"/>
      <geom name="shell" type="box" size="0.2 0.2 0.2"/>
    </body>
  </worldbody>
</mujoco>
"""
SIGMA = HOKUYO.noise_m


@pytest.fixture()
def world() -> tuple[mujoco.MjModel, mujoco.MjData]:
    model = mujoco.MjModel.from_xml_string(WORLD)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def _ray_index(angle: float) -> int:
    return int(round((angle - HOKUYO.min_angle) / HOKUYO.angle_increment))


def test_the_head_frames_compose_as_the_urdf_places_them() -> None:
    """The laser frame 3 cm ahead and 1.5 cm over the spindle's origin, carried about the
    head's x axis by the spindle; the cameras' optical frames look forward, x right, y down."""
    origin, rotation = frame_in_head(HEAD_HOKUYO_FRAME, 0.0)
    np.testing.assert_allclose(origin, [-0.0146, 0.0, 0.103], atol=1e-12)
    np.testing.assert_allclose(rotation, np.eye(3), atol=1e-12)
    origin, rotation = frame_in_head(HEAD_HOKUYO_FRAME, math.pi / 2)
    np.testing.assert_allclose(origin, [-0.0146, -0.015, 0.088], atol=1e-12)
    np.testing.assert_allclose(rotation[:, 1], [0.0, 0.0, 1.0], atol=1e-12)  # scan plane: x-z
    for side, y in (('left', 0.035), ('right', -0.035)):
        origin, rotation = frame_in_head(f'{side}_camera_optical_frame')
        np.testing.assert_allclose(origin, [0.0, y, -0.002], atol=1e-12)
        np.testing.assert_allclose(rotation.T, [[0, -1, 0], [0, 0, -1], [1, 0, 0]], atol=1e-4)
    np.testing.assert_allclose(frame_in_head('head_imu_link')[0], [-0.0475, 0.035, 0.0])


def test_the_rays_hit_the_box_and_the_floor_at_their_distances(world) -> None:
    """Spindle 0: the scan plane is level at 1.603 m; straight ahead the box's face at
    1.9146 m from the laser, sideways nothing within 30 m (+inf), not the visual geom, the
    wall 40 m behind nor the head's own shell. Spindle pi/2: the plane is vertical, the
    ray straight down meets the floor 1.588 m below (the frame sits 1.5 cm aside)."""
    model, data = world
    laser = HokuyoLaser(model, seed=3)
    ranges = np.zeros(HOKUYO.samples, np.float32)
    laser.scan(data, 0.0, 1_000_000, ranges)
    ahead = _ray_index(0.0)
    assert abs(HOKUYO.angles()[ahead]) < 1e-2
    expected = (1.9 + 0.0146) / math.cos(HOKUYO.angles()[ahead])
    assert abs(ranges[ahead] - expected) < 5 * SIGMA
    box = laser.geom_id == model.geom('box').id
    assert box.sum() > 20 and np.all(np.abs(ranges[box] - 1.9146 / np.cos(
        HOKUYO.angles()[box])) < 5 * SIGMA)
    assert np.all(np.isposinf(ranges[~box]))
    laser.scan(data, math.pi / 2, 2_000_000, ranges)
    down = _ray_index(-math.pi / 2)
    assert laser.geom_id[down] == model.geom('floor').id
    assert abs(ranges[down] - (1.5 + 0.088)) < 5 * SIGMA


def test_the_noise_is_seeded_by_the_run_and_the_stamp(world) -> None:
    """The same seed and stamp give the same ranges bit for bit, whatever came before; a
    new stamp or seed other noise, of the URDF's standard deviation."""
    model, data = world
    first, again, later, other = (np.zeros(HOKUYO.samples, np.float32) for _ in range(4))
    laser = HokuyoLaser(model, seed=7)
    laser.scan(data, 0.0, 25_000_000, first)
    laser.scan(data, 0.0, 50_000_000, later)
    HokuyoLaser(model, seed=7).scan(data, 0.0, 25_000_000, again)
    HokuyoLaser(model, seed=8).scan(data, 0.0, 25_000_000, other)
    assert first.tobytes() == again.tobytes()
    hit = np.isfinite(first)
    assert not np.array_equal(first[hit], later[hit])
    assert not np.array_equal(first[hit], other[hit])
    true = laser.cast(data, 0.0)[hit]
    errors = np.concatenate([first[hit] - true, later[hit] - true, other[hit] - true])
    assert abs(np.std(errors) - SIGMA) < 0.25 * SIGMA


def test_the_spindle_ramps_to_its_speed_and_integrates_its_angle() -> None:
    """DRCSim's PID: 80 % of 50 RPM within 30 ms, within 1 % by 0.3 s; after 2 s the angle
    is the speed's integral less the ramp's lag, and joint_states' angle is in [-pi, pi)."""
    spindle = Spindle(0.001)
    spindle.command(MAX_SPINDLE_SPEED)
    for _ in range(30):
        spindle.step()
    assert spindle.velocity > 0.75 * MAX_SPINDLE_SPEED
    for _ in range(270):
        spindle.step()
    assert abs(spindle.velocity - MAX_SPINDLE_SPEED) < 0.02 * MAX_SPINDLE_SPEED
    for _ in range(1700):
        spindle.step()
    assert 2.0 * MAX_SPINDLE_SPEED - 0.5 < spindle.angle < 2.0 * MAX_SPINDLE_SPEED
    assert -math.pi <= spindle.normalized_angle < math.pi
    assert math.isclose(math.cos(spindle.normalized_angle), math.cos(spindle.angle))
    spindle.command(0.0)
    for _ in range(1000):
        spindle.step()
    assert abs(spindle.velocity) < 0.01


@pytest.mark.parametrize(('sent', 'taken', 'warned'), [
    (1.0, 1.0, False), (0.0, 0.0, False), (6.0, MAX_SPINDLE_SPEED, True),
    (-1.0, 0.0, True), (math.inf, MAX_SPINDLE_SPEED, True), (-math.inf, 0.0, True),
    (math.nan, None, True)])
def test_a_spindle_command_is_clamped_as_drcsim_did(sent: float, taken: float | None,
                                                    warned: bool) -> None:
    command = spindle_command(sent)
    assert command.speed == taken
    assert bool(command.warning) == warned


def test_the_head_sends_laserscan_and_joint_state_bytes(world) -> None:
    """genpy reads the wire bytes as the scan cast and the spindle's state."""
    laser_scan = pytest.importorskip('sensor_msgs.msg', reason='needs ROS: source ./env.sh')
    model, data = world
    head = HeadSensors(model, data, 0.001, seed=1)
    head.spindle.command(1.0)
    for _ in range(100):
        head.step()
    scan = laser_scan.LaserScan().deserialize(bytes(head.scan(2_500_000_000))[4:])
    assert scan.header.frame_id == HEAD_HOKUYO_FRAME and scan.header.stamp.secs == 2
    assert len(scan.ranges) == HOKUYO.samples and scan.range_max == pytest.approx(30.0)
    np.testing.assert_array_equal(np.array(scan.ranges, np.float32), head.scan_wire.ranges)
    state = laser_scan.JointState().deserialize(bytes(head.joint_state(1))[4:])
    assert state.name == ['hokuyo_joint']
    assert state.position[0] == pytest.approx(head.spindle.angle)
    assert 0.5 < state.velocity[0] < 1.0


def test_the_head_imu_reads_gravity_and_the_turn_at_its_point(world) -> None:
    """The head turning at 2 rad/s about y through its origin: the IMU, 4.75 cm behind and
    3.5 cm left of it, reads that rate, gravity's reaction up and the centripetal pull
    towards the axis (0.0475 m x 4 rad2/s2 forward)."""
    sensor_msgs = pytest.importorskip('sensor_msgs.msg', reason='needs ROS: source ./env.sh')
    model, data = world
    data.qvel[0] = 2.0
    mujoco.mj_forward(model, data)
    mujoco.mj_rnePostConstraint(model, data)  # Atlas's accelerometer has mj_step do it
    imu = sensor_msgs.Imu().deserialize(bytes(HeadSensors(model, data, 0.001).imu(7))[4:])
    assert imu.header.frame_id == 'head_imu_link'
    assert (imu.orientation.x, imu.orientation.w) == (0.0, 1.0)
    np.testing.assert_allclose([imu.angular_velocity.x, imu.angular_velocity.y,
                                imu.angular_velocity.z], [0.0, 2.0, 0.0], atol=1e-12)
    acceleration = imu.linear_acceleration
    np.testing.assert_allclose([acceleration.x, acceleration.y, acceleration.z],
                               [0.0475 * 4.0, 0.0, 9.81], atol=1e-9)


def test_a_heightfield_is_met_where_mujocos_own_rays_meet_it() -> None:
    """A heightfield is marched, not left to mj_multiRay (480 ms a scan on the course): over
    a bumpy one the spinning scans hit where MuJoCo's rays hit, within a centimetre but for a
    few grazing rays, and see the box on it as before."""
    xs = np.linspace(-1.0, 1.0, 81)
    bumps = 0.5 + 0.25 * np.sin(6.0 * xs)[None, :] * np.sin(5.0 * xs + 0.4)[:, None]
    elevation = ' '.join(f'{z:.6f}' for z in bumps.ravel())
    model = mujoco.MjModel.from_xml_string(f'''<mujoco><asset>
      <hfield name="bumps" nrow="81" ncol="81" size="20 20 1 0.1" elevation="{elevation}"/>
      </asset><worldbody>
      <geom name="ground" type="hfield" hfield="bumps" pos="1 -2 -0.5"/>
      <geom name="box" type="box" size="0.1 1 3" pos="2 0 0"/>
      <body name="head" pos="0 0 1.6"><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
        <joint name="pitch" type="hinge" axis="0 1 0"/>
        <geom name="shell" type="box" size="0.2 0.2 0.2"/></body>
      </worldbody></mujoco>''')
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    laser = HokuyoLaser(model)
    assert [field.geom for field in laser.heightfields] == [model.geom('ground').id]
    differences, disagreements, hits = [], 0, 0
    for spindle in np.linspace(0.0, 2.0 * math.pi, 12, endpoint=False):
        ours = laser.cast(data, spindle).copy()
        theirs, geoms = np.zeros(HOKUYO.samples), np.zeros(HOKUYO.samples, np.int32)
        mujoco.mj_multiRay(model, data, laser.origin, laser._world_rays.reshape(-1),
                           np.array([1, 0, 0, 0, 0, 0], np.uint8), 1, laser.head_body, geoms,
                           theirs, None, HOKUYO.samples, HOKUYO.range_max)
        theirs[theirs > HOKUYO.range_max] = -1.0
        hits += int((theirs >= 0.0).sum())
        disagreements += int(((theirs >= 0.0) != (ours >= 0.0)).sum())
        both = (theirs >= 0.0) & (ours >= 0.0)
        differences += list(np.abs(ours[both] - theirs[both]))
    assert hits > 4000
    assert disagreements <= 0.01 * hits
    assert np.percentile(differences, 99) < 0.02
