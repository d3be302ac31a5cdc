"""Gravity stiffness of a stance joint: why single support needs stiffer gains.

Standing on one foot, everything the stance leg carries above a roll joint is an inverted
pendulum about that joint's axis: tipped by a small angle, gravity pulls it further with a
torque of about m·g·h per radian (m the mass above the joint, h its centre of mass's height
above the axis). A position gain p below m·g·h cannot hold the pose without the other foot.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco

from tutorial_atlas_control.sim.model import AtlasModel, reset_to_initial

__all__ = ['GRAVITY_M_S2', 'GravityStiffness', 'gravity_stiffness']

GRAVITY_M_S2 = 9.81


@dataclass(frozen=True)
class GravityStiffness:
    """What a joint holds up, standing in the initial pose."""

    joint: str
    mass_kg: float      # every body that is not distal to the joint
    height_m: float     # that mass's centre of mass above the joint's axis
    stiffness_nm_rad: float  # m·g·h

    def line(self) -> str:
        return (f'{self.joint}: {self.mass_kg:.1f} kg, centre of mass {self.height_m:.3f} m '
                f'above the axis: {self.stiffness_nm_rad:.0f} N m/rad')


def gravity_stiffness(atlas: AtlasModel, joint: str) -> GravityStiffness:
    """m·g·h of `joint` as a stance joint, in the model's initial standing pose."""
    model = atlas.model
    data = mujoco.MjData(model)
    reset_to_initial(atlas, data)
    mujoco.mj_kinematics(model, data)
    distal_root = int(model.joint(joint).bodyid[0])
    carried = [body for body in range(1, model.nbody) if not _descends(model, body, distal_root)]
    masses = model.body_mass[carried]
    com = (masses[:, None] * data.xipos[carried]).sum(axis=0) / masses.sum()
    height = float(com[2] - data.xanchor[model.joint(joint).id][2])
    mass = float(masses.sum())
    return GravityStiffness(joint, mass, height, mass * GRAVITY_M_S2 * height)


def _descends(model: mujoco.MjModel, body: int, root: int) -> bool:
    """Is `body` `root` or below it in the kinematic tree?"""
    while body > 0:
        if body == root:
            return True
        body = int(model.body_parentid[body])
    return False
