"""The balancing Stand as the simulator's Stand behaviour (sim/behaviour.py's protocol).

On start it holds the robot where it stands (StandReference.from_state: the capture point
over the soles' midpoint, the centre of mass at its height, the pelvis upright at its yaw);
each step it estimates the state from the simulator's MjData and returns the controller's
torque, which the simulator blends with the user's PID by k_effort as f_out.
"""

from __future__ import annotations

import mujoco
import numpy as np

from tutorial_atlas_control.balance.estimator import BalanceEstimator, BalanceState
from tutorial_atlas_control.balance.stand import (
    StandController,
    StandGains,
    StandOutput,
    StandReference,
)
from tutorial_atlas_control.sim import AtlasModel

__all__ = ['StandBehaviour']


class StandBehaviour:
    """Capture-point Stand for one simulator's robot."""

    def __init__(self, atlas: AtlasModel, gains: StandGains | None = None) -> None:
        self.atlas = atlas
        self.gains = gains
        self.estimator = BalanceEstimator(atlas)
        self.controller: StandController | None = None
        #: The last step's state and decision (None before the first), for feedback.
        self.last_state: BalanceState | None = None
        self.last_output: StandOutput | None = None

    def start(self, data: mujoco.MjData) -> None:
        """Stand where the robot stands now."""
        state = self.estimator.estimate(data.qpos, data.qvel)
        self.controller = StandController(
            self.estimator.mass_kg, self.atlas.effort_limit_nm, StandReference.from_state(state),
            self.estimator.sole_half_size_m, self.gains)
        self.last_state = state
        self.last_output = None

    def torque(self, data: mujoco.MjData) -> np.ndarray:
        """This step's f_out (N m, (28,)), within the effort limits."""
        controller = self.controller
        if controller is None:
            raise RuntimeError('StandBehaviour.torque before start()')
        atlas = self.atlas
        state = self.estimator.estimate(data.qpos, data.qvel)
        output = controller.step(state, data.qpos[atlas.qpos_adr], data.qvel[atlas.dof_adr])
        self.last_state, self.last_output = state, output
        return output.torque_nm
