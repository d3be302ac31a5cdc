"""The balancing Stand as the simulator's Stand behaviour (sim/behaviour.py's protocol).

On start it holds the robot where it stands (StandReference.from_state: the capture point
over the soles' midpoint, the pelvis upright at its yaw) and, over TRANSITION_S, brings the
posture and the centre-of-mass height from where they are to DRCSim's Stand pose (a
smoothstep: no jump in the reference, none in the torque). A robot taken over standing
straight under the hold thus bends its knees to the Stand pose instead of fighting it.
Each step it estimates the state from the simulator's MjData and returns the controller's
torque, which the simulator blends with the user's PID by k_effort as f_out.
"""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np

from tutorial_atlas_control.balance.estimator import BalanceEstimator, BalanceState
from tutorial_atlas_control.balance.stand import (
    StandController,
    StandGains,
    StandOutput,
    StandReference,
)
from tutorial_atlas_control.balance.stand_pose import STAND_POSE_RAD, place_in_stand_pose
from tutorial_atlas_control.sim import AtlasModel

__all__ = ['TRANSITION_S', 'StandBehaviour', 'stand_pose_com_height_m']

#: How long Stand takes to bring the robot from where it starts to the Stand pose (s).
TRANSITION_S = 1.0


def stand_pose_com_height_m(atlas: AtlasModel) -> float:
    """The centre of mass's height (m) of the robot in the Stand pose, feet on the ground."""
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    mujoco.mj_comPos(atlas.model, data)
    return float(data.subtree_com[0][2])


def smoothstep(fraction: float) -> float:
    """0 at 0, 1 at 1 and beyond, with zero slope at both ends."""
    s = min(max(fraction, 0.0), 1.0)
    return s * s * (3.0 - 2.0 * s)


class StandBehaviour:
    """Capture-point Stand for one simulator's robot."""

    def __init__(self, atlas: AtlasModel, gains: StandGains | None = None,
                 transition_s: float = TRANSITION_S) -> None:
        self.atlas = atlas
        self.gains = gains
        self.transition_s = transition_s
        self.estimator = BalanceEstimator(atlas)
        self.com_height_m = stand_pose_com_height_m(atlas)
        self.controller: StandController | None = None
        #: The last step's state and decision (None before the first), for feedback.
        self.last_state: BalanceState | None = None
        self.last_output: StandOutput | None = None
        self._start: tuple[float, StandReference] | None = None  # (sim time, reference)

    def start(self, data: mujoco.MjData) -> None:
        """Stand where the robot stands now, going to the Stand pose over transition_s."""
        state = self.estimator.estimate(data.qpos, data.qvel)
        held = StandReference.from_state(state, posture_rad=data.qpos[self.atlas.qpos_adr])
        self.controller = StandController(
            self.estimator.mass_kg, self.atlas.effort_limit_nm, held,
            self.estimator.sole_half_size_m, self.gains)
        self._start = (float(data.time), held)
        self.last_state = state
        self.last_output = None

    def _reference_at(self, time_s: float) -> StandReference:
        """The transition's reference at `time_s`; the Stand pose's once it has ended."""
        assert self._start is not None
        started_s, held = self._start
        fraction = ((time_s - started_s) / self.transition_s if self.transition_s > 0.0
                    else 1.0)
        s = smoothstep(fraction)
        reference = dataclasses.replace(
            held, com_height_m=(1.0 - s) * held.com_height_m + s * self.com_height_m,
            posture_rad=(1.0 - s) * held.posture_rad + s * STAND_POSE_RAD)
        if fraction >= 1.0:
            self._start = None
        return reference

    def torque(self, data: mujoco.MjData) -> np.ndarray:
        """This step's f_out (N m, (28,)), within the effort limits."""
        controller = self.controller
        if controller is None:
            raise RuntimeError('StandBehaviour.torque before start()')
        if self._start is not None:
            controller.reference = self._reference_at(float(data.time))
        atlas = self.atlas
        state = self.estimator.estimate(data.qpos, data.qvel)
        output = controller.step(state, data.qpos[atlas.qpos_adr], data.qvel[atlas.dof_adr])
        self.last_state, self.last_output = state, output
        return output.torque_nm
