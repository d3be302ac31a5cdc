"""One physics step with the extra body forces of that step only, over the viewer's.

xfrc_applied holds what the viewer's mouse puts there between steps. For one step the
simulator adds VRCPlugin's cheats' forces (sim.vrc: gravity cancelled on some links, the
held pelvis wrench), then the mud's drag (sim.mud), in that order every step so that runs
and replays add the same numbers, and puts the viewer's forces back after the step. The mud
needs the new positions' kinematics: with mud, mj_step runs as its two halves, the drag
computed between them (the same arithmetic as mj_step: a world whose mud nothing touches
steps bit for bit as one without); so does a behaviour's step (sim.shared_passes).
"""

from __future__ import annotations

from collections.abc import Callable

import mujoco
import numpy as np

from tutorial_atlas_control.sim.mud import MudDrag

__all__ = ['step_with_body_forces']


def step_with_body_forces(model: mujoco.MjModel, data: mujoco.MjData,
                          cheats_xfrc: np.ndarray | None, mud: MudDrag | None,
                          between: Callable[[], None] | None = None) -> None:
    """mj_step with `cheats_xfrc` (nbody, 6; None: none) and the mud's drag (None: no mud)
    added to xfrc_applied for this step; xfrc_applied is as it was afterwards. `between`
    (None: nothing) runs between mj_step1 and mj_step2, before the mud's drag: a behaviour's
    torque on the step's own passes (shared_passes)."""
    if cheats_xfrc is None and mud is None:
        _step(model, data, between)
        return
    held = data.xfrc_applied.copy()  # the viewer's mouse forces, if any
    try:
        if cheats_xfrc is not None:
            data.xfrc_applied += cheats_xfrc
        if mud is None:
            _step(model, data, between)
        else:
            mujoco.mj_step1(model, data)
            if between is not None:
                between()
            if mud.update(data, float(model.opt.timestep)):
                data.xfrc_applied += mud.xfrc
            mujoco.mj_step2(model, data)
    finally:
        data.xfrc_applied[:] = held


def _step(model: mujoco.MjModel, data: mujoco.MjData, between: Callable[[], None] | None
          ) -> None:
    """mj_step, as its two halves around `between` when there is one (the same numbers)."""
    if between is None:
        mujoco.mj_step(model, data)
    else:
        mujoco.mj_step1(model, data)
        between()
        mujoco.mj_step2(model, data)
