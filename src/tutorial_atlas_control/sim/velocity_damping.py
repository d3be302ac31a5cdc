"""The velocity gain as the joints' damping, as DRCSim 2.7 applied kp_velocity.

DRCSim 2.5.2 added kp_velocity * (velocity - v) to each joint's torque every 1 ms step. On
Atlas v1's light links (wrists, elbows, neck, the feet through the floating base) a gain of
50 N m s/rad is past that explicit term's stability limit (gain * dt / inertia > 2): the
torques flip between their limits each step and the robot slides and falls. DRCSim 2.7
(AtlasPlugin::UpdatePIDControl) passed kp_velocity through to the joint's damping instead
("simulating infinite bandwidth kp_velocity"), clamped to [the model's damping, effort limit
/ velocity limit * 50], and kept kp_velocity * velocity in the torque (controller.py).
MuJoCo's implicitfast integrator integrates dof_damping implicitly, so any gain is stable.

One deviation: a joint gets its PID's share of the gain, model + k_effort * (passed - model).
2.7 set the damping whatever k_effort, under BDI's behaviours too; here a joint a behaviour
drives (k_effort 0) is not slowed by a gain meant for the user's PID. The torque reported
(joint_states effort, AtlasState) is the law's, without the damping's, as 2.7's.
"""

from __future__ import annotations

import numpy as np

from tutorial_atlas_control.command import JointCommandArrays

__all__ = ['MAX_DAMPING_PER_LIMIT', 'VelocityDamping']

#: 2.7's most damping a gain passes through: this many times effort limit / velocity limit.
MAX_DAMPING_PER_LIMIT = 50.0


class VelocityDamping:
    """Sets the joints' damping (`dof_damping`, the model's array, at `dof_adr`) each step
    from the velocity gain of the command in force."""

    def __init__(self, dof_damping: np.ndarray, dof_adr: np.ndarray, effort_limit_nm: np.ndarray,
                 velocity_limit_rad_s: np.ndarray) -> None:
        self._dof_damping = dof_damping
        self._dof_adr = dof_adr
        #: The model's own damping (N m s/rad, (28,)); /atlas/debug/test sets it.
        self.model_nm_s = dof_damping[dof_adr].copy()
        #: The most a gain passes through (N m s/rad, (28,)).
        self.most_nm_s = effort_limit_nm / velocity_limit_rad_s * MAX_DAMPING_PER_LIMIT
        #: Whether the damping now holds a gain (else it is the model's).
        self.passing = False

    def set_model(self, damping_nm_s: np.ndarray) -> None:
        """The model's own damping (N m s/rad, (28,)): the floor a gain passes through."""
        self.model_nm_s[:] = damping_nm_s
        self._dof_damping[self._dof_adr] = self.model_nm_s
        self.passing = False

    def damping(self, gains: JointCommandArrays) -> np.ndarray:
        """Each joint's damping (N m s/rad, (28,)) under `gains`: its kp_velocity clamped as
        Gazebo's math::clamp(kp, model, most), weighted by k_effort above the model's."""
        model = self.model_nm_s
        passed = np.maximum(np.minimum(gains.kp_velocity, self.most_nm_s), model)
        return model + gains.k_effort * (passed - model)

    def apply(self, gains: JointCommandArrays | None) -> None:
        """This step's damping: `gains`' velocity gain passed through; the model's where
        `gains` is None (a behaviour alone, a recorded torque) or has no velocity gain."""
        if gains is None or not gains.kp_velocity.any():
            if self.passing:
                self._dof_damping[self._dof_adr] = self.model_nm_s
                self.passing = False
            return
        self._dof_damping[self._dof_adr] = self.damping(gains)
        self.passing = True
