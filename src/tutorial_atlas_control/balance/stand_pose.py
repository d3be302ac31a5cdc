"""DRCSim's Stand pose and the robot placed in it, feet flat on the ground."""

from __future__ import annotations

import mujoco
import numpy as np

from tutorial_atlas_control.balance.sole import lowest_sole_corner_m
from tutorial_atlas_control.sim import STAND_POSE_RAD, AtlasModel, reset_to_initial

__all__ = ['STAND_POSE_RAD', 'place_in_stand_pose']


def place_in_stand_pose(atlas: AtlasModel, data: mujoco.MjData,
                        joint_angles_rad: np.ndarray = STAND_POSE_RAD,
                        ground_m: float = 0.0) -> float:
    """Set the joints to `joint_angles_rad` at rest with the pelvis upright over the model
    file's spawn, lowered so that the lowest sole corner touches z = `ground_m` (a course's
    ground under the feet); returns the pelvis height (m).

    DRCSim set the joints of a pinned robot; placing it on the ground instead lets an
    offline run start balancing at once.
    """
    reset_to_initial(atlas, data)
    data.qpos[atlas.qpos_adr] = joint_angles_rad
    mujoco.mj_kinematics(atlas.model, data)
    adr = atlas.free_qpos_adr
    data.qpos[adr + 2] -= lowest_sole_corner_m(atlas.model, data) - ground_m
    data.qvel[:] = 0.0
    mujoco.mj_forward(atlas.model, data)
    return float(data.qpos[adr + 2])

