"""DRCSim's Stand pose and the robot placed in it, feet flat on the ground."""

from __future__ import annotations

import mujoco
import numpy as np

from tutorial_atlas_control.sim import STAND_POSE_RAD, AtlasModel, reset_to_initial

__all__ = ['STAND_POSE_RAD', 'place_in_stand_pose', 'sole_corners']


#: The sole boxes of the model (sim/atlas_v1.xml), left then right.
SOLE_GEOMS: tuple[str, str] = ('l_foot_sole', 'r_foot_sole')


def place_in_stand_pose(atlas: AtlasModel, data: mujoco.MjData,
                        joint_angles_rad: np.ndarray = STAND_POSE_RAD) -> float:
    """Set the joints to `joint_angles_rad` at rest with the pelvis upright, lowered so
    that the lowest sole corner touches z = 0; returns the pelvis height (m).

    DRCSim set the joints of a pinned robot; placing it on the ground instead lets an
    offline run start balancing at once.
    """
    reset_to_initial(atlas, data)
    data.qpos[atlas.qpos_adr] = joint_angles_rad
    mujoco.mj_kinematics(atlas.model, data)
    lowest = min(float(np.min(sole_corners(atlas.model, data, name)[:, 2]))
                 for name in SOLE_GEOMS)
    adr = atlas.free_qpos_adr
    data.qpos[adr + 2] -= lowest
    data.qvel[:] = 0.0
    mujoco.mj_forward(atlas.model, data)
    return float(data.qpos[adr + 2])


def sole_corners(model: mujoco.MjModel, data: mujoco.MjData, geom_name: str) -> np.ndarray:
    """The four bottom corners (4, 3) (m, world) of a sole box, after kinematics."""
    geom = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, geom_name)
    half = model.geom_size[geom]
    signs = np.array([[1, 1, -1], [1, -1, -1], [-1, -1, -1], [-1, 1, -1]], dtype=np.float64)
    rotation = data.geom_xmat[geom].reshape(3, 3)
    return data.geom_xpos[geom] + (signs * half) @ rotation.T
