"""The balancing Stand as the simulator's Stand behaviour (sim/behaviour.py's protocol), and
Manipulate's pelvis servo on top of it.

On start it holds the robot where it stands (StandReference.from_state: the capture point
over the soles' midpoint, the pelvis upright at its yaw) and, over TRANSITION_S, brings the
posture and the centre-of-mass height from where they are to DRCSim's Stand pose (a
smoothstep: no jump in the reference, none in the torque). A robot taken over standing
straight under the hold thus bends its knees to the Stand pose instead of fighting it.
`servo` moves the reference the same way to a pelvis height, yaw and lateral offset
(Manipulate, balance/manipulate.py), or back to the Stand pose. Each step it estimates the
state from the simulator's MjData and returns the controller's torque, which the simulator
blends with the user's PID by k_effort as f_out.
"""

from __future__ import annotations

import dataclasses
import functools

import mujoco
import numpy as np

from tutorial_atlas_control.balance.estimator import BalanceEstimator, BalanceState
from tutorial_atlas_control.balance.manipulate import (
    PelvisServo,
    SquatTable,
    bent_posture,
    clamp_servo,
)
from tutorial_atlas_control.balance.stand import (
    StandController,
    StandGains,
    StandOutput,
    StandReference,
    yaw_of,
    yaw_rotation,
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
        #: Manipulate's pelvis target as clamped (None: the Stand pose).
        self.servo_target: PelvisServo | None = None
        #: How many times Stand has started (a restart drops the servo target).
        self.starts = 0
        #: The reference moving on: (start time, from, to); None once it has arrived.
        self._transition: tuple[float, StandReference, StandReference] | None = None

    @functools.cached_property
    def squats(self) -> SquatTable:
        """Manipulate's reach and postures, built when first servoed (not every Stand is)."""
        return SquatTable(self.atlas)

    def start(self, data: mujoco.MjData) -> None:
        """Stand where the robot stands now, going to the Stand pose over transition_s."""
        state = self.estimator.estimate(data.qpos, data.qvel)
        held = StandReference.from_state(state, posture_rad=data.qpos[self.atlas.qpos_adr])
        self.controller = StandController(
            self.estimator.mass_kg, self.atlas.effort_limit_nm, held,
            self.estimator.sole_half_size_m, self.gains)
        self.servo_target = None
        self.starts += 1
        self._transition = (float(data.time), held, dataclasses.replace(
            held, com_height_m=self.com_height_m, posture_rad=STAND_POSE_RAD))
        self.last_state = state
        self.last_output = None

    def servo(self, desired: PelvisServo | None, time_s: float) -> PelvisServo | None:
        """Move the pelvis to `desired` (clamped to what the legs reach; None: back to the
        Stand pose) over transition_s from the present reference; the target as clamped.
        The same target again changes nothing (a client may stream it)."""
        target = None if desired is None else clamp_servo(desired, self.squats)
        if target == self.servo_target:
            return target
        controller, state = self.controller, self.last_state
        if controller is None or state is None:
            raise RuntimeError('StandBehaviour.servo before start()')
        feet = state.sole_centres[:, :2]
        headings = state.sole_rotations[:, 0:2, 0].sum(axis=0)
        feet_yaw = float(np.arctan2(headings[1], headings[0]))
        left = feet[0] - feet[1]
        left /= np.linalg.norm(left)
        if target is None:
            goal = StandReference(feet.mean(axis=0), self.com_height_m, yaw_rotation(feet_yaw),
                                  STAND_POSE_RAD.copy())
        else:
            goal = StandReference(
                feet.mean(axis=0) + target.lateral_m * left,
                self.squats.com_for(target.height_m),
                yaw_rotation(feet_yaw + target.yaw_rad),
                bent_posture(self.squats.knee_for(target.height_m), target.yaw_rad))
        self._transition = (time_s, controller.reference, goal)
        self.servo_target = target
        return target

    def _reference_at(self, time_s: float) -> StandReference:
        """The moving reference at `time_s`; its goal once transition_s has passed."""
        assert self._transition is not None
        started_s, start, goal = self._transition
        fraction = ((time_s - started_s) / self.transition_s if self.transition_s > 0.0
                    else 1.0)
        if fraction >= 1.0:
            self._transition = None
            return goal
        s = smoothstep(fraction)
        start_yaw = yaw_of(start.pelvis_rotation)
        turn = (yaw_of(goal.pelvis_rotation) - start_yaw + np.pi) % (2 * np.pi) - np.pi
        return StandReference(
            (1.0 - s) * start.capture_point + s * goal.capture_point,
            (1.0 - s) * start.com_height_m + s * goal.com_height_m,
            yaw_rotation(start_yaw + s * turn),
            (1.0 - s) * start.posture_rad + s * goal.posture_rad)

    def torque(self, data: mujoco.MjData) -> np.ndarray:
        """This step's f_out (N m, (28,)), within the effort limits."""
        controller = self.controller
        if controller is None:
            raise RuntimeError('StandBehaviour.torque before start()')
        if self._transition is not None:
            controller.reference = self._reference_at(float(data.time))
        atlas = self.atlas
        state = self.estimator.estimate(data.qpos, data.qvel)
        output = controller.step(state, data.qpos[atlas.qpos_adr], data.qvel[atlas.dof_adr])
        self.last_state, self.last_output = state, output
        return output.torque_nm
