"""DRCSim's Stand pose and the robot placed in it, feet flat on the ground."""

from __future__ import annotations

import mujoco
import numpy as np

from tutorial_atlas_control.sim import AtlasModel, reset_to_initial

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
