"""The controller law applied to one simulator's joints: the one place that chooses how.

Each step the mode's command (the user command in User mode, else the hold) gives the
torque; outside User mode a user command with some k_effort not 0 is blended with that
hold's torque (f_out); under a behaviour (apply_behaviour) its torque is f_out instead.
Whether the compiled kernel (law_kernel) or the numpy law
(controller.compute_torque) computes it, JointLaw.apply() is the only call every kind of
step makes (plain, under a cheat), so the two laws cannot take different branches.
"""

from __future__ import annotations

import copy

import mujoco
import numpy as np

from tutorial_atlas_control import native
from tutorial_atlas_control.command import JointCommandArrays
from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.sim.controller import PidState, compute_torque
from tutorial_atlas_control.sim.law_kernel import CompiledLaw, LawJoints
from tutorial_atlas_control.sim.model import AtlasModel
from tutorial_atlas_control.sim.velocity_damping import VelocityDamping


class JointLaw:
    """The law's memory and output for one MjData: torque_nm (N m, (28,)), also written to
    MjData.ctrl, from the mode's command and the blended user command.

    `compiled`: run the law through law_kernel's C kernel when the library is built (the
    same torques bit for bit, faster); False, or no library: controller.compute_torque.
    """

    def __init__(self, atlas: AtlasModel, data: mujoco.MjData, dt_s: float,
                 compiled: bool = True) -> None:
        self.joints = LawJoints(data.qpos, atlas.qpos_adr, data.qvel, atlas.dof_adr,
                                atlas.lower_rad, atlas.upper_rad, atlas.effort_limit_nm, dt_s)
        self.torque_nm = np.zeros(NUM_JOINTS)
        #: The memory of the mode's command, and of the user command blended under a hold.
        self.pid = PidState()
        self.blend_pid = PidState()
        # f_out when blending: the hold's torque, or a behaviour's
        self._hold_torque_nm = np.zeros(NUM_JOINTS)
        self._ctrl = data.ctrl
        self._plain: CompiledLaw | None = None
        self._hold: CompiledLaw | None = None
        self._blend: CompiledLaw | None = None
        library = native.load_library() if compiled else None
        if library is not None and self._ctrl.shape == self.torque_nm.shape:
            joints = self.joints
            self._plain = CompiledLaw(library, joints, self.pid, self.torque_nm, self._ctrl)
            self._hold = CompiledLaw(library, joints, self.pid, self._hold_torque_nm)
            self._blend = CompiledLaw(library, joints, self.blend_pid, self.torque_nm,
                                      self._ctrl, self._hold_torque_nm)
        #: The effort limits' negatives (N m): a behaviour's torque's lower bound.
        self._lowest_nm = -self.joints.effort_limit
        #: A lone behaviour's torque, copied into _hold_torque_nm, limited into it, torque_nm
        #: and ctrl by one C call (None: numpy's).
        self._limit_behaviour = None if self._blend is None else self._blend.behaviour_call()
        #: The velocity gain of the command in force, as the joints' damping (DRCSim 2.7).
        self.velocity_damping = VelocityDamping(atlas.model.dof_damping, atlas.dof_adr,
                                                atlas.effort_limit_nm, atlas.velocity_limit_rad_s)
        #: Every qpos and qvel finite? (the kernel's one C call when compiled)
        self.state_is_finite = (self._numpy_state_is_finite if self._plain is None
                                else self._plain.state_is_finite)

    @property
    def f_out_nm(self) -> np.ndarray:
        """The f_out of the last blended step (N m, (28,)): the hold's or the behaviour's
        torque the user's PID was blended with (read-only view)."""
        view = self._hold_torque_nm.view()
        view.setflags(write=False)
        return view

    @property
    def kernel(self) -> CompiledLaw | None:
        """The compiled law's plain call (None: numpy's law)."""
        return self._plain

    @property
    def compiled(self) -> bool:
        return self._plain is not None

    def apply(self, command: JointCommandArrays, blended: JointCommandArrays | None) -> None:
        """One step of the law: `command`'s torque, or, when `blended` is not None, its PID
        torque blended by k_effort with `command`'s (the hold's); into torque_nm and ctrl;
        the velocity gain of the user's command (`blended`, else `command`) into the joints'
        damping."""
        self.velocity_damping.apply(command if blended is None else blended)
        plain = self._plain
        if plain is None:
            self._numpy_torque(command, blended, self.pid, self.blend_pid, self.torque_nm)
            self._ctrl[:] = self.torque_nm
        elif blended is None:
            plain(command)
        else:
            self._hold(command)  # type: ignore[misc]  # set with _plain
            self._blend(blended)  # type: ignore[misc]

    def apply_behaviour(self, f_out_nm: np.ndarray, blended: JointCommandArrays | None) -> None:
        """One step under a behaviour (sim/behaviour.py): its torque `f_out_nm` (N m, (28,))
        within the effort limits, or, when `blended` is not None, `blended`'s PID torque
        blended with it by k_effort, as apply() blends a hold's; into torque_nm and ctrl;
        `blended`'s velocity gain into the joints' damping."""
        self.velocity_damping.apply(blended)
        f_out = self._hold_torque_nm
        if blended is None and self._limit_behaviour is not None:  # every walk's step
            f_out[:] = f_out_nm
            self._limit_behaviour()
            return
        limit = self.joints.effort_limit
        # np.clip's own arithmetic (max, then min) without its Python wrappers: every step
        np.maximum(f_out_nm, self._lowest_nm, out=f_out)
        np.minimum(f_out, limit, out=f_out)
        if blended is None:
            self.torque_nm[:] = f_out
            self._ctrl[:] = f_out
        elif self._blend is not None:
            self._blend(blended)
        else:
            joints = self.joints
            compute_torque(blended, joints.positions(), joints.velocities(), self.blend_pid,
                           joints.dt_s, joints.lower, joints.upper, limit, out=self.torque_nm,
                           f_out=f_out)
            self._ctrl[:] = self.torque_nm

    def predict_behaviour(self, f_out_nm: np.ndarray,
                          blended: JointCommandArrays | None) -> np.ndarray:
        """The torque (N m) apply_behaviour() would give now; the law's memory is kept."""
        joints = self.joints
        limit = joints.effort_limit
        f_out = np.clip(f_out_nm, -limit, limit)
        if blended is None:
            return f_out
        return compute_torque(blended, joints.positions(), joints.velocities(),
                              copy.deepcopy(self.blend_pid), joints.dt_s, joints.lower,
                              joints.upper, limit, f_out=f_out)

    def set_torque(self, torque_nm: np.ndarray | float) -> None:
        """Apply `torque_nm` instead of the law (a recorded torque; 0 while physics is off)."""
        self.velocity_damping.apply(None)
        self.torque_nm[:] = torque_nm
        self._ctrl[:] = self.torque_nm

    def predict(self, command: JointCommandArrays,
                blended: JointCommandArrays | None) -> np.ndarray:
        """The torque (N m) apply() would give now; the law's memory is kept."""
        return self._numpy_torque(command, blended, copy.deepcopy(self.pid),
                                  copy.deepcopy(self.blend_pid), np.empty(NUM_JOINTS),
                                  hold_nm=np.empty(NUM_JOINTS))

    def reset(self) -> None:
        """Forget the integrals and previous errors (ResetControls' reset_pid_controller); the
        derivative restarts without a kick."""
        self.pid.reset()
        self.blend_pid.reset()

    def restart_derivative(self) -> None:
        """The target changed (a mode switch): the next step's derivative term is 0."""
        self.pid.initialized = False
        self.blend_pid.initialized = False

    def _numpy_torque(self, command: JointCommandArrays, blended: JointCommandArrays | None,
                      pid: PidState, blend_pid: PidState, out: np.ndarray,
                      hold_nm: np.ndarray | None = None) -> np.ndarray:
        joints = self.joints
        q, v = joints.positions(), joints.velocities()
        limits = (joints.lower, joints.upper, joints.effort_limit)
        if blended is None:
            return compute_torque(command, q, v, pid, joints.dt_s, *limits, out=out)
        hold = compute_torque(command, q, v, pid, joints.dt_s, *limits,
                              out=self._hold_torque_nm if hold_nm is None else hold_nm)
        return compute_torque(blended, q, v, blend_pid, joints.dt_s, *limits, out=out,
                              f_out=hold)

    def _numpy_state_is_finite(self) -> bool:
        joints = self.joints
        return bool(np.isfinite(joints.qpos).all() and np.isfinite(joints.qvel).all())
