"""The Atlas simulation without ROS: one MuJoCo Atlas stepped with the controller law.

The ROS node (sim_node.py) owns one AtlasSimulator and only translates messages;
everything that decides what torque a joint gets lives in this subpackage, so it is
unit-tested without a master and shared with offline replay. AtlasSimulator puts together
its collaborators, each a concern of its own: the mode and its commands (mode_commands),
the law applied to the joints (joint_law), the start-up pin (startup_pin), VRCPlugin's
cheats (vrc), the mud's drag in a world with mud (mud) and the divergence check (divergence).
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
from collections.abc import Callable, Mapping, Sequence

import mujoco
import numpy as np

from tutorial_atlas_control.command import CommandUpdate, JointCommandArrays
from tutorial_atlas_control.course import MUD_DAMPING, Start, start_text
from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.behaviour import Behaviour, ModeBehaviours
from tutorial_atlas_control.sim.body_forces import step_with_body_forces
from tutorial_atlas_control.sim.controller import Gains, hold_command
from tutorial_atlas_control.sim.divergence import (
    DIVERGENCE_WARNINGS,
    DivergenceCheck,
    PhysicsDivergenceError,
)
from tutorial_atlas_control.sim.ground import Ground
from tutorial_atlas_control.sim.joint_law import JointLaw
from tutorial_atlas_control.sim.mode_commands import (
    GAIN_FIELDS,
    K_EFFORT_PID,
    VALID_MODES,
    ControlMode,
    ModeCommands,
    ModeError,
    parse_mode,
)
from tutorial_atlas_control.sim.mud import MudDrag
from tutorial_atlas_control.sim.shared_passes import (
    behaviour_between,
    shares_passes,
    step_behaviour,
)
from tutorial_atlas_control.sim.sim_config import SimConfig
from tutorial_atlas_control.sim.start_pose import home_qpos
from tutorial_atlas_control.sim.startup_pin import StartupEvent, StartupPin
from tutorial_atlas_control.sim.vrc import (
    DEFAULT_STARTUP_MODE,
    STAND_POSE_RAD,
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

__all__ = ['DEFAULT_TIME_TO_UNPIN_S', 'DIVERGENCE_WARNINGS', 'GAIN_FIELDS', 'K_EFFORT_PID',
           'VALID_MODES', 'AtlasSimulator', 'ControlMode', 'ModeError', 'PhysicsDivergenceError',
           'parse_mode']

#: AtlasState's k_effort while a behaviour alone drives every joint.
_NO_PID = np.zeros(NUM_JOINTS, np.uint8)
_NO_PID.setflags(write=False)
#: DRCSim released the pinned torso after this long (s); `/atlas/time_to_unpin` overrides it.
DEFAULT_TIME_TO_UNPIN_S = 1.0


def _placed_cheats(atlas: atlas_model.AtlasModel, data: mujoco.MjData, start: Start | None
                   ) -> tuple[Ground, np.ndarray, VrcState]:
    """The world's ground, the pelvis's qpos (7,) at `start` (soles on that ground; None:
    the origin) and VRCPlugin's cheats (modes, teleport, cmd_vel, pelvis wrench, kinematic
    playback) pinning there."""
    ground = Ground(atlas.model, data)
    qpos = home_qpos(atlas, start, ground)
    return ground, qpos, VrcState(atlas, data, ground, None if start is None else qpos)


def _apply_torque(sim: AtlasSimulator, torque_nm: np.ndarray | None
                  ) -> Callable[[], None] | None:
    """A step's torque applied by the simulator's law before the step: the law on the mode's
    command, the acting behaviour's f_out, or `torque_nm` (a recorded torque; None: the
    law's); or, returned, what applies the behaviour's between mj_step1 and mj_step2 when it
    steps on the step's own passes (sim.shared_passes)."""
    law = sim.law
    if torque_nm is not None:
        law.set_torque(torque_nm)
        return None
    commands = sim.commands
    behaviour = sim.behaviours.acting
    if behaviour is None:
        law.apply(commands.law_command, commands.blend_command)
    elif sim.shares_passes:
        return behaviour_between(law, behaviour, sim.data, commands.blend_command)
    else:
        law.apply_behaviour(behaviour.torque(sim.data), commands.blend_command)
    return None


def _playback_step(sim: AtlasSimulator) -> None:
    """AtlasSimulator.step() during kinematic playback: physics off, no torque, time
    advances."""
    sim.vrc.playback_step(sim.sim_time_ns)
    sim.law.set_torque(0.0)
    sim.state_time_ns = sim.sim_time_ns
    sim.sim_time_ns += sim.step_ns
    sim.data.time = sim.sim_time_ns / NS_PER_S


class AtlasSimulator:
    """One Atlas in MuJoCo, driven by DRCSim's per-joint controller law. Not thread-safe:
    the ROS node calls every method under its own lock."""

    def __init__(self, atlas: atlas_model.AtlasModel, gains: Gains,
                 time_to_unpin_s: float = DEFAULT_TIME_TO_UNPIN_S,
                 compiled_law: bool = True,
                 startup_mode: VrcMode = DEFAULT_STARTUP_MODE,
                 start: Start | None = None,
                 mud_damping: float = MUD_DAMPING) -> None:
        """`compiled_law`: run the law through law_kernel's C kernel when it is built
        (the same torques bit for bit, faster); False: always controller.compute_torque.
        `startup_mode`: one of vrc.STARTUP_MODES, what reset_world starts the robot in;
        `start`: where, soles on the ground (None: the origin; ModelError: no ground);
        `mud_damping`: the MudPlugin's damping (N s/m) in a world with mud (sim.mud)."""
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
        self.dt_s = float(self.model.opt.timestep)
        self.step_ns = int(round(self.dt_s * NS_PER_S))
        self.law = JointLaw(atlas, self.data, self.dt_s, compiled_law)
        self.torque_nm = self.law.torque_nm  # the law's output array, applied each step
        self.commands = ModeCommands(gains, self.joint_positions, self.torque_nm)
        self.behaviours = ModeBehaviours()  # install_stand
        divergence = DivergenceCheck(self.data, self.law.state_is_finite, self.law.kernel)
        self._unsound, self._check_divergence = divergence.unsound, divergence.check
        self.sim_time_ns = 0
        self.start = start
        # VRCPlugin's cheats, pinning at reset_world's pelvis qpos; the world's ground.
        self.ground, self.start_qpos, self.vrc = _placed_cheats(atlas, self.data, start)
        self.mud = MudDrag.for_model(self.model, atlas.path, mud_damping)  # None: no mud
        #: A behaviour's step is mj_step1, its torque, mj_step2 (sim.shared_passes).
        self.shares_passes = shares_passes()
        self.startup_pin = StartupPin(atlas, self.data, self.vrc, time_to_unpin_s, startup_mode)
        #: How many inputs were applied since the last reset, and the last one (sim time (ns)
        #: before the step it first acted in, input): /atlas/sim_inputs publishes each for
        #: replay. Only a count is kept: a 1 kHz wrench stream must not grow a list.
        self.inputs_since_reset = 0
        self._last_input: tuple[int, SimInput] | None = None
        self.sensor_seed = 0  #: the head laser's noise seed (sensors/), for the config
        self.reset_world()

    @property
    def uses_compiled_law(self) -> bool:
        return self.law.compiled

    @property
    def time_to_unpin_s(self) -> float:
        return self.startup_pin.time_to_unpin_s

    @property
    def startup_mode(self) -> VrcMode:
        return self.startup_pin.startup_mode

    # -- state -------------------------------------------------------------------------
    def reset_world(self) -> None:
        """Robot back to its initial state (pinned again), sim time kept, as Gazebo did."""
        atlas_model.reset_to_initial(self.atlas, self.data, self.start_qpos)
        self.data.time = self.sim_time_ns / NS_PER_S
        self.last_reset_ns = self.sim_time_ns
        self.state_time_ns = self.sim_time_ns
        self.law.reset()
        self.torque_nm[:] = 0.0
        self.vrc.reset()
        self.inputs_since_reset = 0
        self._last_input = None
        self.startup_pin.start(self.sim_time_ns)
        self.commands.reset()
        if self.startup_mode is VrcMode.BDI_STAND:
            self._begin_bdi_stand()
        else:
            self.behaviours.restart(self.mode, self.data)

    def _begin_bdi_stand(self) -> None:
        """VRCPlugin's `bdi_stand` (SetPIDStand): pinned without gravity, the joints set to
        the Stand pose and held by the user's PID (User, k_effort 1) until the pin's Stand."""
        self.startup_pin.begin_bdi_stand(self.sim_time_ns)
        self.vrc.set_joint_positions(STAND_POSE_RAD)
        self.set_mode(ControlMode.USER)
        self.commands.user_command = hold_command(self.gains, STAND_POSE_RAD)  # k_effort 1

    def config(self) -> SimConfig:
        """What re-creates this run offline: the model, its step, start, pin, last reset."""
        return SimConfig(model_file=self.atlas_path.name, model_sha1=self.atlas_sha1,
                         timestep_s=self.dt_s, time_to_unpin_s=self.time_to_unpin_s,
                         last_reset_time_s=self.last_reset_ns / NS_PER_S,
                         startup_mode=self.startup_mode.value,
                         start=start_text(self.start) if self.start else '',
                         mud_damping=None if self.mud is None else self.mud.damping,
                         sensor_seed=self.sensor_seed)

    def reset_simulation(self, sim_time_ns: int = 0) -> None:
        """reset_world, and sim time back to `sim_time_ns` (Gazebo's reset_simulation
        restarts at 0; replay restarts at a recorded reset)."""
        self.sim_time_ns = sim_time_ns
        self.reset_world()

    @property
    def pinned(self) -> bool:
        """The pelvis is welded (the start-up pin, a pinned mode, or cmd_vel's warp)."""
        return self.vrc.is_pinned()

    @property
    def playing(self) -> bool:
        """A /joint_trajectory is playing: physics is off."""
        return self.vrc.playback is not None

    def joint_positions(self) -> np.ndarray:
        return atlas_model.joint_positions(self.atlas, self.data)

    def joint_velocities(self) -> np.ndarray:
        return atlas_model.joint_velocities(self.atlas, self.data)

    def joint_damping(self) -> np.ndarray:
        """The joints' own viscous damping (N m s/rad), under a velocity gain's."""
        return self.law.velocity_damping.model_nm_s.copy()

    def set_joint_damping(self, damping: np.ndarray) -> None:
        """Set the joints' viscous damping (N m s/rad, (28,)), as /atlas/debug/test does
        (Gazebo's Joint::SetDamping); kept across resets, as in Gazebo."""
        self.law.velocity_damping.set_model(damping)

    # -- VRCPlugin's inputs ----------------------------------------------------------------
    def apply_input(self, item: SimInput) -> None:
        """Apply one checked input now, between two steps, and log it for replay.

        An explicit /atlas/mode cancels the start-up release (the user's mode stays);
        `bdi_stand` starts VRCPlugin's sequence from here: pinned in the Stand pose, released
        after 1 s, the Stand behaviour after 2 s.
        """
        vrc = self.vrc
        if isinstance(item, ModeInput):
            self.startup_pin.cancel()
            if item.mode is VrcMode.BDI_STAND:
                self._begin_bdi_stand()
            else:
                vrc.set_mode(item.mode)
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

    # -- commands (mode_commands.ModeCommands holds them) ----------------------------------
    @property
    def mode(self) -> ControlMode:
        return self.commands.mode

    @property
    def user_command(self) -> JointCommandArrays | None:
        """The command merged from JointCommands and AtlasCommand (None: none since reset)."""
        return self.commands.user_command

    def set_mode(self, mode: ControlMode) -> None:
        """ModeCommands.set_mode; the derivative restarts (no kick); a behaviour starts."""
        self.commands.set_mode(mode)
        self.law.restart_derivative()
        self.behaviours.select(mode, self.data)

    def install_stand(self, behaviour: Behaviour | None,
                      mode: ControlMode = ControlMode.STAND) -> None:
        """`mode` runs `behaviour` (f_out), or its hold for None (the start's hold: later)."""
        self.behaviours.install(mode, behaviour)
        if mode is self.mode and not self.behaviours.holding_start:
            self.behaviours.select(mode, self.data)

    def receive_command(self, names: Sequence[str],
                        arrays: Mapping[str, Sequence[float]]) -> None:
        """ModeCommands.receive_command: merge one JointCommands message."""
        self.commands.receive_command(names, arrays)

    def receive_updates(self, updates: Sequence[CommandUpdate]) -> None:
        """ModeCommands.receive_updates: apply checked command messages, in order."""
        self.commands.receive_updates(updates)

    def active_k_effort(self) -> np.ndarray:
        """AtlasState's k_effort (uint8, (28,)): 0 while a behaviour alone drives (its f_out,
        as DRCSim 2.7 said), else the PID command's (255: the PID alone, a hold's too)."""
        if self.behaviours.acting is not None and self.commands.blend_command is None:
            return _NO_PID
        return self.commands.active_k_effort()

    # -- stepping ----------------------------------------------------------------------
    def step(self, torque_nm: np.ndarray | None = None) -> None:
        """Advance one physics step with the controller law's torque, or with `torque_nm`.

        Offline replay passes the recorded torque (N m, (28,)): the pin release and the
        divergence check are then the very code the node runs. While a cheat acts the law
        is applied by the same call: only the warp and the extra body forces wrap it.

        Raises:
            PhysicsDivergenceError: the new state is not finite (the caller resets).
        """
        pin = self.startup_pin
        if pin.pending and self.sim_time_ns >= pin.release_ns \
                and pin.release() is StartupEvent.STAND:
            self.set_mode(ControlMode.STAND)  # bdi_stand's end: every k_effort 0
        vrc = self.vrc
        if vrc.active:
            if vrc.playback is not None:
                _playback_step(self)
                return
            vrc.warp_step(self.dt_s)
        behaviour = self.behaviours.acting
        if vrc.active or behaviour is None or torque_nm is not None or self.mud is not None \
                or not self.shares_passes or self.commands.blend_command is not None:
            step_with_body_forces(self.model, self.data, vrc.xfrc if vrc.active else None,
                                  self.mud, _apply_torque(self, torque_nm))
        else:  # a behaviour acting alone (every offline walk's step): one call
            step_behaviour(self.model, self.data, self.law, behaviour)
        # mj_step integrates last: joint positions/velocities are at the new time, while body
        # poses and sensor readings were computed before integrating, at the step's start.
        self.state_time_ns = self.sim_time_ns
        self.sim_time_ns += self.step_ns
        if self._unsound():
            self._check_divergence(self.sim_time_ns)

    def next_law_torque(self) -> np.ndarray:
        """The torque (N m) the law would apply at the next step; the law's memory is kept."""
        commands = self.commands
        behaviour = self.behaviours.acting
        if behaviour is not None:
            return self.law.predict_behaviour(behaviour.torque(self.data), commands.blend_command)
        return self.law.predict(commands.law_command, commands.blend_command)
