"""The simulator's sensor messages, serialized from an AtlasSimulator's state.

What each 1 kHz message holds (which array, which time, which quaternion order) is
decided once, here, for both writers of those messages: the stepping loop
(stepping/publication.py), which sends the bytes over TCPROS, and offline runs
(offline/player.py), which write them to a bag. The bytes come from wire.py's
pre-laid-out messages: a step copies numbers in and stamps the header; nothing is
serialized field by field.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from tutorial_atlas_control.command import LAW_FIELDS
from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.msgs import (
    WRENCH_FLOATS,
    AtlasStateWire,
    ForceTorqueSensorsWire,
    ImuWire,
    JointStateWire,
    OdometryWire,
    PositionsWire,
    StampedWire,
    TransformsWire,
    TransformWire,
    WrenchStampedWire,
)
from tutorial_atlas_control.sim.copy_plan import Copy, CopyPlan
from tutorial_atlas_control.sim.link_transforms import LinkTransforms
from tutorial_atlas_control.sim.simulator import AtlasSimulator
from tutorial_atlas_control.topics import PELVIS_FRAME, WORLD_FRAME

__all__ = ['DRCSIM_FOOT_COMPONENTS', 'HAND_BODIES', 'TCPROS_PREFIX_BYTES', 'SensorSelection',
           'SimMessages']

#: wire.py's messages start with TCPROS's 4-byte length; a bag record holds what follows.
TCPROS_PREFIX_BYTES = 4

#: The MuJoCo sensors the messages read, by name in the model.
SENSOR_NAMES = ('imu_orientation', 'imu_angular_velocity', 'imu_linear_acceleration',
                'l_foot_force', 'l_foot_torque', 'r_foot_force', 'r_foot_torque')


#: What DRCSim 2.5.2 reported of each ankle's wrench in AtlasState and ForceTorqueSensors
#: (Fz, Mx, My: the components of Atlas' 3-axis foot sensors), as indices into a wrench's
#: six floats (force x y z, torque x y z); the other three stay 0, as in DRCSim.
DRCSIM_FOOT_COMPONENTS = (2, 3, 4)
#: The body after each last wrist joint (l_arm_mwx, r_arm_mwx): DRCSim's hand wrenches are
#: what that joint transmits to it (the model has the wrist link, no hand beyond it).
HAND_BODIES = {'l_hand': 'l_hand', 'r_hand': 'r_hand'}
#: The feet, whose contact wrench /atlas/debug/{l,r}_foot_contact carry.
FOOT_BODIES = {'l': 'l_foot', 'r': 'r_foot'}


#: AtlasState's gain rows (its joint arrays 3..8), which are LAW_FIELDS' rows 3..8 too.
_GAIN_ROWS = slice(3, 9)
assert AtlasStateWire.FIELDS[_GAIN_ROWS] == LAW_FIELDS[_GAIN_ROWS]


def _float_offset(message: StampedWire) -> int:
    """Byte offset of `message`'s float block in its serialization (without TCPROS prefix)."""
    base = np.frombuffer(message.buf, dtype=np.uint8).ctypes.data
    return message.floats.ctypes.data - base - TCPROS_PREFIX_BYTES


@dataclass(frozen=True)
class SensorSelection:
    """A message whose floats are a fixed selection of `data.sensordata`:
    floats[to] = sensordata[source].

    Attributes:
        wire: the message.
        float_offset: byte offset of its float block in its serialization (without the
            TCPROS prefix).
    """

    wire: StampedWire
    float_offset: int
    to: np.ndarray
    source: np.ndarray


class SimMessages:
    """One simulator's /atlas/joint_states, /ground_truth_odom, /atlas/imu and foot contacts.

    The per-step messages (joint state, IMU, feet) are filled through fill_plan; odometry
    and the pelvis transform by their fill_* methods, which odometry() and pelvis_tf() also
    stamp and return with the TCPROS length prefix. The IMU and contact messages are a
    fixed selection of `data.sensordata` (sensor_selection), so a writer that keeps
    sensordata per step can build many messages at once (offline/player.py).
    """

    #: The per-step messages that are a selection of sensordata (sensor_selection).
    SENSOR_MESSAGES = ('imu', 'l', 'r')

    def __init__(self, sim: AtlasSimulator) -> None:
        self.sim = sim
        self.joint_state_wire = JointStateWire(JOINT_NAMES)
        self.odometry_wire = OdometryWire(WORLD_FRAME, PELVIS_FRAME)
        self.imu_wire = ImuWire(PELVIS_FRAME)
        self.contact_wires = {side: WrenchStampedWire(f'{side}_foot') for side in 'lr'}
        self.pelvis_tf_wire = TransformWire(WORLD_FRAME, PELVIS_FRAME)
        self.links: LinkTransforms | None = None  # see use_link_transforms
        model = sim.model
        adr = {name: int(model.sensor_adr[model.sensor(name).id]) for name in SENSOR_NAMES}
        orientation = adr['imu_orientation']
        # Orientation as ROS orders it (x y z w) from MuJoCo's (w x y z); covariances stay 0.
        self._imu_map = (
            np.r_[0:4, 13:16, 25:28],
            np.r_[orientation + 1:orientation + 4, orientation,
                  adr['imu_angular_velocity'] + np.arange(3),
                  adr['imu_linear_acceleration'] + np.arange(3)])
        self._contact_maps = {
            side: (np.arange(6), np.r_[adr[f'{side}_foot_force'] + np.arange(3),
                                       adr[f'{side}_foot_torque'] + np.arange(3)])
            for side in 'lr'}
        self._pelvis_velocity = np.zeros(6)
        # The per-step messages' numbers as CopyPlan copies (dst, to, src, from), by name.
        # joint_state: positions and velocities after the step, effort = the torque it
        # applied (stamp with `sim.sim_time_ns`); imu, l and r (the feet): sensor readings,
        # computed before mj_step integrates (stamp with `sim.state_time_ns`).
        data, joints = sim.data, np.arange(len(JOINT_NAMES))
        wire = self.joint_state_wire
        self._copies: dict[str, list[Copy]] = {
            'joint_state': [(wire.position, joints, data.qpos, sim.atlas.qpos_adr),
                            (wire.velocity, joints, data.qvel, sim.atlas.dof_adr),
                            (wire.effort, joints, sim.torque_nm, joints)],
            'imu': [(self.imu_wire.floats, self._imu_map[0], data.sensordata, self._imu_map[1])],
            **{side: [(self.contact_wires[side].floats, to, data.sensordata, source)]
               for side, (to, source) in self._contact_maps.items()}}
        #: The wire message of each per-step message, by the same names.
        self.step_wires: dict[str, StampedWire] = {
            'joint_state': self.joint_state_wire, 'imu': self.imu_wire, **self.contact_wires}
        self._init_drcsim_messages(adr)

    # -- DRCSim's AtlasState, ForceTorqueSensors and debug foot contacts -----------------
    def _init_drcsim_messages(self, adr: dict[str, int]) -> None:
        """The messages filled only when someone listens (see fill_on_demand)."""
        sim, data = self.sim, self.sim.data
        model = sim.model
        self.atlas_state_wire = AtlasStateWire(len(JOINT_NAMES))
        self.force_torque_wire = ForceTorqueSensorsWire()
        self.debug_contact_wires = {side: WrenchStampedWire(f'{side}_foot') for side in 'lr'}
        self.render_state_wire = PositionsWire(model.nq)
        self._body = {name: int(model.body(name).id)
                      for name in (*HAND_BODIES.values(), *FOOT_BODIES.values())}
        self._root = {name: int(model.body_rootid[body]) for name, body in self._body.items()}
        # Each body's frame in MjData (position, its subtree's com, rotation): views made
        # once (MjData's arrays are never reallocated), not three attribute reads a wrench.
        self._frames = {name: (data.xpos[body], data.subtree_com[self._root[name]],
                               data.xmat[body]) for name, body in self._body.items()}
        #: (wrench name, what the last wrist joint transmits to the hand, its body's name).
        self._hands = tuple((field, data.cfrc_int[self._body[body]], body)
                            for field, body in HAND_BODIES.items())
        self._spatial = np.zeros(6)  # MuJoCo's (torque, force) at a new point
        self._wrench = np.zeros(WRENCH_FLOATS)  # (force, torque) in a body frame
        # AtlasState's float32 joint rows in float64 first: position, velocity, effort
        # by plan; the gains of the active command at each fill.
        self._joint_rows = np.zeros(self.atlas_state_wire.joints.shape)
        joints = np.arange(len(JOINT_NAMES))
        feet = {side: np.r_[adr[f'{side}_foot_force'] + 2, adr[f'{side}_foot_torque'],
                            adr[f'{side}_foot_torque'] + 1] for side in 'lr'}
        state, torque = self.atlas_state_wire, self.force_torque_wire
        foot_at = np.array(DRCSIM_FOOT_COMPONENTS)
        self._atlas_state_plan = CopyPlan([
            (self._joint_rows[0], joints, data.qpos, sim.atlas.qpos_adr),
            (self._joint_rows[1], joints, data.qvel, sim.atlas.dof_adr),
            (self._joint_rows[2], joints, sim.torque_nm, joints),
            (state.floats, np.arange(10), data.sensordata, self._imu_map[1]),
            *((state.wrench_floats, k * WRENCH_FLOATS + foot_at, data.sensordata, feet[side])
              for k, side in enumerate('lr'))])
        self._force_torque_plan = CopyPlan([
            (torque.floats, k * WRENCH_FLOATS + foot_at, data.sensordata, feet[side])
            for k, side in enumerate('lr')])
        #: Name -> (wire message, fill: True when the message is to be sent).
        self.on_demand: dict[str, tuple[StampedWire, Callable[[], bool]]] = {
            'atlas_state': (state, self.fill_atlas_state),
            'force_torque_sensors': (torque, self.fill_force_torque_sensors),
            'debug_l': (self.debug_contact_wires['l'], lambda: self.fill_debug_contact('l')),
            'debug_r': (self.debug_contact_wires['r'], lambda: self.fill_debug_contact('r')),
            'render_state': (self.render_state_wire, self.fill_render_state),
        }

    def body_wrench(self, spatial: np.ndarray, body_name: str) -> np.ndarray:
        """A MuJoCo com-based spatial force (cfrc_int or cfrc_ext of the body) as a wrench in
        the body's frame about its origin: (force x y z, torque x y z), N and N m.

        The force sensors' own transformation (a site at the body origin reads the same).
        The result is a scratch array, valid until the next call.
        """
        wrench = self._wrench
        self._body_wrench_into(wrench, spatial, body_name)
        return wrench

    def _body_wrench_into(self, wrench: np.ndarray, spatial: np.ndarray, body_name: str) -> None:
        """body_wrench written into `wrench` (6 floats, of any float type)."""
        position, com, rotation = self._frames[body_name]
        # Moved to the body origin and rotated into the body frame (xmat: body to world).
        mujoco.mju_transformSpatial(self._spatial, spatial, 1, position, com, rotation)
        moved = self._spatial
        wrench[:3] = moved[3:]
        wrench[3:] = moved[:3]

    def _fill_hands(self, wrenches: dict[str, np.ndarray]) -> None:
        """What each last wrist joint transmits to the hand link (parent on child)."""
        for field, interaction, body in self._hands:
            self._body_wrench_into(wrenches[field], interaction, body)

    def fill_atlas_state(self) -> bool:
        """AtlasState: joints after the step (as joint_state), the active gains and
        k_effort, IMU and wrenches from the step's start. Always sent."""
        self._atlas_state_plan()
        rows, command = self._joint_rows, self.sim.commands.pid_command()
        block = command.rows_block()
        if block is not None:  # the gains are rows 3..8 of both, in the same order
            rows[_GAIN_ROWS] = block[_GAIN_ROWS]
        else:
            rows[3] = command.kp_position
            rows[4] = command.ki_position
            rows[5] = command.kd_position
            rows[6] = command.kp_velocity
            rows[7] = command.i_effort_min
            rows[8] = command.i_effort_max
        state = self.atlas_state_wire
        state.joints[:] = rows
        state.k_effort[:] = self.sim.active_k_effort()
        self._fill_hands(state.wrenches)
        return True

    def fill_force_torque_sensors(self) -> bool:
        """ForceTorqueSensors: ankles (Fz, Mx, My) and wrists. Always sent."""
        self._force_torque_plan()
        self._fill_hands(self.force_torque_wire.wrenches)
        return True

    def fill_render_state(self) -> bool:
        """The world's whole qpos after the step, for the camera node. Always sent."""
        self.render_state_wire.positions[:] = self.sim.data.qpos
        return True

    def fill_debug_contact(self, side: str) -> bool:
        """The ground's (or anything's) push on a foot, in the foot frame about the ankle;
        False, nothing to send, while nothing touches it (DRCSim sent only on contact)."""
        body = FOOT_BODIES[side]
        external = self.sim.data.cfrc_ext[self._body[body]]
        if not external.any():
            return False
        self.debug_contact_wires[side].floats[:] = self.body_wrench(external, body)
        return True

    def sensor_selection(self, name: str) -> SensorSelection:
        """How the per-step message `name` (one of SENSOR_MESSAGES) is filled from
        `data.sensordata`."""
        wire = self.imu_wire if name == 'imu' else self.contact_wires[name]
        to, source = self._imu_map if name == 'imu' else self._contact_maps[name]
        return SensorSelection(wire, _float_offset(wire), to, source)

    def fill_plan(self, names: Sequence[str]) -> CopyPlan:
        """One call that writes the current state into the named per-step messages.

        A writer that fills several of them at the same steps joins them in one plan: one
        C call a step instead of one per message.
        """
        return CopyPlan([copy for name in names for copy in self._copies[name]])

    def fill_odometry(self) -> None:
        """Pelvis pose and world-frame twist, as Gazebo's p3d plugin reported them.

        Body poses are computed before mj_step integrates: stamp with `sim.state_time_ns`.
        """
        sim, odom = self.sim, self.odometry_wire
        body = sim.atlas.pelvis_body_id
        odom.position[:] = sim.data.xpos[body]
        odom.orientation_xyzw[:3] = sim.data.xquat[body, 1:]
        odom.orientation_xyzw[3] = sim.data.xquat[body, 0]
        mujoco.mj_objectVelocity(sim.model, sim.data, mujoco.mjtObj.mjOBJ_BODY, body,
                                 self._pelvis_velocity, 0)
        odom.angular[:] = self._pelvis_velocity[:3]
        odom.linear[:] = self._pelvis_velocity[3:]

    def fill_pelvis_tf(self) -> None:
        """world -> pelvis, the pose /ground_truth_odom has (stamp with `sim.state_time_ns`)."""
        sim, tf = self.sim, self.pelvis_tf_wire
        body = sim.atlas.pelvis_body_id
        tf.translation[:] = sim.data.xpos[body]
        tf.rotation_xyzw[:3] = sim.data.xquat[body, 1:]
        tf.rotation_xyzw[3] = sim.data.xquat[body, 0]

    def odometry(self, stamp_ns: int) -> bytes:
        self.fill_odometry()
        return self.odometry_wire.to_bytes(stamp_ns)

    def pelvis_tf(self, stamp_ns: int) -> bytes:
        self.fill_pelvis_tf()
        return self.pelvis_tf_wire.to_bytes(stamp_ns)

    # -- the links' transforms, in robot_state_publisher's stead (link_transforms.py) ------
    def use_link_transforms(self, links: LinkTransforms) -> None:
        """Lay out the links' /tf message for `links` (built on JOINT_NAMES' positions)."""
        self.links = links
        self.links_tf_wire = TransformsWire(links.frames)
        self._links_qpos_adr = self.sim.atlas.qpos_adr

    def links_tf(self, stamp_ns: int) -> bytearray:
        """Every moving joint's parent -> child transform at the joint positions now (those
        /atlas/joint_states carries when stamped with `sim.sim_time_ns`), stamped
        `stamp_ns`: the wire's buffer, valid until the next call."""
        wire = self.links_tf_wire
        self.links.compute(self.sim.data.qpos[self._links_qpos_adr], wire.translations,
                           wire.rotations_xyzw)
        return wire.stamped(stamp_ns)
