"""DRCSim's VRCPlugin "cheats" without ROS: harness/pin and gravity modes, teleport, cmd_vel,
the held pelvis wrench (gazebo_ros_force) and kinematic joint playback
(gazebo_ros_joint_trajectory).

The node decodes each message into one of the frozen inputs below (checked whole: a bad
field refuses the message and nothing is applied; /joint_trajectory's check is
sim/joint_trajectory.py); the stepping loop hands it to
AtlasSimulator.apply_input between two steps, under its lock. Every applied input is also
logged, with the sim time it took effect, on /atlas/sim_inputs (JSON, `to_dict`), so that
offline replay re-applies it before the very same step.

Mapping to MuJoCo:
* pinning welds the pelvis (the model's `pelvis_pin` weld, its target moved to the pin
  pose); DRCSim pinned `utorso` with a fixed joint;
* a link with gravity off gets -m·g at its centre of mass through `xfrc_applied`
  (Gazebo's per-link gravity flag has no MuJoCo twin; the force cancels gravity exactly);
* the pelvis wrench is added to `xfrc_applied` (world frame, at the centre of mass, as
  Gazebo's Link::SetForce/SetTorque), held until the next message.
"""

from __future__ import annotations

import enum
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Union

import mujoco
import numpy as np

from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.ground import Ground

__all__ = [
    'DEFAULT_STARTUP_MODE', 'STARTUP_MODES', 'VALID_VRC_MODES', 'CmdVelInput', 'InputError',
    'InputEvent', 'InputNote', 'STAND_POSE_RAD', 'describe_input', 'finite_values',
    'input_notes',
    'ModeInput', 'PoseInput', 'SimInput', 'TrajectoryInput', 'VrcMode', 'VrcState',
    'WrenchInput', 'cmd_vel_input', 'input_from_dict', 'parse_vrc_mode', 'pose_input',
    'wrench_input',
]


class VrcMode(str, enum.Enum):
    """The strings VRCPlugin accepted on /atlas/mode."""

    HARNESSED = 'harnessed'
    PINNED = 'pinned'
    PINNED_WITH_GRAVITY = 'pinned_with_gravity'
    NOMINAL = 'nominal'
    FEET = 'feet'
    NO_GRAVITY = 'no_gravity'
    BDI_STAND = 'bdi_stand'


VALID_VRC_MODES: tuple[str, ...] = tuple(mode.value for mode in VrcMode)
#: `/atlas/startup_mode`: DRCSim's `pinned` (gravity off, `nominal` after time_to_unpin; 0
#: keeps it pinned) and `bdi_stand` (free, Stand hold), and the port's historical start,
#: `pinned_with_gravity` for time_to_unpin (0: never pinned), the default.
STARTUP_MODES: tuple[str, ...] = (VrcMode.PINNED_WITH_GRAVITY.value, VrcMode.PINNED.value,
                                  VrcMode.BDI_STAND.value)
DEFAULT_STARTUP_MODE = VrcMode.PINNED_WITH_GRAVITY

#: VRCPlugin::AtlasCommandController::SetPIDStand's "StandPrep end pose --> Stand pose"
#: (DRCSim 2.7.0), the tutorial's joint order (rad): bent knees (0.518), arms down and out.
STAND_POSE_RAD: np.ndarray = np.array([
    2.438504816382192e-05, 0.0015186156379058957, 9.983908967114985e-06,
    -0.0010675729718059301,
    -0.0003740221436601132, 0.06201673671603203, -0.2333149015903473,
    0.5181407332420349, -0.27610817551612854, -0.062101610004901886,
    0.00035181696875952184, -0.06218484416604042, -0.2332201600074768,
    0.51811283826828, -0.2762000858783722, 0.06211360543966293,
    0.29983898997306824, -1.303462266921997, 2.0007927417755127,
    0.49823325872421265, 0.0003098883025813848, -0.0044272784143686295,
    0.29982614517211914, 1.3034454584121704, 2.000779867172241,
    -0.498238742351532, 0.0003156556049361825, 0.004448802210390568,
])
STAND_POSE_RAD.setflags(write=False)

#: `harnessed` lifts the robot upright with DRCSim's pin link (utorso) this high (m) above
#: the ground under it: the pelvis ends 4.3 cm above standing.
HARNESS_UTORSO_HEIGHT_M = 1.11
#: The links `feet` leaves under gravity (VRCPlugin's names).
FEET_BODIES = ('l_foot', 'r_foot')
#: Bounds past which an input is refused as absurd (VRCPlugin took anything).
MAX_POSITION_M = 1e4
MAX_FORCE_N = 1e5
MAX_TORQUE_NM = 1e5
MAX_SPEED_M_S = 1e2
MAX_TURN_RAD_S = 1e2
#: A quaternion shorter than this cannot be normalized into an orientation.
MIN_QUATERNION_NORM = 1e-9


class InputError(AtlasControlError):
    """An input message is refused whole; the message says which field and why."""


def parse_vrc_mode(text: str) -> VrcMode:
    """The VrcMode for an /atlas/mode string.

    Raises:
        InputError: unknown mode (the message lists the valid ones).
    """
    try:
        return VrcMode(text)
    except ValueError:
        shown = text if len(text) <= 40 else text[:40] + '...'
        raise InputError(f'unknown mode {shown!r}; valid modes: '
                         + ', '.join(VALID_VRC_MODES)) from None


def finite_values(values: Sequence[float], what: str, bound: float) -> tuple[float, ...]:
    """`values` as floats; refused if one is NaN/Inf or its magnitude exceeds `bound`."""
    out = tuple(float(v) for v in values)
    for value in out:
        if not math.isfinite(value):
            raise InputError(f'{what} is not finite ({value})')
        if abs(value) > bound:
            raise InputError(f'{what} {value:g} exceeds {bound:g}')
    return out


# ---------------------------------------------------------------------------- inputs


@dataclass(frozen=True)
class ModeInput:
    """/atlas/mode."""

    mode: VrcMode
    kind = 'mode'

    def to_dict(self) -> dict[str, Any]:
        return {'kind': self.kind, 'mode': self.mode.value}


@dataclass(frozen=True)
class PoseInput:
    """/atlas/set_pose: the pelvis pose (m; unit quaternion w x y z)."""

    position_m: tuple[float, float, float]
    quat_wxyz: tuple[float, float, float, float]
    kind = 'set_pose'

    def to_dict(self) -> dict[str, Any]:
        return {'kind': self.kind, 'position': list(self.position_m),
                'quat_wxyz': list(self.quat_wxyz)}


@dataclass(frozen=True)
class CmdVelInput:
    """/atlas/cmd_vel: VRCPlugin uses linear x, y (m/s, pelvis frame) and angular z (rad/s)."""

    linear_x: float
    linear_y: float
    angular_z: float
    kind = 'cmd_vel'

    @property
    def stops(self) -> bool:
        return self.linear_x == 0.0 and self.linear_y == 0.0 and self.angular_z == 0.0

    def to_dict(self) -> dict[str, Any]:
        return {'kind': self.kind, 'linear_x': self.linear_x, 'linear_y': self.linear_y,
                'angular_z': self.angular_z}


@dataclass(frozen=True)
class WrenchInput:
    """/atlas/apply_pelvis_force: world-frame force (N) and torque (N m) at the pelvis."""

    force_n: tuple[float, float, float]
    torque_nm: tuple[float, float, float]
    kind = 'pelvis_wrench'

    def to_dict(self) -> dict[str, Any]:
        return {'kind': self.kind, 'force': list(self.force_n), 'torque': list(self.torque_nm)}


@dataclass(frozen=True)
class InputNote:
    """A line about an accepted input for the node to log: a `logging` level and the text
    (e.g. what a trajectory's check clamped)."""

    level: int
    text: str


@dataclass(frozen=True)
class TrajectoryInput:
    """/joint_trajectory: joint indices (JOINT_NAMES order), one row of positions (rad) per
    point, each point's time from the start (ns), and the requested start (sim time, ns; a
    start in the past, e.g. a zero stamp, means at once). `notes` say what the check
    changed; they are not part of the logged input (replay applies the positions and times
    played)."""

    joints: tuple[int, ...]
    positions_rad: tuple[tuple[float, ...], ...]
    times_ns: tuple[int, ...]
    start_ns: int
    reference_link: str = ''  # a link kept where it is while the joints move; '' = the pelvis
    notes: tuple[InputNote, ...] = field(default=(), compare=False, repr=False)
    kind = 'joint_trajectory'

    def to_dict(self) -> dict[str, Any]:
        return {'kind': self.kind, 'joints': [JOINT_NAMES[i] for i in self.joints],
                'positions': [list(row) for row in self.positions_rad],
                'times_ns': list(self.times_ns), 'start_ns': self.start_ns,
                'reference_link': self.reference_link}


SimInput = Union[ModeInput, PoseInput, CmdVelInput, WrenchInput, TrajectoryInput]


def pose_input(position: Sequence[float], orientation_xyzw: Sequence[float]) -> PoseInput:
    """Check a geometry_msgs/Pose's numbers; the quaternion is normalized as VRCPlugin did.

    Raises:
        InputError: non-finite or absurd numbers, or a quaternion of (near) zero length.
    """
    pos = finite_values(position, 'position', MAX_POSITION_M)
    x, y, z, w = finite_values(orientation_xyzw, 'orientation', 1e6)
    norm = math.sqrt(w * w + x * x + y * y + z * z)
    if norm < MIN_QUATERNION_NORM:
        raise InputError('orientation is a zero quaternion (set w = 1 for upright)')
    return PoseInput((pos[0], pos[1], pos[2]), (w / norm, x / norm, y / norm, z / norm))


def cmd_vel_input(linear: Sequence[float], angular: Sequence[float]) -> CmdVelInput:
    """Check a geometry_msgs/Twist (all six fields must be finite; three are used)."""
    lin = finite_values(linear, 'linear velocity', MAX_SPEED_M_S)
    ang = finite_values(angular, 'angular velocity', MAX_TURN_RAD_S)
    return CmdVelInput(lin[0], lin[1], ang[2])


def wrench_input(force: Sequence[float], torque: Sequence[float]) -> WrenchInput:
    """Check a geometry_msgs/Wrench."""
    f = finite_values(force, 'force', MAX_FORCE_N)
    t = finite_values(torque, 'torque', MAX_TORQUE_NM)
    return WrenchInput((f[0], f[1], f[2]), (t[0], t[1], t[2]))


#: The topic each input kind comes from (for logs and the bag report's timeline).
INPUT_TOPICS = {'mode': '/atlas/mode', 'set_pose': '/atlas/set_pose', 'cmd_vel': '/atlas/cmd_vel',
                'pelvis_wrench': '/atlas/apply_pelvis_force',
                'joint_trajectory': '/joint_trajectory'}


def input_notes(item: SimInput) -> tuple[InputNote, ...]:
    """The lines to log about an accepted input (only a trajectory's check has any)."""
    return item.notes if isinstance(item, TrajectoryInput) else ()


def describe_input(item: SimInput) -> str:
    """One short line: the input's topic and values (a trajectory's only counted)."""
    data = item.to_dict()
    if isinstance(item, TrajectoryInput):
        values = f'{len(item.joints)} joints, {len(item.times_ns)} points'
    elif isinstance(item, ModeInput):
        values = item.mode.value
    else:
        values = ', '.join(f'{key}={value}' for key, value in data.items() if key != 'kind')
    return f'{INPUT_TOPICS[item.kind]} {values}'


def input_from_dict(item: Mapping[str, Any]) -> SimInput:
    """An input from its logged JSON object (`to_dict`), for replay.

    Raises:
        InputError: not a logged input.
    """
    try:
        kind = item['kind']
        if kind == ModeInput.kind:
            return ModeInput(parse_vrc_mode(item['mode']))
        if kind == PoseInput.kind:
            pos, quat = (tuple(float(v) for v in item[key]) for key in ('position', 'quat_wxyz'))
            return PoseInput(pos, quat)  # type: ignore[arg-type]
        if kind == CmdVelInput.kind:
            return CmdVelInput(float(item['linear_x']), float(item['linear_y']),
                               float(item['angular_z']))
        if kind == WrenchInput.kind:
            force, torque = (tuple(float(v) for v in item[key]) for key in ('force', 'torque'))
            return WrenchInput(force, torque)  # type: ignore[arg-type]
        if kind == TrajectoryInput.kind:
            joints = tuple(JOINT_NAMES.index(name) for name in item['joints'])
            return TrajectoryInput(joints, tuple(tuple(float(v) for v in row)
                                                 for row in item['positions']),
                                   tuple(int(t) for t in item['times_ns']),
                                   int(item['start_ns']), str(item.get('reference_link', '')))
    except (KeyError, TypeError, ValueError) as err:
        raise InputError(f'not a logged input ({type(err).__name__}: {err})') from None
    raise InputError(f'unknown input kind {kind!r}')


@dataclass(frozen=True)
class InputEvent:
    """One applied input as /atlas/sim_inputs carries it: the sim time (ns) before the step
    it first acted in, the reset it belongs to (last_reset, ns), its number since that
    reset (from 0), and the input."""

    time_ns: int
    reset_ns: int
    seq: int
    item: SimInput

    def to_json(self) -> str:
        return json.dumps({'time_ns': self.time_ns, 'reset_ns': self.reset_ns, 'seq': self.seq,
                           'input': self.item.to_dict()})

    @classmethod
    def from_json(cls, text: str) -> InputEvent:
        """Raises: InputError: not an /atlas/sim_inputs text."""
        try:
            event = json.loads(text)
            return cls(int(event['time_ns']), int(event['reset_ns']), int(event['seq']),
                       input_from_dict(event['input']))
        except (json.JSONDecodeError, KeyError, TypeError, ValueError) as err:
            raise InputError(f'not an input event ({type(err).__name__}: {err})') from None


# ---------------------------------------------------------------------------- the physics


class _Playback:
    """A trajectory being played: the sim time (ns) each point is due, and the next one."""

    def __init__(self, trajectory: TrajectoryInput, now_ns: int, qpos_adr: np.ndarray,
                 reference_body: int) -> None:
        start_ns = max(trajectory.start_ns, now_ns)
        self.due_ns = [start_ns + t for t in trajectory.times_ns]
        self.qpos_adr = qpos_adr[list(trajectory.joints)]
        self.rows = [np.array(row) for row in trajectory.positions_rad]
        self.reference_body = reference_body  # -1: the pelvis stays
        self.next = 0


def _yaw_quat(yaw_rad: float) -> np.ndarray:
    return np.array([math.cos(yaw_rad / 2.0), 0.0, 0.0, math.sin(yaw_rad / 2.0)])


def _yaw(quat_wxyz: np.ndarray) -> float:
    w, x, y, z = quat_wxyz
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


class VrcState:
    """The cheats' effect on one simulator's MuJoCo model and data.

    `active` is False while nothing acts (no gravity change, wrench, warp or playback): the
    simulator's step then runs exactly as without this class.
    """

    def __init__(self, atlas: atlas_model.AtlasModel, data: mujoco.MjData,
                 ground: Ground | None = None, home_qpos: np.ndarray | None = None) -> None:
        """`ground`: the world's ground, which `harnessed` lifts the robot above (None: the
        plane z = 0); `home_qpos`: the pelvis's start pose (set_home; None: the model's)."""
        self.atlas = atlas
        self.model = model = atlas.model
        self.data = data
        self.ground = ground
        self._pin_eq_data = model.eq_data[atlas.pin_eq_id].copy()
        self._home_z_m = atlas_model.SPAWN_HEIGHT_M
        # The force that cancels each body's weight, at its centre of mass (N, world frame).
        self._weight_counter = -model.body_mass[:, None] * model.opt.gravity[None, :]
        self._feet = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
                      for name in FEET_BODIES]
        # utorso's height over the pelvis at the spawn pose (all joints 0), for `harnessed`.
        utorso = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, 'utorso')
        probe = mujoco.MjData(model)
        atlas_model.reset_to_initial(atlas, probe)
        self._utorso_above_pelvis_m = (
            float(probe.xpos[utorso, 2] - probe.xpos[atlas.pelvis_body_id, 2]) if utorso >= 0
            else 0.0)
        self.xfrc = np.zeros((model.nbody, 6))
        if home_qpos is not None:
            self.set_home(home_qpos)
        self.reset()

    def reset(self) -> None:
        """Nothing acting, the weld back on the model's spawn pose (reset_world)."""
        self.model.eq_data[self.atlas.pin_eq_id] = self._pin_eq_data
        self.gravity_off = np.zeros(self.model.nbody, dtype=bool)
        self.wrench = np.zeros(6)
        self.warp: CmdVelInput | None = None
        self.warp_z_m = self._home_z_m
        self.playback: _Playback | None = None
        self.active = False

    def set_home(self, pelvis_qpos: np.ndarray) -> None:
        """The start the robot is reset to (the pelvis's qpos (7,)): the start-up pin's weld
        holds it from the next reset on, and cmd_vel's warp starts at its height."""
        relpos, relquat = np.zeros(3), np.zeros(4)
        mujoco.mju_negPose(relpos, relquat, pelvis_qpos[:3], pelvis_qpos[3:7])
        self._pin_eq_data[0:3] = 0.0
        self._pin_eq_data[3:6] = relpos
        self._pin_eq_data[6:10] = relquat
        self._home_z_m = float(pelvis_qpos[2])

    # -- state ---------------------------------------------------------------------------
    def harness_pelvis_z_m(self, x_m: float, y_m: float) -> float:
        """The pelvis height (m) `harnessed` lifts the robot to over world (x, y)."""
        ground_m = self.ground.height_m(x_m, y_m) if self.ground is not None else 0.0
        if not math.isfinite(ground_m):  # off the world's ground: as over the plane
            ground_m = 0.0
        return ground_m + HARNESS_UTORSO_HEIGHT_M - self._utorso_above_pelvis_m

    def pelvis_pose(self) -> tuple[np.ndarray, np.ndarray]:
        adr = self.atlas.free_qpos_adr
        return self.data.qpos[adr:adr + 3].copy(), self.data.qpos[adr + 3:adr + 7].copy()

    def _set_pelvis_pose(self, pos: np.ndarray, quat: np.ndarray) -> None:
        adr = self.atlas.free_qpos_adr
        self.data.qpos[adr:adr + 3] = pos
        self.data.qpos[adr + 3:adr + 7] = quat

    def _still_pelvis(self) -> None:
        adr = int(self.model.jnt_dofadr[self.model.body_jntadr[self.atlas.pelvis_body_id]])
        self.data.qvel[adr:adr + 6] = 0.0

    def is_pinned(self) -> bool:
        return bool(self.data.eq_active[self.atlas.pin_eq_id])

    def pin_at(self, pos: np.ndarray, quat: np.ndarray) -> None:
        """Weld the pelvis at (pos, quat): the weld holds the world's pose in the pelvis frame."""
        relpos, relquat = np.zeros(3), np.zeros(4)
        mujoco.mju_negPose(relpos, relquat, pos, quat)
        eq = self.model.eq_data[self.atlas.pin_eq_id]
        eq[0:3] = 0.0
        eq[3:6] = relpos
        eq[6:10] = relquat
        self.data.eq_active[self.atlas.pin_eq_id] = 1

    def unpin(self) -> None:
        self.data.eq_active[self.atlas.pin_eq_id] = 0

    def set_gravity(self, on: bool, except_feet: bool = False) -> None:
        self.gravity_off[:] = not on
        if except_feet:
            self.gravity_off[self._feet] = False
        self._update()

    def _update(self) -> None:
        """Recompute the extra body forces and whether anything acts."""
        xfrc = self.xfrc
        xfrc[:] = 0.0
        xfrc[self.gravity_off, 0:3] = self._weight_counter[self.gravity_off]
        xfrc[self.atlas.pelvis_body_id] += self.wrench
        self.active = bool(self.gravity_off.any() or self.wrench.any()
                           or self.warp is not None or self.playback is not None)

    # -- inputs ----------------------------------------------------------------------------
    def set_mode(self, mode: VrcMode) -> None:
        """VRCPlugin::SetRobotMode: the pin and gravity. `bdi_stand` pins without gravity, as
        `pinned` does; its Stand pose and timed sequence are the simulator's part."""
        if mode in (VrcMode.PINNED, VrcMode.PINNED_WITH_GRAVITY, VrcMode.BDI_STAND):
            pos, quat = self.pelvis_pose()
            if not self.is_pinned():
                self.pin_at(pos, quat)
            self.warp_z_m = float(pos[2])
            if mode is VrcMode.BDI_STAND:
                self.warp = None  # as the free modes: bdi_stand stops cmd_vel
            self.set_gravity(mode is VrcMode.PINNED_WITH_GRAVITY)
            return
        if mode is VrcMode.HARNESSED:
            pos, _ = self.pelvis_pose()
            pos[2] = self.harness_pelvis_z_m(float(pos[0]), float(pos[1]))
            quat = np.array([1.0, 0.0, 0.0, 0.0])
            self._set_pelvis_pose(pos, quat)
            self._still_pelvis()
            self.pin_at(pos, quat)
            self.warp_z_m = float(pos[2])
            self.set_gravity(False)
            return
        # nominal, feet, no_gravity: free, warp stopped
        self.unpin()
        self.warp = None
        self.set_gravity(mode is VrcMode.NOMINAL, except_feet=mode is VrcMode.FEET)

    def set_joint_positions(self, positions_rad: np.ndarray) -> None:
        """Gazebo's Model::SetJointPositions, as VRCPlugin's SetPIDStand calls it: the joints
        at `positions_rad` (tutorial order), at rest; the pelvis stays where it is."""
        self.data.qpos[self.atlas.qpos_adr] = positions_rad
        self.data.qvel[self.atlas.dof_adr] = 0.0
        mujoco.mj_forward(self.model, self.data)

    def set_pose(self, item: PoseInput) -> None:
        """Teleport the pelvis; a pinned robot takes its pin along (velocities kept)."""
        pos, quat = np.array(item.position_m), np.array(item.quat_wxyz)
        self._set_pelvis_pose(pos, quat)
        if self.is_pinned():
            self.pin_at(pos, quat)

    def set_cmd_vel(self, item: CmdVelInput) -> None:
        """All zero stops the warp; anything else warps (and pins) the robot every step."""
        self.warp = None if item.stops else item
        self._update()

    def set_wrench(self, item: WrenchInput) -> None:
        self.wrench[:] = item.force_n + item.torque_nm
        self._update()

    def start_playback(self, item: TrajectoryInput, now_ns: int) -> None:
        """Physics off from now until the last point is set (a new trajectory replaces one
        playing)."""
        reference = -1
        if item.reference_link:
            reference = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY,
                                          item.reference_link)
            if reference < 0:  # checked against the model's links before
                raise InputError(f'no link {item.reference_link!r} in the model')
        self.playback = _Playback(item, now_ns, self.atlas.qpos_adr, reference)
        self._update()

    @property
    def link_names(self) -> tuple[str, ...]:
        """The model's bodies (links), what a trajectory's frame_id may name."""
        return tuple(self.model.body(i).name for i in range(1, self.model.nbody))

    # -- stepping ------------------------------------------------------------------------
    def warp_step(self, dt_s: float) -> None:
        """VRCPlugin's cmd_vel: move the pinned pelvis by the twist, upright, at warp_z_m."""
        warp = self.warp
        if warp is None:
            return
        pos, quat = self.pelvis_pose()
        step = np.zeros(3)
        mujoco.mju_rotVecQuat(step, np.array([warp.linear_x, warp.linear_y, 0.0]), quat)
        pos = pos + step * dt_s
        pos[2] = self.warp_z_m
        quat = _yaw_quat(_yaw(quat) + warp.angular_z * dt_s)
        self._set_pelvis_pose(pos, quat)
        self.pin_at(pos, quat)

    def _set_keeping(self, body: int, qpos_adr: np.ndarray, values: np.ndarray) -> None:
        """Set joint positions and move the pelvis so that `body` keeps its world pose."""
        model, data = self.model, self.data
        mujoco.mj_kinematics(model, data)
        old_pos, old_quat = data.xpos[body].copy(), data.xquat[body].copy()
        data.qpos[qpos_adr] = values
        mujoco.mj_kinematics(model, data)
        inv_pos, inv_quat = np.zeros(3), np.zeros(4)
        mujoco.mju_negPose(inv_pos, inv_quat, data.xpos[body], data.xquat[body])
        shift_pos, shift_quat = np.zeros(3), np.zeros(4)
        mujoco.mju_mulPose(shift_pos, shift_quat, old_pos, old_quat, inv_pos, inv_quat)
        pelvis_pos, pelvis_quat = self.pelvis_pose()
        new_pos, new_quat = np.zeros(3), np.zeros(4)
        mujoco.mju_mulPose(new_pos, new_quat, shift_pos, shift_quat, pelvis_pos, pelvis_quat)
        mujoco.mju_normalize4(new_quat)
        self._set_pelvis_pose(new_pos, new_quat)

    def playback_step(self, now_ns: int) -> None:
        """One step with physics off: set the points due by `now_ns`, the robot at rest."""
        playback = self.playback
        assert playback is not None
        qpos = self.data.qpos
        while playback.next < len(playback.rows) and playback.due_ns[playback.next] <= now_ns:
            if playback.reference_body >= 0:
                self._set_keeping(playback.reference_body, playback.qpos_adr,
                                  playback.rows[playback.next])
            else:
                qpos[playback.qpos_adr] = playback.rows[playback.next]
            playback.next += 1
        self.data.qvel[:] = 0.0
        mujoco.mj_forward(self.model, self.data)
        if playback.next == len(playback.rows):
            self.playback = None
            self._update()
