"""The Atlas simulation without ROS: modes, pinning, the controller law and stepping.

The ROS node (sim_node.py) owns one AtlasSimulator and only translates messages;
everything that decides what torque a joint gets lives here, so it is unit-tested
without a master and shared with offline replay.

Which torque a joint gets (DRCSim 2.5.2's AtlasPlugin, with the port's holds standing in
for BDI's behaviours): in User mode, the law on the user command (JointCommands,
AtlasCommand), its k_effort blending with nothing (BDI outputs no torque in User: a joint
at k_effort 0 is limp); in Stand/StandPrep/Freeze, the hold's torque (what BDI's behaviour
gave), blended with the user command's PID torque on the joints whose k_effort is not 0;
in ragdoll, 0 blended likewise. As AtlasPlugin::OnRobotMode does, a switch to User sets
every k_effort to 1 (255) and any other switch sets them to 0.
"""

from __future__ import annotations

import copy
import dataclasses
import enum
import hashlib
from collections.abc import Mapping, Sequence

import mujoco
import numpy as np

from tutorial_atlas_control import native
from tutorial_atlas_control.command.arrays import (
    LAW_FIELDS,
    CommandUpdate,
    JointCommandArrays,
    command_update,
)
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.sim import law_kernel
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import Gains, PidState, compute_torque, hold_command
from tutorial_atlas_control.sim.sim_config import SimConfig
from tutorial_atlas_control.sim.vrc import (
    DEFAULT_STARTUP_MODE,
    CmdVelInput,
    InputEvent,
    ModeInput,
    PoseInput,
    SimInput,
    TrajectoryInput,
    VrcMode,
    VrcState,
    WrenchInput,
)
from tutorial_atlas_control.units import NS_PER_S

#: DRCSim released the pinned torso after this long (s); `/atlas/time_to_unpin` overrides it.
DEFAULT_TIME_TO_UNPIN_S = 1.0
#: AtlasState's k_effort of a joint driven by the PID law alone (DRCSim: k_effort / 255
#: weighs the PID torque against BDI's f_out, which the port does not have).
K_EFFORT_PID = 255


#: MuJoCo's warnings for an unstable step (plain ints: indexing MjData's counters with the
#: enums is slower, and this runs every step), each with what it means.
DIVERGENCE_WARNINGS = (
    (int(mujoco.mjtWarning.mjWARN_BADQPOS), 'NaN/Inf/huge joint position'),
    (int(mujoco.mjtWarning.mjWARN_BADQVEL), 'NaN/Inf/huge joint velocity'),
    (int(mujoco.mjtWarning.mjWARN_BADQACC), 'NaN/Inf/huge joint acceleration'),
)

class ControlMode(str, enum.Enum):
    """The strings DRCSim accepted on /atlas/control_mode."""

    STAND = 'Stand'
    STAND_PREP = 'StandPrep'
    FREEZE = 'Freeze'
    RAGDOLL = 'ragdoll'
    USER = 'User'


VALID_MODES: tuple[str, ...] = tuple(mode.value for mode in ControlMode)
#: What ResetControls' reload_pid_from_ros sets in the user command (k_effort to 1).
GAIN_FIELDS: tuple[str, ...] = ('kp_position', 'ki_position', 'kd_position', 'i_effort_min',
                                'i_effort_max', 'k_effort')


class ModeError(AtlasControlError):
    """An unknown control mode string."""


class PhysicsDivergenceError(AtlasControlError):
    """The physics produced NaN/Inf or MuJoCo flagged an unstable step."""


def parse_mode(text: str) -> ControlMode:
    """Return the ControlMode for a /atlas/control_mode string.

    Raises:
        ModeError: the string is not one of VALID_MODES (the message lists them).
    """
    try:
        return ControlMode(text)
    except ValueError:
        shown = text if len(text) <= 40 else text[:40] + '...'
        raise ModeError(f'unknown control mode {shown!r}; valid modes: '
                        + ', '.join(VALID_MODES)) from None


class AtlasSimulator:
    """One Atlas in MuJoCo, driven by DRCSim's per-joint controller law.

    Not thread-safe: the ROS node calls every method under its own lock.
    """

    def __init__(self, atlas: atlas_model.AtlasModel, gains: Gains,
                 time_to_unpin_s: float = DEFAULT_TIME_TO_UNPIN_S,
                 compiled_law: bool = True,
                 startup_mode: VrcMode = DEFAULT_STARTUP_MODE) -> None:
        """`compiled_law`: run the law through law_kernel's C kernel when it is built
        (the same torques bit for bit, faster); False: always controller.compute_torque.
        `startup_mode`: one of vrc.STARTUP_MODES, what reset_world starts the robot in."""
        # A model of its own: the cheats move the pin weld's target (model.eq_data), which
        # must not move the pin of another simulator sharing the compiled model.
        atlas = dataclasses.replace(atlas, model=copy.deepcopy(atlas.model))
        self.atlas = atlas
        # The path comes with the compiled model, so the config cannot name another file.
        self.atlas_path = atlas.path
        self.atlas_sha1 = hashlib.sha1(atlas.path.read_bytes()).hexdigest()
        self.model = atlas.model
        self.data = mujoco.MjData(self.model)
        self.gains = gains
        self.time_to_unpin_s = time_to_unpin_s
        self.dt_s = float(self.model.opt.timestep)
        self.step_ns = int(round(self.dt_s * NS_PER_S))
        self.mode = ControlMode.STAND
        self.user_command: JointCommandArrays | None = None
        self.torque_nm = np.zeros(NUM_JOINTS)
        # The law's memory for the mode's command (the user command in User mode, else the
        # hold), and for the user command's PID while it is blended with a hold.
        self._pid = PidState()
        self._blend_pid = PidState()
        self._hold_torque_nm = np.zeros(NUM_JOINTS)  # the hold's torque: f_out when blending
        self._compiled_law = self._compiled_hold = self._compiled_blend = None
        if compiled_law:
            self._make_compiled_laws()
        self._warning_counts = self.data.warning.number  # a view: MuJoCo's counters
        # Stand/StandPrep hold the initial pose (all joints 0) with the parameter gains.
        self._stand_command = hold_command(gains, np.zeros(NUM_JOINTS))
        self._mode_command = self._stand_command
        self._ragdoll_command = JointCommandArrays.zeros()
        self.sim_time_ns = 0
        self.startup_mode = startup_mode
        # VRCPlugin's cheats (modes, teleport, cmd_vel, pelvis wrench, kinematic playback).
        self.vrc = VrcState(atlas, self.data)
        #: How many inputs were applied since the last reset, and the last one (sim time (ns)
        #: before the step it first acted in, input): /atlas/sim_inputs publishes each for
        #: replay. Only a count is kept: a 1 kHz wrench stream must not grow a list.
        self.inputs_since_reset = 0
        self._last_input: tuple[int, SimInput] | None = None
        self._release_pending = False
        self.reset_world()

    def _make_compiled_laws(self) -> None:
        """The C law: the mode's command into torque_nm and MjData.ctrl, or into the hold's
        torque, and the blended user command; left None (numpy law) if it is not built."""
        library = native.load_library()
        if library is None or self.data.ctrl.shape != self.torque_nm.shape:
            return

        def law(state: PidState, torque: np.ndarray, ctrl: np.ndarray | None,
                f_out: np.ndarray | None = None) -> law_kernel.CompiledLaw:
            return law_kernel.CompiledLaw(
                library, self.data.qpos, self.atlas.qpos_adr, self.data.qvel,
                self.atlas.dof_adr, self.atlas.lower_rad, self.atlas.upper_rad,
                self.atlas.effort_limit_nm, self.dt_s, state, torque, ctrl, f_out)
        self._compiled_law = law(self._pid, self.torque_nm, self.data.ctrl)
        self._compiled_hold = law(self._pid, self._hold_torque_nm, None)
        self._compiled_blend = law(self._blend_pid, self.torque_nm, self.data.ctrl,
                                   self._hold_torque_nm)

    @property
    def uses_compiled_law(self) -> bool:
        return self._compiled_law is not None

    # -- state -------------------------------------------------------------------------
    def reset_world(self) -> None:
        """Robot back to its initial state (pinned again), sim time kept, as Gazebo did."""
        atlas_model.reset_to_initial(self.atlas, self.data)
        self.data.time = self.sim_time_ns / NS_PER_S
        self.last_reset_ns = self.sim_time_ns
        self.state_time_ns = self.sim_time_ns
        self._pid.reset()
        self._blend_pid.reset()
        self.torque_nm[:] = 0.0
        # A reset robot waits for fresh commands rather than jumping to a stale target.
        self.user_command = None
        self.vrc.reset()
        self.inputs_since_reset = 0
        self._last_input = None
        self._pin_until_ns = self.sim_time_ns + int(round(self.time_to_unpin_s * NS_PER_S))
        startup = self.startup_mode
        if startup is VrcMode.PINNED:
            # DRCSim's: pinned with gravity off, nominal after time_to_unpin (0: for good).
            self.vrc.set_mode(VrcMode.PINNED)
            self._release_pending = self.time_to_unpin_s > 0.0
        elif startup is VrcMode.BDI_STAND:
            self._release_pending = False
        else:  # the port's historical start: pinned with gravity for time_to_unpin
            self._set_pinned(self.time_to_unpin_s > 0.0)
            self._release_pending = self.pinned
        if self.mode in (ControlMode.FREEZE, ControlMode.USER):
            self._mode_command = self._hold_current_pose()

    def config(self) -> SimConfig:
        """What re-creates this run offline: the model, its step, pinning and last reset."""
        return SimConfig(model_file=self.atlas_path.name, model_sha1=self.atlas_sha1,
                         timestep_s=self.dt_s, time_to_unpin_s=self.time_to_unpin_s,
                         last_reset_time_s=self.last_reset_ns / NS_PER_S,
                         startup_mode=self.startup_mode.value)

    def reset_simulation(self, sim_time_ns: int = 0) -> None:
        """reset_world, and sim time back to `sim_time_ns`.

        Gazebo's reset_simulation restarts at 0; replay restarts at a recorded reset.
        """
        self.sim_time_ns = sim_time_ns
        self.reset_world()

    def _set_pinned(self, pinned: bool) -> None:
        atlas_model.set_pelvis_pinned(self.atlas, self.data, pinned)

    @property
    def pinned(self) -> bool:
        """The pelvis is welded (the start-up pin, a pinned mode, or cmd_vel's warp)."""
        return self.vrc.is_pinned()

    @property
    def playing(self) -> bool:
        """A /joint_trajectory is playing: physics is off."""
        return self.vrc.playback is not None

    # -- VRCPlugin's inputs ----------------------------------------------------------------
    def apply_input(self, item: SimInput) -> None:
        """Apply one checked input now, between two steps, and log it for replay.

        An explicit /atlas/mode cancels the start-up release (the user's mode stays);
        `bdi_stand` also switches the control mode to Stand (the port's stand-in for BDI's
        stand behaviour).
        """
        vrc = self.vrc
        if isinstance(item, ModeInput):
            self._release_pending = False
            vrc.set_mode(item.mode)
            if item.mode is VrcMode.BDI_STAND:
                self.set_mode(ControlMode.STAND)
        elif isinstance(item, PoseInput):
            vrc.set_pose(item)
        elif isinstance(item, CmdVelInput):
            vrc.set_cmd_vel(item)
        elif isinstance(item, WrenchInput):
            vrc.set_wrench(item)
        elif isinstance(item, TrajectoryInput):
            vrc.start_playback(item, self.sim_time_ns)
        else:  # pragma: no cover - the union is closed
            raise TypeError(f'not a simulator input: {item!r}')
        self.inputs_since_reset += 1
        self._last_input = (self.sim_time_ns, item)

    def last_input_event(self) -> InputEvent:
        """The input apply_input logged last, as /atlas/sim_inputs carries it."""
        assert self._last_input is not None, 'no input applied since the last reset'
        time_ns, item = self._last_input
        return InputEvent(time_ns, self.last_reset_ns, self.inputs_since_reset - 1, item)

    def joint_positions(self) -> np.ndarray:
        return atlas_model.joint_positions(self.atlas, self.data)

    def joint_velocities(self) -> np.ndarray:
        return atlas_model.joint_velocities(self.atlas, self.data)

    # -- commands ----------------------------------------------------------------------
    def set_mode(self, mode: ControlMode) -> None:
        """Switch control mode; Freeze and User start by holding the current pose.

        The user command's k_effort becomes 1 in User, 0 otherwise (AtlasPlugin::OnRobotMode:
        LoadPIDGainsFromParameter, ZeroAtlasCommand); its other fields are kept.
        """
        if mode in (ControlMode.STAND, ControlMode.STAND_PREP):
            self._mode_command = self._stand_command
        elif mode in (ControlMode.FREEZE, ControlMode.USER):
            self._mode_command = self._hold_current_pose()
        # The target changed: restart the derivative so the switch gives no kick.
        self._pid.initialized = False
        self._blend_pid.initialized = False
        self.mode = mode
        if self.user_command is not None:
            command = self.user_command.copy()
            command.k_effort.fill(self._mode_k_effort())
            self.user_command = command

    def _mode_k_effort(self) -> float:
        """k_effort a mode gives the user command: 1 in User (the PID alone), else 0."""
        return 1.0 if self.mode is ControlMode.USER else 0.0

    def _hold_current_pose(self) -> JointCommandArrays:
        """Target = the measured pose, feed-forward = the torque applied now.

        A bumpless transfer: holding the measured pose with the PD gains alone would let
        each joint sag again under the load it already sagged under (the robot leans
        further and, mid-sway, falls); keeping the present torque as `effort` makes the
        switch seamless.
        """
        command = hold_command(self.gains, self.joint_positions())
        command.effort[:] = self.torque_nm
        return command

    def receive_command(self, names: Sequence[str],
                        arrays: Mapping[str, Sequence[float]]) -> None:
        """Merge one JointCommands message into the user command (applied in User mode).

        Raises:
            CommandError: the message is refused whole; the previous command stays.
        """
        self.receive_updates([command_update(names, arrays)])

    def receive_updates(self, updates: Sequence[CommandUpdate]) -> None:
        """Apply checked JointCommands messages, in order, to the user command.

        Joints a message does not name keep their previous command; before the first
        command that is the current pose with the parameter-server gains.
        """
        if not updates:
            return
        previous = self.user_command
        if previous is None:
            previous = (self._mode_command if self.mode is ControlMode.USER
                        else self._hold_current_pose())
        merged = previous.copy()  # the law may hold `previous`; never edit it in place
        if self.user_command is None:
            merged.k_effort.fill(self._mode_k_effort())
        for update in updates:
            update.apply_to(merged)
        self.user_command = merged

    def active_command(self) -> JointCommandArrays:
        """The mode's command the law applies this step: the user command in User mode,
        else the hold (or ragdoll's zeros), whose torque is f_out for blended_command()."""
        if self.mode is ControlMode.RAGDOLL:
            return self._ragdoll_command
        if self.mode is ControlMode.USER and self.user_command is not None:
            return self.user_command
        return self._mode_command

    def blended_command(self) -> JointCommandArrays | None:
        """Outside User mode, the user command when some of its k_effort are not 0: its PID
        torque is blended with the hold's; else None (the hold alone)."""
        command = self.user_command
        if self.mode is ControlMode.USER or command is None or not command.k_effort.any():
            return None
        return command

    def reset_pid(self) -> None:
        """Forget the law's integrals and previous errors (ResetControls'
        reset_pid_controller); the derivative restarts without a kick."""
        self._pid.reset()
        self._blend_pid.reset()

    def load_gains(self, gains: Gains) -> None:
        """The user command's gains from `gains`, k_effort 1 on every joint
        (ResetControls' reload_pid_from_ros: AtlasPlugin::LoadPIDGainsFromParameter);
        targets, velocity gain and feed-forward kept."""
        gain_command = hold_command(gains, np.zeros(NUM_JOINTS))
        rows = tuple(LAW_FIELDS.index(name) for name in GAIN_FIELDS)
        values = np.array([getattr(gain_command, name) for name in GAIN_FIELDS])  # k_effort 1
        self.receive_updates([CommandUpdate(np.arange(NUM_JOINTS), rows, values)])

    def joint_damping(self) -> np.ndarray:
        """The joints' viscous damping (N m s/rad), tutorial order."""
        return self.model.dof_damping[self.atlas.dof_adr].copy()

    def set_joint_damping(self, damping: np.ndarray) -> None:
        """Set the joints' viscous damping (N m s/rad, (28,)), as /atlas/debug/test does
        (Gazebo's Joint::SetDamping); kept across resets, as in Gazebo."""
        self.model.dof_damping[self.atlas.dof_adr] = damping

    def pid_command(self) -> JointCommandArrays:
        """The command whose PID torque k_effort weighs, as AtlasState reports it: the user
        command blended under a hold, else the mode's command (the hold's PID alone)."""
        blended = self.blended_command()
        return self.active_command() if blended is None else blended

    def active_k_effort(self) -> np.ndarray:
        """AtlasState's k_effort (uint8, (28,)): pid_command()'s, times 255."""
        return np.rint(self.pid_command().k_effort * K_EFFORT_PID).astype(np.uint8)

    # -- stepping ----------------------------------------------------------------------
    def step(self, torque_nm: np.ndarray | None = None) -> None:
        """Advance one physics step with the controller law's torque, or with `torque_nm`.

        Offline replay passes the recorded torque (N m, (28,)): the pin release and the
        divergence check are then the very code the node runs.

        Raises:
            PhysicsDivergenceError: the new state is not finite (the caller resets).
        """
        if self._release_pending and self.sim_time_ns >= self._pin_until_ns:
            self._release_pending = False
            if self.startup_mode is VrcMode.PINNED:
                self.vrc.set_mode(VrcMode.NOMINAL)
            else:
                self._set_pinned(False)
        vrc = self.vrc
        if vrc.active:
            self._step_with_cheats(torque_nm)
            return
        if torque_nm is not None:
            self.torque_nm[:] = torque_nm
            self.data.ctrl[:] = self.torque_nm
        elif self._compiled_law is not None:
            blended = self.blended_command()
            if blended is None:
                self._compiled_law(self.active_command())  # sets torque_nm and data.ctrl
            else:
                self._compiled_hold(self.active_command())  # f_out
                self._compiled_blend(blended)
        else:
            self._law_torque(self._pid, out=self.torque_nm)
            self.data.ctrl[:] = self.torque_nm
        mujoco.mj_step(self.model, self.data)
        # mj_step integrates last: joint positions/velocities are at the new time, while body
        # poses and sensor readings were computed before integrating, at the step's start.
        self.state_time_ns = self.sim_time_ns
        self.sim_time_ns += self.step_ns
        self._check_divergence()

    def _step_with_cheats(self, torque_nm: np.ndarray | None) -> None:
        """step() while a cheat acts: kinematic playback (physics off, no torque), or the
        warp and the extra body forces around the usual step."""
        vrc = self.vrc
        if vrc.playback is not None:
            vrc.playback_step(self.sim_time_ns)
            self.torque_nm[:] = 0.0
            self.data.ctrl[:] = 0.0
            self.state_time_ns = self.sim_time_ns
            self.sim_time_ns += self.step_ns
            self.data.time = self.sim_time_ns / NS_PER_S
            return
        vrc.warp_step(self.dt_s)
        data = self.data
        viewer_xfrc = data.xfrc_applied.copy()  # the viewer's mouse forces, if any
        data.xfrc_applied += vrc.xfrc
        if torque_nm is not None:
            self.torque_nm[:] = torque_nm
            data.ctrl[:] = self.torque_nm
        elif self._compiled_law is not None:
            self._compiled_law(self.active_command())
        else:
            self._law_torque(self._pid, out=self.torque_nm)
            data.ctrl[:] = self.torque_nm
        mujoco.mj_step(self.model, data)
        data.xfrc_applied[:] = viewer_xfrc
        self.state_time_ns = self.sim_time_ns
        self.sim_time_ns += self.step_ns
        self._check_divergence()

    def next_law_torque(self) -> np.ndarray:
        """The torque (N m) the law would apply at the next step; the law's memory is kept."""
        return self._law_torque(copy.deepcopy(self._pid), copy.deepcopy(self._blend_pid))

    def _law_torque(self, pid: PidState, blend_pid: PidState | None = None,
                    out: np.ndarray | None = None) -> np.ndarray:
        q, v = self.joint_positions(), self.joint_velocities()
        limits = (self.atlas.lower_rad, self.atlas.upper_rad, self.atlas.effort_limit_nm)
        blended = self.blended_command()
        if blended is None:
            return compute_torque(self.active_command(), q, v, pid, self.dt_s, *limits, out=out)
        hold = compute_torque(self.active_command(), q, v, pid, self.dt_s, *limits,
                              out=self._hold_torque_nm)
        return compute_torque(blended, q, v, self._blend_pid if blend_pid is None else blend_pid,
                              self.dt_s, *limits, out=out, f_out=hold)

    def _check_divergence(self) -> None:
        """Raise on an unstable step.

        MuJoCo resets the state by itself on NaN/Inf/huge values and only warns: catching
        it here means no silently reset (or non-finite) state is ever published or replayed.
        """
        counts = self._warning_counts
        for warning, what in DIVERGENCE_WARNINGS:
            if counts[warning] > 0:
                counts[warning] = 0
                raise PhysicsDivergenceError(
                    f'physics diverged at t={self.sim_time_ns / NS_PER_S:.3f} s ({what})')
        compiled = self._compiled_law
        if compiled is not None:
            finite = compiled.state_is_finite()
        else:
            finite = bool(np.isfinite(self.data.qpos).all() and np.isfinite(self.data.qvel).all())
        if not finite:
            raise PhysicsDivergenceError(
                f'physics diverged at t={self.sim_time_ns / NS_PER_S:.3f} s (non-finite state)')
