"""The control mode and the commands the law applies in it.

Which torque a joint gets (DRCSim 2.5.2's AtlasPlugin, with the port's holds standing in
for BDI's behaviours): in User mode, the law on the user command (JointCommands,
AtlasCommand), its k_effort blending with nothing (BDI outputs no torque in User: a joint
at k_effort 0 is limp); in Stand/StandPrep/Freeze, the hold's torque (what BDI's behaviour
gave), blended with the user command's PID torque on the joints whose k_effort is not 0;
in ragdoll, 0 blended likewise. As AtlasPlugin::OnRobotMode does, a switch to User sets
every k_effort to 1 (255) and any other switch sets them to 0.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np

from tutorial_atlas_control.command import (
    LAW_FIELDS,
    CommandUpdate,
    JointCommandArrays,
    command_update,
)
from tutorial_atlas_control.control_modes import VALID_CONTROL_MODES, ControlMode
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.sim.controller import Gains, hold_command

#: AtlasState's k_effort of a joint driven by the PID law alone (DRCSim: k_effort / 255
#: weighs the PID torque against BDI's f_out, which the port does not have).
K_EFFORT_PID = 255


VALID_MODES: tuple[str, ...] = VALID_CONTROL_MODES
#: What ResetControls' reload_pid_from_ros sets in the user command (k_effort to 1).
GAIN_FIELDS: tuple[str, ...] = ('kp_position', 'ki_position', 'kd_position', 'i_effort_min',
                                'i_effort_max', 'k_effort')
#: The modes whose hold is the pose at the switch (Stand/StandPrep hold the initial pose).
HOLD_AT_SWITCH = (ControlMode.FREEZE, ControlMode.USER)


class ModeError(AtlasControlError):
    """An unknown control mode string."""


def parse_mode(text: str) -> ControlMode:
    """Return the ControlMode for a /atlas/control_mode string.

    Raises:
        ModeError: the string is not one of VALID_MODES (the message lists them).
    """
    if text in VALID_MODES:
        return ControlMode(text)
    shown = text if len(text) <= 40 else text[:40] + '...'
    raise ModeError(f'unknown control mode {shown!r}; valid modes: ' + ', '.join(VALID_MODES))


class ModeCommands:
    """The control mode, its hold, and the user command merged from the messages.

    Reads the measured pose (`joint_positions`) and the torque applied now (`torque_nm`,
    the law's output array) only to hold the current pose at a switch. What the law applies
    is worked out at each change, not each step: `law_command` and `blend_command` are
    attributes the 1 kHz step reads without a call (commands are replaced, never edited in
    place, so a change always passes through here).
    """

    def __init__(self, gains: Gains, joint_positions: Callable[[], np.ndarray],
                 torque_nm: np.ndarray) -> None:
        self.gains = gains
        self._joint_positions = joint_positions
        self._torque_nm = torque_nm
        self._mode = ControlMode.STAND
        self._user_command: JointCommandArrays | None = None
        # Stand/StandPrep hold the initial pose (all joints 0) with the parameter gains.
        self._stand_command = hold_command(gains, np.zeros(NUM_JOINTS))
        self._mode_command = self._stand_command
        self._ragdoll_command = JointCommandArrays.zeros()
        #: The mode's command the law applies: the user command in User mode, else the hold
        #: (or ragdoll's zeros), whose torque is f_out for blend_command.
        self.law_command = self._mode_command
        #: Outside User mode, the user command when some of its k_effort are not 0: its PID
        #: torque is blended with the hold's; else None (the hold alone).
        self.blend_command: JointCommandArrays | None = None

    @property
    def mode(self) -> ControlMode:
        return self._mode

    @property
    def user_command(self) -> JointCommandArrays | None:
        """The command merged from JointCommands and AtlasCommand (None: none since reset)."""
        return self._user_command

    @user_command.setter
    def user_command(self, command: JointCommandArrays | None) -> None:
        self._user_command = command
        self._update_law_commands()

    def _update_law_commands(self) -> None:
        """law_command and blend_command from the mode and the commands, after a change."""
        mode, user = self._mode, self._user_command
        if mode is ControlMode.RAGDOLL:
            self.law_command = self._ragdoll_command
        elif mode is ControlMode.USER and user is not None:
            self.law_command = user
        else:
            self.law_command = self._mode_command
        blends = mode is not ControlMode.USER and user is not None and bool(user.k_effort.any())
        self.blend_command = user if blends else None

    def reset(self) -> None:
        """After reset_world: the robot waits for fresh commands rather than jumping to a
        stale target, and Freeze/User hold the reset pose."""
        if self._mode in HOLD_AT_SWITCH:
            self._mode_command = self.hold_current_pose()
        self.user_command = None

    def set_mode(self, mode: ControlMode) -> None:
        """Switch control mode; Freeze and User start by holding the current pose.

        The user command's k_effort becomes 1 in User, 0 otherwise (AtlasPlugin::OnRobotMode:
        LoadPIDGainsFromParameter, ZeroAtlasCommand); its other fields are kept.
        """
        if mode in (ControlMode.STAND, ControlMode.STAND_PREP, ControlMode.WALK,
                    ControlMode.STEP):
            self._mode_command = self._stand_command
        elif mode in HOLD_AT_SWITCH:
            self._mode_command = self.hold_current_pose()
        self._mode = mode
        command = self._user_command
        if command is not None:
            command = command.copy()
            command.k_effort.fill(self._mode_k_effort())
        self.user_command = command  # law_command and blend_command follow

    def _mode_k_effort(self) -> float:
        """k_effort a mode gives the user command: 1 in User (the PID alone), else 0."""
        return 1.0 if self.mode is ControlMode.USER else 0.0

    def hold_current_pose(self) -> JointCommandArrays:
        """Target = the measured pose, feed-forward = the torque applied now.

        A bumpless transfer: holding the measured pose with the PD gains alone would let
        each joint sag again under the load it already sagged under (the robot leans
        further and, mid-sway, falls); keeping the present torque as `effort` makes the
        switch seamless.
        """
        command = hold_command(self.gains, self._joint_positions())
        command.effort[:] = self._torque_nm
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
                        else self.hold_current_pose())
        merged = previous.copy()  # the law may hold `previous`; never edit it in place
        if self.user_command is None:
            merged.k_effort.fill(self._mode_k_effort())
        for update in updates:
            update.apply_to(merged)
        self.user_command = merged

    def load_gains(self, gains: Gains) -> None:
        """The user command's gains from `gains`, k_effort 1 on every joint
        (ResetControls' reload_pid_from_ros: AtlasPlugin::LoadPIDGainsFromParameter);
        targets, velocity gain and feed-forward kept."""
        gain_command = hold_command(gains, np.zeros(NUM_JOINTS))
        rows = tuple(LAW_FIELDS.index(name) for name in GAIN_FIELDS)
        values = np.array([getattr(gain_command, name) for name in GAIN_FIELDS])  # k_effort 1
        self.receive_updates([CommandUpdate(np.arange(NUM_JOINTS), rows, values)])

    def pid_command(self) -> JointCommandArrays:
        """The command whose PID torque k_effort weighs, as AtlasState reports it: the user
        command blended under a hold, else the mode's command (the hold's PID alone)."""
        blended = self.blend_command
        return self.law_command if blended is None else blended

    def active_k_effort(self) -> np.ndarray:
        """AtlasState's k_effort (uint8, (28,)): pid_command()'s, times 255."""
        return np.rint(self.pid_command().k_effort * K_EFFORT_PID).astype(np.uint8)
