"""The robot placed in DRCSim's Stand pose and the balancing Stand started on it, without
physics: what the walking controller's unit tests start from (one estimate, its controller)."""

from __future__ import annotations

import mujoco

from tutorial_atlas_control.balance import StandBehaviour
from tutorial_atlas_control.balance.stand_pose import place_in_stand_pose
from tutorial_atlas_control.sim import AtlasModel
from tutorial_atlas_control.sim import model as atlas_model


def started_stand() -> tuple[AtlasModel, mujoco.MjData, StandBehaviour]:
    """A fresh model and data in the Stand pose, and a Stand started on them (its
    `last_state` and `controller` set)."""
    atlas = atlas_model.load_model()
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    stand = StandBehaviour(atlas)
    stand.start(data)
    assert stand.last_state is not None and stand.controller is not None
    return atlas, data, stand
