"""The simulator's sensor messages, serialized from an AtlasSimulator's state.

What each 1 kHz message holds (which array, which time, which quaternion order) is
decided once, here, for both writers of those messages: the ROS node (sim_node.py),
which sends the bytes over TCPROS, and offline runs (offline_run.py), which write them
to a bag. The bytes come from wire.py's pre-laid-out messages: a step copies numbers in
and stamps the header; nothing is serialized field by field.
"""

from __future__ import annotations

import mujoco
import numpy as np

from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.simulator import AtlasSimulator
from tutorial_atlas_control.topics import PELVIS_FRAME, WORLD_FRAME
from tutorial_atlas_control.wire import ImuWire, JointStateWire, OdometryWire, WrenchStampedWire

__all__ = ['TCPROS_PREFIX_BYTES', 'SimMessages']

#: wire.py's messages start with TCPROS's 4-byte length; a bag record holds what follows.
TCPROS_PREFIX_BYTES = 4

#: The MuJoCo sensors the messages read, by name in the model.
SENSOR_NAMES = ('imu_orientation', 'imu_angular_velocity', 'imu_linear_acceleration',
                'l_foot_force', 'l_foot_torque', 'r_foot_force', 'r_foot_torque')


class SimMessages:
    """One simulator's /atlas/joint_states, /ground_truth_odom, /atlas/imu and foot contacts.

    Each method fills its message from the simulator's current state and returns it
    serialized with the TCPROS length prefix (strip TCPROS_PREFIX_BYTES for a bag).
    The messages keep their own Header.seq counters.
    """

    def __init__(self, sim: AtlasSimulator) -> None:
        self.sim = sim
        self._joint_state = JointStateWire(JOINT_NAMES)
        self._odom = OdometryWire(WORLD_FRAME, PELVIS_FRAME)
        self._imu = ImuWire(PELVIS_FRAME)
        self._contacts = {side: WrenchStampedWire(f'{side}_foot') for side in 'lr'}
        self._sensors = {name: sim.data.sensor(name).data for name in SENSOR_NAMES}
        self._pelvis_velocity = np.zeros(6)

    def joint_state(self, stamp_ns: int) -> bytes:
        """Joint positions and velocities after the last step; effort = the torque it applied.

        Stamp it with the sim time after the step (`sim.sim_time_ns`).
        """
        sim, msg = self.sim, self._joint_state
        np.take(sim.data.qpos, sim.atlas.qpos_adr, out=msg.position)
        np.take(sim.data.qvel, sim.atlas.dof_adr, out=msg.velocity)
        msg.effort[:] = sim.torque_nm
        return msg.to_bytes(stamp_ns)

    def odometry(self, stamp_ns: int) -> bytes:
        """Pelvis pose and world-frame twist, as Gazebo's p3d plugin reported them.

        Body poses are computed before mj_step integrates: stamp with `sim.state_time_ns`.
        """
        sim, odom = self.sim, self._odom
        body = sim.atlas.pelvis_body_id
        odom.position[:] = sim.data.xpos[body]
        w, x, y, z = sim.data.xquat[body]
        odom.orientation_xyzw[:] = (x, y, z, w)
        mujoco.mj_objectVelocity(sim.model, sim.data, mujoco.mjtObj.mjOBJ_BODY, body,
                                 self._pelvis_velocity, 0)
        odom.angular[:] = self._pelvis_velocity[:3]
        odom.linear[:] = self._pelvis_velocity[3:]
        return odom.to_bytes(stamp_ns)

    def imu(self, stamp_ns: int) -> bytes:
        """The pelvis IMU (sensor readings: stamp with `sim.state_time_ns`)."""
        imu, sensors = self._imu, self._sensors
        w, x, y, z = sensors['imu_orientation']
        imu.orientation_xyzw[:] = (x, y, z, w)
        imu.angular_velocity[:] = sensors['imu_angular_velocity']
        imu.linear_acceleration[:] = sensors['imu_linear_acceleration']
        return imu.to_bytes(stamp_ns)

    def foot_contact(self, side: str, stamp_ns: int) -> bytes:
        """The `side` ('l' or 'r') foot's force/torque sensor (stamp with `sim.state_time_ns`)."""
        msg, sensors = self._contacts[side], self._sensors
        msg.force[:] = sensors[f'{side}_foot_force']
        msg.torque[:] = sensors[f'{side}_foot_torque']
        return msg.to_bytes(stamp_ns)
