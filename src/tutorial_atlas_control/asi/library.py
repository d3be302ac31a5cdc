"""The behaviour library's contract: what the AtlasSimInterface asks of a behaviour it serves
beyond Stand, so that the interface has no branch per behaviour.

A library behaviour is a simulator Behaviour (sim/behaviour.py: `start`, `torque`) that also
says which ASI behaviour it answers to and which control mode runs it, takes its command's
parameters, answers Stand asked for while it runs, reports its feedback, and says after each
tick what it hands the robot over to (a walk done: Stand; fallen: Freeze). Adding one is a
class with these members (BehaviourBase has their quiet defaults) and the interface's
`register`. A behaviour whose control mode reports another behaviour (Manipulate, in Stand's
mode) is not installed for that mode but runs inside the behaviour there (NestedBehaviour):
the interface enters and leaves it, asks whether the mode still runs it, and hands it every
command while it runs.
"""

from __future__ import annotations

import dataclasses
from typing import Protocol, cast

import mujoco
import numpy as np

from tutorial_atlas_control.asi.behaviors import BEHAVIOR_OF_MODE, Behavior
from tutorial_atlas_control.asi.walk_params import footsteps_of, step_feedback, walk_feedback
from tutorial_atlas_control.balance import PelvisServo, SoleBox, StandBehaviour
from tutorial_atlas_control.control_modes import ControlMode
from tutorial_atlas_control.msgs import AsiCommand, ManipulateFeedback, ManipulateParams
from tutorial_atlas_control.sim import Ground
from tutorial_atlas_control.walking import (
    STEP_DURATION_S,
    Footstep,
    StepBehaviour,
    WalkBehaviour,
    footprint_surface,
)

__all__ = ['BehaviourBase', 'Handover', 'LibraryBehaviour', 'ManipulateEntry', 'NestedBehaviour',
           'StepEntry', 'WalkEntry', 'nested', 'on_ground', 'servo_of']


@dataclasses.dataclass(frozen=True)
class Handover:
    """The behaviour a library behaviour hands the robot to, and whether the library did it
    by itself (WARNING_AUTO_TRANS) rather than as the client asked (a Stand it deferred)."""

    behavior: Behavior
    automatic: bool


class LibraryBehaviour(Protocol):
    """A behaviour of the open AtlasSimInterface, beyond the simulator's `start`/`torque`."""

    #: The ASI behaviour it answers to and the control mode that runs it.
    behavior: Behavior
    mode: ControlMode
    #: A request for it waits while Stand is still taking the robot over (a walk does not
    #: start from the hold's straight legs).
    waits_for_stand: bool

    def start(self, data: mujoco.MjData) -> None:
        """Take the robot over as it is."""

    def torque(self, data: mujoco.MjData) -> np.ndarray:
        """This tick's f_out (N m, (28,))."""

    def refusal(self, command: AsiCommand, running: bool) -> str | None:
        """Why `command` cannot be taken (a log line's reason), None if it can."""

    def prepare(self, command: AsiCommand) -> None:
        """`command`'s parameters before the interface requests the behaviour (whether or
        not the request is granted)."""

    def take(self, command: AsiCommand, running: bool) -> None:
        """`command`'s parameters once granted: for the next start, or (`running`) for the
        behaviour under way."""

    def stop(self) -> bool:
        """Stand is asked for while it runs: True if it first finishes what is under way
        (it then hands over itself), False if Stand may take over at once."""

    def handover(self, fallen: bool) -> Handover | None:
        """After a tick it ran: what it hands the robot to now (`fallen`: the robot is down
        for good), None to go on."""

    def feedback(self, time_s: float, sole_ahead_m: float) -> dict[str, object]:
        """Its fields of AtlasSimInterfaceState (e.g. walk_feedback), now."""


class NestedBehaviour(LibraryBehaviour, Protocol):
    """A library behaviour that runs inside the behaviour of its control mode (Manipulate: the
    balancing Stand with its pelvis servoed) instead of being installed for the mode."""

    def enter(self) -> None:
        """It becomes the current behaviour, inside its mode's behaviour as that runs now."""

    def leave(self, mode: ControlMode, time_s: float) -> None:
        """Another behaviour was granted; the simulator is now in `mode`."""

    def runs(self, mode: ControlMode) -> bool:
        """Whether it still runs with the simulator in `mode` (a switch or a restart made
        elsewhere ends it)."""

    def follow(self, command: AsiCommand, time_s: float) -> None:
        """Every command while it runs, whatever behaviour the command asks for: BDI's
        library read the running behaviour's parameters from each one."""


def nested(behaviour: LibraryBehaviour) -> NestedBehaviour | None:
    """`behaviour` if it runs inside its control mode's behaviour (the mode reports
    another behaviour), None if it is installed for its mode."""
    if BEHAVIOR_OF_MODE.get(behaviour.mode) is behaviour.behavior:
        return None
    return cast(NestedBehaviour, behaviour)


class BehaviourBase:
    """The contract's quiet defaults, for a behaviour of one's own: it takes every command,
    needs none of its parameters, lets Stand in at once, never hands over by itself (a
    fallen robot is the client's to handle) and reports no feedback of its own. A subclass
    sets `behavior` and `mode` and writes `start` and `torque`."""

    behavior: Behavior
    mode: ControlMode
    waits_for_stand = False

    def start(self, data: mujoco.MjData) -> None:
        raise NotImplementedError

    def torque(self, data: mujoco.MjData) -> np.ndarray:
        raise NotImplementedError

    def refusal(self, command: AsiCommand, running: bool) -> str | None:
        return None

    def prepare(self, command: AsiCommand) -> None:
        """Nothing to take before the request."""

    def take(self, command: AsiCommand, running: bool) -> None:
        """Nothing to take from the command."""

    def stop(self) -> bool:
        return False

    def handover(self, fallen: bool) -> Handover | None:
        return None

    def feedback(self, time_s: float, sole_ahead_m: float) -> dict[str, object]:
        return {}


def on_ground(steps: list[Footstep], ground: Ground | None) -> list[Footstep]:
    """`steps` placed on the world's surface under each sole (its height and normal): on a
    heightfield the plane its footprint rests on (walking/sole_footprint.py), elsewhere the
    surface under its centre. A DRC-era client's z is the foot link's, or none (ASI.md: it
    may be ignored), so the world says where a sole lands. Nothing below (off the world):
    as asked."""
    if ground is None or ground.level_m == 0.0:
        return steps  # the ground the robot starts on: every step's default
    hfields = ground.hfield_geoms
    half_size = SoleBox.of(ground.model).half_size_m if hfields else (0.0, 0.0)
    placed = []
    for step in steps:
        hit = ground.hit(step.x_m, step.y_m)
        if hit.geom_id < 0:
            placed.append(step)
            continue
        surface = None if hit.geom_id not in hfields else footprint_surface(
            ground, step.x_m, step.y_m, step.yaw_rad, half_size, hit.height_m)
        if surface is None:
            surface = (hit.height_m, (float(hit.normal[0]), float(hit.normal[1]),
                                      float(hit.normal[2])))
        placed.append(dataclasses.replace(step, z_m=surface[0], normal=surface[1]))
    return placed


class _SteppingEntry(BehaviourBase):
    """What Walk's and Step's entries share: the behaviour they serve, where the soles'
    steps are (`sole_ahead_m` of the foot link, on `ground`: None, the plane z = 0), and
    whether a Stand was asked for while it ran (reset at each start)."""

    waits_for_stand = True

    def __init__(self, behaviour: WalkBehaviour | StepBehaviour, sole_ahead_m: float,
                 ground: Ground | None = None) -> None:
        self.behaviour = behaviour
        self.sole_ahead_m = sole_ahead_m
        self.ground = ground
        self._stand_asked = False

    def start(self, data: mujoco.MjData) -> None:
        self._stand_asked = False
        self.behaviour.start(data)

    def torque(self, data: mujoco.MjData) -> np.ndarray:
        return self.behaviour.torque(data)


class WalkEntry(_SteppingEntry):
    """Walk in the library: a WALK's step queue (for the next start once granted, or to the
    walk under way; nothing before the request, so a refused WALK leaves the next start's
    steps alone), Stand deferred to the end of the step under way, Stand again once the walk
    has caught itself, Freeze once fallen."""

    behavior = Behavior.WALK
    mode = ControlMode.WALK

    def __init__(self, walking: WalkBehaviour, sole_ahead_m: float,
                 ground: Ground | None = None) -> None:
        super().__init__(walking, sole_ahead_m, ground)
        self._decoded: tuple[AsiCommand, list[Footstep]] | None = None

    @property
    def walking(self) -> WalkBehaviour:
        """The Walk behaviour served."""
        assert isinstance(self.behaviour, WalkBehaviour)
        return self.behaviour

    def _steps(self, command: AsiCommand) -> list[Footstep]:
        """The command's step queue as the soles' steps (kept for the same command: the
        refusal and the take read it once)."""
        if self._decoded is None or self._decoded[0] is not command:
            self._decoded = (command, on_ground(
                footsteps_of(command.step_queue, self.sole_ahead_m), self.ground))
        return self._decoded[1]

    def refusal(self, command: AsiCommand, running: bool) -> str | None:
        """A WALK without step 1 (a new walk's first) starts nothing: it is a window of a
        walk that has ended, sent before the client saw the end. Started, it could take no
        step and would only catch itself from standing."""
        if running:
            return None
        indices = [step.step_index for step in self._steps(command)]
        if 1 in indices:
            return None
        return (f'its step_queue has step_index {indices or "none"}, and a new walk starts '
                'with step_index 1')

    def take(self, command: AsiCommand, running: bool) -> None:
        if running:
            self.walking.offer(self._steps(command))
        else:
            self.walking.next_steps = self._steps(command)

    def stop(self) -> bool:
        if self.walking.done:
            return False
        if not self._stand_asked:
            self.walking.finish()
            self._stand_asked = True
        return True

    def handover(self, fallen: bool) -> Handover | None:
        if fallen:
            return Handover(Behavior.FREEZE, True)
        if self.walking.done:
            return Handover(Behavior.STAND, not self._stand_asked)
        return None

    def feedback(self, time_s: float, sole_ahead_m: float) -> dict[str, object]:
        return {'walk_feedback': walk_feedback(self.walking.status(time_s), sole_ahead_m)}


class StepEntry(_SteppingEntry):
    """Step in the library: each STEP's desired step (taken before the request, granted or
    not: Step's start keeps it), Stand deferred until the step under way is down, Freeze
    once fallen."""

    behavior = Behavior.STEP
    mode = ControlMode.STEP

    def __init__(self, stepping: StepBehaviour, sole_ahead_m: float,
                 ground: Ground | None = None) -> None:
        super().__init__(stepping, sole_ahead_m, ground)

    @property
    def stepping(self) -> StepBehaviour:
        """The Step behaviour served."""
        assert isinstance(self.behaviour, StepBehaviour)
        return self.behaviour

    def prepare(self, command: AsiCommand) -> None:
        """step_params.desired_step as a sole's step (None: an empty one, no step wanted);
        without a duration (DRCSim's actionlib server sends none) it swings for
        STEP_DURATION_S."""
        desired = command.desired_step
        if desired.duration_s <= 0.0:
            desired = dataclasses.replace(desired, duration_s=STEP_DURATION_S)
        steps = on_ground(footsteps_of([desired], self.sole_ahead_m), self.ground)
        self.stepping.desire(steps[0] if steps else None)

    def stop(self) -> bool:
        if self.stepping.static_step is None:
            return False
        self._stand_asked = True
        return True

    def handover(self, fallen: bool) -> Handover | None:
        if fallen:
            return Handover(Behavior.FREEZE, True)
        if self._stand_asked and self.stepping.static_step is None:
            return Handover(Behavior.STAND, False)
        return None

    def feedback(self, time_s: float, sole_ahead_m: float) -> dict[str, object]:
        return {'step_feedback': step_feedback(self.stepping.status(time_s), sole_ahead_m)}


def servo_of(params: ManipulateParams) -> PelvisServo | None:
    """Manipulate's pelvis target: `desired` when use_desired, else None (the Stand pose)."""
    if not params.use_desired:
        return None
    return PelvisServo(params.pelvis_height_m, params.pelvis_yaw_rad, params.pelvis_lat_m)


class ManipulateEntry(BehaviourBase):
    """Manipulate in the library: the balancing Stand, already running, with its pelvis
    servoed to each command's `manipulate_params.desired` (the Stand pose without
    use_desired), back to the Stand pose when another behaviour is granted in Stand; it ends
    when Stand restarts or the mode changes elsewhere (/atlas/control_mode)."""

    behavior = Behavior.MANIPULATE
    mode = ControlMode.STAND

    def __init__(self, stand: StandBehaviour) -> None:
        self.stand = stand
        #: The Stand's start it runs in (StandBehaviour.starts when entered).
        self._stand_start = 0

    def start(self, data: mujoco.MjData) -> None:
        self.stand.start(data)

    def torque(self, data: mujoco.MjData) -> np.ndarray:
        return self.stand.torque(data)

    def enter(self) -> None:
        self._stand_start = self.stand.starts

    def leave(self, mode: ControlMode, time_s: float) -> None:
        if mode is self.mode:
            self.stand.servo(None, time_s)

    def runs(self, mode: ControlMode) -> bool:
        return mode is self.mode and self.stand.starts == self._stand_start

    def follow(self, command: AsiCommand, time_s: float) -> None:
        self.stand.servo(servo_of(command.manipulate), time_s)

    def feedback(self, time_s: float, sole_ahead_m: float) -> dict[str, object]:
        """The pelvis target in use, as clamped (the Stand pose's without use_desired)."""
        target = self.stand.servo_target or PelvisServo(self.stand.squats.stand_height_m)
        return {'manipulate_feedback': ManipulateFeedback(
            0, target.height_m, target.yaw_rad, target.lateral_m)}
