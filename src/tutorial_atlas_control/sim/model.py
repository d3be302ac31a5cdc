"""Loading the MuJoCo Atlas v1 model and reading/writing its state by joint name.

Everything here indexes MuJoCo arrays with precomputed integer arrays in the
tutorial's joint order (joints.JOINT_NAMES), so the 1 kHz loop never loops
over joints in Python.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np

from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.resources import package_path

MODEL_PATH: Path = package_path('sim', 'atlas_v1.xml')

#: Pelvis z (m) at which both sole boxes touch z = 0 with every joint at 0:
#: hip-pitch origin 0.05 + knee 0.374 + ankle 0.422 + sole centre 0.076119 +
#: half sole thickness 0.005. DRCSim spawned the pelvis at 0.93 m, i.e. it
#: dropped the robot 2.9 mm onto the ground; we start in contact instead.
SPAWN_HEIGHT_M: float = 0.05 + 0.374 + 0.422 + 0.076119 + 0.005

PELVIS_BODY = 'pelvis'
#: The feet's sole boxes, left then right: what stands on the ground.
SOLE_GEOMS: tuple[str, str] = ('l_foot_sole', 'r_foot_sole')
PIN_EQUALITY = 'pelvis_pin'

#: Sensors the model defines, by name (see sim/atlas_v1.xml).
SENSOR_NAMES: tuple[str, ...] = (
    'imu_orientation', 'imu_angular_velocity', 'imu_linear_acceleration',
    'l_foot_force', 'l_foot_torque', 'r_foot_force', 'r_foot_torque',
)

#: Columns of the joints' MJCF `user` data: effort limit (N m), velocity limit (rad/s).
USER_EFFORT, USER_VELOCITY = 0, 1


class ModelError(AtlasControlError):
    """The MuJoCo model file is missing, invalid, or not the Atlas model we expect."""


@dataclass(frozen=True)
class AtlasModel:
    """A compiled model plus the index arrays that map it to the tutorial's joints."""

    model: mujoco.MjModel
    path: Path                    # the MJCF it was compiled from: sim_config names and hashes it
    qpos_adr: np.ndarray          # (28,) int, qpos index of each joint in JOINT_NAMES order
    dof_adr: np.ndarray           # (28,) int, qvel/qfrc index
    lower_rad: np.ndarray         # (28,) position limits
    upper_rad: np.ndarray
    effort_limit_nm: np.ndarray   # (28,) torque clamp applied by the controller law
    velocity_limit_rad_s: np.ndarray  # (28,) data only: recorded, not enforced (as in DRCSim v1)
    pelvis_body_id: int
    pin_eq_id: int
    free_qpos_adr: int            # first qpos index of the pelvis free joint (x y z qw qx qy qz)
    sensor_slices: dict[str, slice] = field(default_factory=dict)  # into data.sensordata


def _require_id(model: mujoco.MjModel, obj: mujoco.mjtObj, name: str, path: Path) -> int:
    """Id of a named object, or a ModelError saying which one is missing."""
    obj_id = mujoco.mj_name2id(model, obj, name)
    if obj_id < 0:
        kind = mujoco.mju_type2Str(obj) if hasattr(mujoco, 'mju_type2Str') else str(obj)
        raise ModelError(f'{path} has no {kind} named {name!r}; regenerate it with '
                         '`python3 tools/make_atlas_mjcf.py`.')
    return obj_id


def load_model(path: Path = MODEL_PATH) -> AtlasModel:
    """Compile the MJCF at `path` and index it by the tutorial's joint names.

    Raises:
        ModelError: the file is missing, does not compile, or lacks a joint,
            actuator, body, equality or sensor this package relies on.
    """
    path = Path(path)
    if not path.is_file():
        raise ModelError(f'MuJoCo model {path} does not exist; regenerate it with '
                         '`python3 tools/make_atlas_mjcf.py`.')
    try:
        model = mujoco.MjModel.from_xml_path(str(path))
    except ValueError as err:
        raise ModelError(f'Could not compile MuJoCo model {path}: {err}') from err
    return index_model(model, path)


def index_model(model: mujoco.MjModel, path: Path = MODEL_PATH) -> AtlasModel:
    """Index a compiled Atlas model (`path`: where it came from, for messages) by the
    tutorial's joint names: a world built in memory (a tilted floor) as load_model's.

    Raises:
        ModelError: it lacks a joint, actuator, body, equality or sensor this package
            relies on.
    """
    joint_ids = np.array([_require_id(model, mujoco.mjtObj.mjOBJ_JOINT, name, path)
                          for name in JOINT_NAMES])
    for index, name in enumerate(JOINT_NAMES):
        actuator_id = _require_id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, name, path)
        if actuator_id != index or model.actuator_trnid[actuator_id, 0] != joint_ids[index]:
            raise ModelError(f'{path}: actuator {index} must drive joint {name!r} so that '
                             'data.ctrl follows the tutorial joint order.')
    pelvis = _require_id(model, mujoco.mjtObj.mjOBJ_BODY, PELVIS_BODY, path)
    pin = _require_id(model, mujoco.mjtObj.mjOBJ_EQUALITY, PIN_EQUALITY, path)
    free_joint = model.body_jntadr[pelvis]
    if free_joint < 0 or model.jnt_type[free_joint] != mujoco.mjtJoint.mjJNT_FREE:
        raise ModelError(f'{path}: the pelvis must have a free joint.')
    if model.nuser_jnt < 2:
        raise ModelError(f'{path}: joints need user="effort_limit velocity_limit" data '
                         '(<size nuser_jnt="2"/>).')
    slices = {}
    for name in SENSOR_NAMES:
        sensor_id = _require_id(model, mujoco.mjtObj.mjOBJ_SENSOR, name, path)
        adr, dim = int(model.sensor_adr[sensor_id]), int(model.sensor_dim[sensor_id])
        slices[name] = slice(adr, adr + dim)

    def frozen(values: np.ndarray) -> np.ndarray:
        values = np.ascontiguousarray(values)
        values.setflags(write=False)
        return values

    return AtlasModel(
        model=model,
        path=path,
        qpos_adr=frozen(model.jnt_qposadr[joint_ids].astype(np.intp)),
        dof_adr=frozen(model.jnt_dofadr[joint_ids].astype(np.intp)),
        lower_rad=frozen(model.jnt_range[joint_ids, 0].astype(np.float64)),
        upper_rad=frozen(model.jnt_range[joint_ids, 1].astype(np.float64)),
        effort_limit_nm=frozen(model.jnt_user[joint_ids, USER_EFFORT].astype(np.float64)),
        velocity_limit_rad_s=frozen(model.jnt_user[joint_ids, USER_VELOCITY].astype(np.float64)),
        pelvis_body_id=int(pelvis),
        pin_eq_id=int(pin),
        free_qpos_adr=int(model.jnt_qposadr[free_joint]),
        sensor_slices=slices,
    )


#: The pelvis's free-joint qpos at the flat world's start: the origin, upright, facing +x.
ORIGIN_PELVIS_QPOS = (0.0, 0.0, SPAWN_HEIGHT_M, 1.0, 0.0, 0.0, 0.0)


def reset_to_initial(atlas: AtlasModel, data: mujoco.MjData,
                     pelvis_qpos: Sequence[float] | np.ndarray | None = None) -> None:
    """Every joint at 0, the pelvis at `pelvis_qpos` (x y z, quaternion w x y z; default:
    the model file's spawn, its free joint's qpos0: on atlas_v1.xml upright at SPAWN_HEIGHT_M
    over the origin, in a course world its start), at rest, unpinned."""
    mujoco.mj_resetData(atlas.model, data)
    adr = atlas.free_qpos_adr
    data.qpos[atlas.qpos_adr] = 0.0
    data.qpos[adr:adr + 7] = (atlas.model.qpos0[adr:adr + 7] if pelvis_qpos is None
                              else pelvis_qpos)
    data.eq_active[atlas.pin_eq_id] = 0
    mujoco.mj_forward(atlas.model, data)


def set_pelvis_pinned(atlas: AtlasModel, data: mujoco.MjData, pinned: bool) -> None:
    """Weld the pelvis to its start pose (DRCSim's start-up pin) or release it.

    The weld holds the pose its data was last set to (the model file's spawn pose, or the
    start's: vrc.VrcState.reset), so pin only while the pelvis is there (e.g. right after
    reset_world).
    """
    data.eq_active[atlas.pin_eq_id] = 1 if pinned else 0


def joint_positions(atlas: AtlasModel, data: mujoco.MjData) -> np.ndarray:
    """(28,) joint angles (rad) in JOINT_NAMES order (a new array)."""
    return data.qpos[atlas.qpos_adr]


def joint_velocities(atlas: AtlasModel, data: mujoco.MjData) -> np.ndarray:
    """(28,) joint velocities (rad/s) in JOINT_NAMES order (a new array)."""
    return data.qvel[atlas.dof_adr]


def joint_efforts(atlas: AtlasModel, data: mujoco.MjData) -> np.ndarray:
    """(28,) actuator torques (N m) applied at the last step, JOINT_NAMES order."""
    return data.actuator_force.copy()


def pelvis_pose(atlas: AtlasModel, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
    """(position (3,) m, quaternion (4,) w x y z) of the pelvis in the world."""
    adr = atlas.free_qpos_adr
    return data.qpos[adr:adr + 3].copy(), data.qpos[adr + 3:adr + 7].copy()


def body_position_in_pose(atlas: AtlasModel, data: mujoco.MjData, body_id: int,
                          pelvis_position: np.ndarray, pelvis_quat_wxyz: np.ndarray,
                          joint_angles: np.ndarray) -> np.ndarray:
    """World position (m) of body `body_id` with the pelvis at `pelvis_position` (3,),
    `pelvis_quat_wxyz` (4,) and the joints at `joint_angles` (28, JOINT_NAMES order).

    Forward kinematics only (no dynamics), so a recorded pose (odometry and joint states)
    gives where a foot was; `data` is scratch space and is overwritten.
    """
    adr = atlas.free_qpos_adr
    data.qpos[adr:adr + 3] = pelvis_position
    data.qpos[adr + 3:adr + 7] = pelvis_quat_wxyz
    data.qpos[atlas.qpos_adr] = joint_angles
    mujoco.mj_kinematics(atlas.model, data)
    return data.xpos[body_id].copy()


def pelvis_height_m(atlas: AtlasModel, data: mujoco.MjData) -> float:
    """Height (m) of the pelvis origin above the ground, z = 0."""
    return float(data.qpos[atlas.free_qpos_adr + 2])


def sensor(atlas: AtlasModel, data: mujoco.MjData, name: str) -> np.ndarray:
    """Reading of the named sensor (a copy), e.g. 'l_foot_force' (N, foot frame).

    Raises:
        ModelError: `name` is not one of SENSOR_NAMES.
    """
    try:
        return data.sensordata[atlas.sensor_slices[name]].copy()
    except KeyError:
        raise ModelError(f'Unknown sensor {name!r}; '
                         f'choose one of {", ".join(SENSOR_NAMES)}.') from None
