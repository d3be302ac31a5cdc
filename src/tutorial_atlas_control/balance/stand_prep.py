"""StandPrep: the passive stance of a harnessed robot, from which Stand takes over.

DRCSim's library brought the joints of a robot hanging in its harness to the pose Stand
starts from; VRCPlugin's SetPIDStand names it the "StandPrep end pose --> Stand pose". Here
each joint follows a smoothstep from where it is to DRCSim's Stand pose over PREP_S under a
PD with the parameter gains (the tutorial's p and d), and holds it: no balance, which a robot
in the air does not need. The numbers are ours.
"""

from __future__ import annotations

import mujoco
import numpy as np

from tutorial_atlas_control.balance.blend import smoothstep
from tutorial_atlas_control.balance.errors import BalanceError
from tutorial_atlas_control.balance.stand_pose import STAND_POSE_RAD
from tutorial_atlas_control.sim import AtlasModel, Gains

__all__ = ['PREP_S', 'StandPrepBehaviour']

#: How long StandPrep takes to reach the Stand pose (s).
PREP_S = 2.0


class StandPrepBehaviour:
    """A PD to the Stand pose, reached over PREP_S from where the joints are at its start."""

    def __init__(self, atlas: AtlasModel, gains: Gains, prep_s: float = PREP_S) -> None:
        self.atlas = atlas
        self.kp = np.asarray(gains.p, dtype=float)
        self.kd = np.asarray(gains.d, dtype=float)
        self.prep_s = prep_s
        self._start: tuple[float, np.ndarray] | None = None

    def start(self, data: mujoco.MjData) -> None:
        self._start = (float(data.time), data.qpos[self.atlas.qpos_adr].copy())

    def target_at(self, time_s: float) -> np.ndarray:
        """The pose (rad) followed at `time_s`: the Stand pose once PREP_S has passed."""
        if self._start is None:
            raise BalanceError('StandPrepBehaviour.target_at before start()')
        started_s, initial = self._start
        s = smoothstep((time_s - started_s) / self.prep_s if self.prep_s > 0.0 else 1.0)
        return (1.0 - s) * initial + s * STAND_POSE_RAD

    def torque(self, data: mujoco.MjData) -> np.ndarray:
        """This tick's f_out (N m, (28,)); the simulator clamps it to the effort limits."""
        atlas = self.atlas
        return (self.kp * (self.target_at(float(data.time)) - data.qpos[atlas.qpos_adr])
                - self.kd * data.qvel[atlas.dof_adr])
