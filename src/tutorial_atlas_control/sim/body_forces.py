"""One physics step with the extra body forces of that step only, over the viewer's.

xfrc_applied holds what the viewer's mouse puts there between steps. For one step the
simulator adds VRCPlugin's cheats' forces (sim.vrc: gravity cancelled on some links, the
held pelvis wrench), then the mud's drag (sim.mud), in that order every step so that runs
and replays add the same numbers, and puts the viewer's forces back after the step. The mud
needs the new positions' kinematics: with mud, mj_step runs as its two halves, the drag
computed between them (the same arithmetic as mj_step: a world whose mud nothing touches
steps bit for bit as one without).
"""

from __future__ import annotations

import mujoco
import numpy as np

from tutorial_atlas_control.sim.mud import MudDrag

__all__ = ['step_with_body_forces']


def step_with_body_forces(model: mujoco.MjModel, data: mujoco.MjData,
                          cheats_xfrc: np.ndarray | None, mud: MudDrag | None) -> None:
    """mj_step with `cheats_xfrc` (nbody, 6; None: none) and the mud's drag (None: no mud)
    added to xfrc_applied for this step; xfrc_applied is as it was afterwards."""
    if cheats_xfrc is None and mud is None:
        mujoco.mj_step(model, data)
        return
    held = data.xfrc_applied.copy()  # the viewer's mouse forces, if any
    if cheats_xfrc is not None:
        data.xfrc_applied += cheats_xfrc
    if mud is None:
        mujoco.mj_step(model, data)
    else:
        mujoco.mj_step1(model, data)
        if mud.update(data, float(model.opt.timestep)):
            data.xfrc_applied += mud.xfrc
        mujoco.mj_step2(model, data)
    data.xfrc_applied[:] = held
