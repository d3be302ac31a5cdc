"""The MultiSense SL head's messages from a simulator's state: the laser's scan, the
spindle's joint state, hokuyo_link's transform and the head's IMU, as wire bytes
(msgs/wire.py).

One writer for the node's stepping loop (stepping/publication.py) and offline runs: the
spindle is stepped with each physics step whether or not anyone listens (its angle is the
same either way); a scan is cast only when one is due and wanted. A scan describes the
state at the start of the last step (the head's pose mj_step computed before integrating,
the spindle's angle before its step: stamp with `sim.state_time_ns`); the joint state and
the transform the spindle after it (stamp with `sim.sim_time_ns`, as /atlas/joint_states).
"""

from __future__ import annotations

import mujoco
import numpy as np

from tutorial_atlas_control.msgs import ImuWire, JointStateWire, LaserScanWire, TransformWire
from tutorial_atlas_control.sensors.frames import (
    HEAD_HOKUYO_FRAME,
    HEAD_IMU,
    HEAD_LINK,
    HOKUYO_JOINT,
    HOKUYO_LINK,
)
from tutorial_atlas_control.sensors.laser import HOKUYO, HokuyoLaser, LaserSpec
from tutorial_atlas_control.sensors.spindle import Spindle

__all__ = ['HeadSensors']


class HeadSensors:
    """The head's laser and spindle on one model and its MjData.

    Args:
        dt_s: the physics step (s): the spindle's.
        seed: the laser noise's seed (~sensor_seed).
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, dt_s: float,
                 seed: int = 0, spec: LaserSpec = HOKUYO) -> None:
        self.data = data
        self.spindle = Spindle(dt_s)
        self.laser = HokuyoLaser(model, spec, seed)
        # gazebo_ros_laser: time_increment 0 (one instant), scan_time one period.
        figures = (spec.min_angle, spec.max_angle, spec.angle_increment, 0.0,
                   1.0 / spec.rate_hz, spec.range_min, spec.range_max)
        self.scan_wire = LaserScanWire(HEAD_HOKUYO_FRAME, figures, spec.samples)
        self.joint_state_wire = JointStateWire((HOKUYO_JOINT.joint,))
        self.hokuyo_tf_wire = TransformWire(HEAD_LINK, HOKUYO_LINK)
        self.hokuyo_tf_wire.translation[:] = HOKUYO_JOINT.xyz_m
        self.model = model
        self.head_body = self.laser.head_body
        self.imu_wire = ImuWire(HEAD_IMU.child)
        self._imu_offset = np.array(HEAD_IMU.xyz_m)
        self._velocity = np.zeros(6)
        self._acceleration = np.zeros(6)
        self._scratch = np.zeros((3, 3))

    def step(self) -> None:
        """With each physics step (after it, before its messages): the spindle's step."""
        self.spindle.step()

    def scan(self, stamp_ns: int) -> bytearray:
        """/multisense_sl/laser/scan of the last step's start, stamped `stamp_ns`: the wire's
        buffer, valid until the next call."""
        wire = self.scan_wire
        self.laser.scan(self.data, self.spindle.previous_angle, stamp_ns, wire.ranges)
        return wire.stamped(stamp_ns)

    def joint_state(self, stamp_ns: int) -> bytearray:
        """/multisense_sl/joint_states: hokuyo_joint's angle (in [-pi, pi), as DRCSim's),
        speed and the PID's torque."""
        wire, spindle = self.joint_state_wire, self.spindle
        wire.position[0] = spindle.normalized_angle
        wire.velocity[0] = spindle.velocity
        wire.effort[0] = spindle.effort
        return wire.stamped(stamp_ns)

    def hokuyo_tf(self, stamp_ns: int) -> bytes:
        """head -> hokuyo_link on /tf (hokuyo_joint at its angle about x)."""
        half = 0.5 * self.spindle.angle
        rotation = self.hokuyo_tf_wire.rotation_xyzw
        rotation[0], rotation[3] = np.sin(half), np.cos(half)
        return self.hokuyo_tf_wire.to_bytes(stamp_ns)

    def imu(self, stamp_ns: int) -> bytearray:
        """/multisense_sl/imu at head_imu_link, of the last step's start (stamp with
        `sim.state_time_ns`, as /atlas/imu): the head's orientation in the world (x y z w),
        its angular velocity and the proper acceleration at the IMU's point (gravity's
        reaction included, 9.81 m/s2 up standing still), both in the IMU's frame (the
        head's axes). MuJoCo's accelerations of that step (its accelerometer's, computed
        by mj_step); no noise."""
        data, body, wire = self.data, self.head_body, self.imu_wire
        quat = data.xquat[body]
        wire.orientation_xyzw[:3] = quat[1:]
        wire.orientation_xyzw[3] = quat[0]
        velocity, acceleration = self._velocity, self._acceleration
        mujoco.mj_objectVelocity(self.model, data, mujoco.mjtObj.mjOBJ_XBODY, body, velocity, 1)
        mujoco.mj_objectAcceleration(self.model, data, mujoco.mjtObj.mjOBJ_XBODY, body,
                                     acceleration, 1)
        # At the IMU's point: a + alpha x r + omega x (omega x r) (MuJoCo's cross products:
        # numpy's cost ten times more per message).
        omega, r, scratch = velocity[:3], self._imu_offset, self._scratch
        wire.angular_velocity[:] = omega
        linear = wire.linear_acceleration
        linear[:] = acceleration[3:]
        mujoco.mju_cross(scratch[0], acceleration[:3], r)
        mujoco.mju_cross(scratch[1], omega, r)
        mujoco.mju_cross(scratch[2], omega, scratch[1])
        linear += scratch[0]
        linear += scratch[2]
        return wire.stamped(stamp_ns)
