"""The open AtlasSimInterface over one simulator: requests applied between ticks, the state
reported after each tick. ROS-free: the node hands it decoded commands and publishes the
bytes of its states.

What it does with a command (DRCSim 2.7's AtlasPlugin::SetASICommand): the behaviour is
requested (AsiSession decides), then k_effort, at exactly 28 entries, becomes the blend of
every joint; a behaviour switch itself never changes k_effort. Stand runs the balancing
StandBehaviour and StandPrep the StandPrepBehaviour, installed into the simulator here (or,
without `balance`, the simulator's holds, DRCSim 2.5.2's stand-in). Manipulate, served with
the balancing Stand only, is that Stand with its pelvis servoed to
`manipulate_params.desired` (the Stand pose without use_desired). Walk, also served with
the balancing Stand only, is walking.WalkBehaviour over the command's step queue (DRCSim's
fixed queue when started by /atlas/control_mode Walk); once it has caught itself after its
last step the interface hands the robot back to Stand (WARNING_AUTO_TRANS); Stand asked for
during a walk ends it after the step under way (TRANSITION_IN_PROGRESS until then). Step,
served with the balancing Stand too, is walking.StepBehaviour: one quasi-static step to each
new `step_params.desired_step` (a STEP streamed for a target already reached does not step
again), standing between steps; Stand asked for during a step is taken once it is down. A
switch made elsewhere (/atlas/control_mode, /atlas/mode bdi_stand) is seen at the next
state or step and reported as a successful transition.

With `hold_at_start` (atlas.launch's default start) the library is loaded but waits: the
start holds the robot with the parameter gains, the tutorial's hold, reported as User (the
PID holds it, k_effort 255) until a Stand is asked for (an ASI STAND, /atlas/control_mode
Stand); after reset_world in Stand, the start's hold again. A WALK or STEP asked for while
Stand is still taking the robot over (bringing it to the Stand pose, 1 s) waits for it,
TRANSITION_IN_PROGRESS meanwhile: a walk does not start from the hold's straight legs.
"""

from __future__ import annotations

import numpy as np

from tutorial_atlas_control.asi.behaviors import BEHAVIOR_OF_MODE, MODE_OF_BEHAVIOR, Behavior
from tutorial_atlas_control.asi.library import (
    LibraryBehaviour,
    ManipulateEntry,
    NestedBehaviour,
    StepEntry,
    WalkEntry,
    nested,
    on_ground,
)
from tutorial_atlas_control.asi.session import STANDING_BEHAVIORS, AsiSession, behavior_name
from tutorial_atlas_control.asi.state_report import StateReport
from tutorial_atlas_control.asi.walk_params import sole_step
from tutorial_atlas_control.balance import (
    BalanceEstimator,
    StandBehaviour,
    StandPrepBehaviour,
    signed_distance,
)
from tutorial_atlas_control.command import LAW_FIELDS, CommandUpdate
from tutorial_atlas_control.control_modes import ControlMode
from tutorial_atlas_control.course import Start
from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.msgs import (
    AsiCommand,
    AsiState,
    ManipulateFeedback,
    StepFeedback,
    WalkFeedback,
)
from tutorial_atlas_control.sim import AtlasSimulator, GroundUnderFeet
from tutorial_atlas_control.walking import (
    DRCSIM_WALK_QUEUE,
    Footstep,
    StepBehaviour,
    WalkBehaviour,
    placed,
)

__all__ = ['AtlasSimInterface']

#: Stand is refused while the centre of mass is further than this outside the feet (m).
COM_OUTSIDE_TOLERANCE_M = 0.0
_K_EFFORT_ROW = (LAW_FIELDS.index('k_effort'),)
_ALL_JOINTS = np.arange(NUM_JOINTS)


def _from_start(steps: list[Footstep], start: Start | None) -> list[Footstep]:
    """DRCSim's fixed Walk queue, made for a robot at the origin facing +x, carried to the
    start the simulator resets the robot to (None: the origin)."""
    if start is None:
        return steps
    return placed(steps, (start.x_m, start.y_m), start.yaw_rad)


class AtlasSimInterface:
    """Behaviour requests and state reports for `sim`; with `balance`, Stand is the
    balancing StandBehaviour, else the simulator's hold until a bdi_stand sequence (the
    start-up mode or /atlas/mode) asks for BDI's Stand, which loads the balancing one.
    `hold_at_start`: a (re)start in Stand holds the robot as the tutorial's start did until
    Stand is asked for. `user_behaviour`: a behaviour of the user's own, registered over the
    library's (with `balance` only; one answering Stand leaves Manipulate unserved)."""

    def __init__(self, sim: AtlasSimulator, balance: bool = True,
                 hold_at_start: bool = False,
                 user_behaviour: LibraryBehaviour | None = None) -> None:
        self.sim = sim
        self.user_behaviour = user_behaviour
        self._ground = GroundUnderFeet(sim.atlas, sim.data, sim.ground)  # the watch's ground
        if balance and hold_at_start:
            sim.behaviours.hold_stand_at_start = True
            if sim.mode is ControlMode.STAND:
                sim.behaviours.hold_start()
        #: Why the last request was not carried out, for the log (take_refusal).
        self._refusal: str | None = None
        #: A WALK or STEP asked for while Stand takes the robot over, taken once it has.
        self._deferred: AsiCommand | None = None
        #: The balancing Stand installed (None: Stand is the hold); its estimator, or one of
        #: the interface's own, checks the centre of mass before Stand is entered.
        self.stand: StandBehaviour | None = None
        #: The library's behaviours beyond Stand (registered with the balancing Stand), and
        #: the one that deferred a Stand asked for while it runs.
        self.library: dict[Behavior, LibraryBehaviour] = {}
        self._stand_deferred_by: Behavior | None = None
        #: The library behaviour running inside its mode's behaviour now (Manipulate in Stand).
        self._nested: NestedBehaviour | None = None
        self.session = AsiSession(MODE_OF_BEHAVIOR)
        if balance:
            self._load_balance()
        else:
            self._estimator = BalanceEstimator(sim.atlas)
        #: The behaviour the mode was last seen running (a nested one apart).
        self._seen = self._mode_behavior()
        self._report = StateReport(sim)

    def _load_balance(self) -> None:
        """Stand and StandPrep become the balancing behaviours; Walk, Step and Manipulate
        are served (the user's behaviour over them)."""
        sim = self.sim
        self.stand = StandBehaviour(sim.atlas)
        sim.install_stand(self.stand)
        sim.install_stand(StandPrepBehaviour(sim.atlas, sim.gains), ControlMode.STAND_PREP)
        ahead = self.stand.estimator.sole_ahead_m
        ground = self._ground.ground
        self.register(WalkEntry(WalkBehaviour(self.stand, default_steps=on_ground(
            _from_start([sole_step(step, ahead) for step in DRCSIM_WALK_QUEUE], sim.start),
            ground)), ahead, ground))
        self.register(StepEntry(StepBehaviour(self.stand), ahead, ground))
        self.register(ManipulateEntry(self.stand))
        self._estimator = self.stand.estimator
        if self.user_behaviour is not None:
            self.register(self.user_behaviour)

    def register(self, behaviour: LibraryBehaviour) -> None:
        """Serve `behaviour` for its ASI number: installed for its control mode (those nested
        in what the mode ran before unserved), or nested in the mode's behaviour."""
        if nested(behaviour) is None:
            self.sim.install_stand(behaviour, behaviour.mode)
            for other in [entry for entry in self.library.values()
                          if entry.mode is behaviour.mode and nested(entry) is not None]:
                del self.library[other.behavior], self.session.served[other.behavior]
        self.session.served[behaviour.behavior] = behaviour.mode
        self.library[behaviour.behavior] = behaviour

    def serves(self, mode: ControlMode) -> bool:
        """Whether a library behaviour is installed for control mode `mode`."""
        return any(entry.mode is mode and nested(entry) is None
                   for entry in self.library.values())

    @property
    def walking(self) -> WalkBehaviour | None:
        """Walk's behaviour (None: not served)."""
        entry = self.library.get(Behavior.WALK)
        return entry.walking if isinstance(entry, WalkEntry) else None

    @property
    def stepping(self) -> StepBehaviour | None:
        """Step's behaviour (None: not served)."""
        entry = self.library.get(Behavior.STEP)
        return entry.stepping if isinstance(entry, StepEntry) else None

    @property
    def current_behavior(self) -> Behavior:
        return self._mode_behavior() if self._nested is None else self._nested.behavior

    @property
    def manipulating(self) -> bool:
        """Whether Manipulate runs (for tests and tools; the interface asks no such thing)."""
        return self.current_behavior is Behavior.MANIPULATE

    def _mode_behavior(self) -> Behavior:
        """The behaviour the control mode runs: User during the start's hold (the PID with
        the parameter gains holds the robot; no behaviour of the library acts)."""
        if self.sim.behaviours.holding_start:
            return Behavior.USER
        return BEHAVIOR_OF_MODE[self.sim.mode]

    def take_refusal(self) -> str | None:
        """The log line of the last request's refusal, once (None: it was not refused)."""
        refusal = self.session.take_refusal()
        line, self._refusal = self._refusal, None
        return refusal.line() if refusal is not None else line

    def apply(self, command: AsiCommand) -> None:
        """One checked AtlasSimInterfaceCommand, between two ticks."""
        self._observe()
        sim = self.sim
        current = self.current_behavior
        self._request(command, current)
        if self._nested is not None:
            self._nested.follow(command, float(sim.data.time))
        if command.k_effort is not None:
            self._set_k_effort(command.k_effort)

    def _request(self, command: AsiCommand, current: Behavior) -> None:
        """The command's behaviour requested, the library behaviour asked for given its
        parameters (for its start, or while it runs); Stand asked for while a library
        behaviour runs waits if that behaviour first finishes what is under way."""
        self._deferred = None
        target = self.library.get(command.behavior)
        running = command.behavior == current
        if target is not None:
            reason = target.refusal(command, running)
            if reason is not None:
                self._refusal = (f'ignored AtlasSimInterfaceCommand behavior '
                                 f'{int(command.behavior)} ({behavior_name(command.behavior)}) '
                                 f'in {behavior_name(current)}: {reason}')
                return
        stand = self.stand
        if target is not None and target.waits_for_stand and current == Behavior.STAND \
                and stand is not None and stand.taking_over:
            self._deferred = command  # the newest one: a streaming client's window
            self.session.defer(Behavior(command.behavior), current)
            return
        if target is not None:
            target.prepare(command)
        acting = self.library.get(current)
        if acting is not None and command.behavior == Behavior.STAND and not running \
                and acting.stop():
            if self._stand_deferred_by is not current:
                self.session.defer(Behavior.STAND, current)
                self._stand_deferred_by = current
            return
        feet_under_com = running or self.com_over_feet()
        mode = self.session.request(command.behavior, current, feet_under_com)
        if mode is not None:
            if target is not None:
                target.take(command, running=False)
            self._switch(mode)
            self._nest(None if target is None else nested(target))
        elif running and target is not None:
            target.take(command, running=True)

    def _switch(self, mode: ControlMode) -> None:
        """The simulator into `mode`; a behaviour switch never changes k_effort."""
        sim = self.sim
        if mode is not sim.mode or sim.behaviours.holding_start:
            kept = None if sim.user_command is None else sim.user_command.k_effort.copy()
            sim.set_mode(mode)
            self._seen = self._mode_behavior()
            if kept is not None:
                self._set_k_effort(kept)

    def _nest(self, entry: NestedBehaviour | None) -> None:
        """After a granted request: `entry` nested in its mode's (None: none), the last left."""
        running = self._nested
        if running is not None and running is not entry:
            running.leave(self.sim.mode, float(self.sim.data.time))
        self._nested = entry
        if entry is not None:
            entry.enter()

    def _observe(self) -> None:
        """A control mode switched outside the interface is the library's transition; so is
        the behaviour a nested one runs in restarted (/atlas/control_mode Stand under
        Manipulate)."""
        if self.stand is None and self.sim.startup_pin.bdi_stand:
            self._load_balance()  # BDI's Stand asked for: the library is there
        mode, running = self.sim.mode, self._nested
        if running is not None and not running.runs(mode):
            self._nested = None
            if mode is running.mode:
                self.session.switched(BEHAVIOR_OF_MODE[mode], running.behavior)
        current = self._mode_behavior()
        if current is not self._seen:
            previous, self._seen = self._seen, current
            self.session.switched(current, previous)

    def _set_k_effort(self, fractions: np.ndarray) -> None:
        self.sim.receive_updates([CommandUpdate(_ALL_JOINTS, _K_EFFORT_ROW,
                                                np.asarray(fractions, dtype=float)[None, :])])

    def com_over_feet(self) -> bool:
        """The centre of mass over the support polygon of the soles touching the ground."""
        state = self._estimator.estimate(self.sim.data.qpos, self.sim.data.qvel)
        polygon = state.support_polygon
        if len(polygon) < 3:
            return False
        return signed_distance(polygon, state.com[:2]) >= -COM_OUTSIDE_TOLERANCE_M

    def status_key(self) -> tuple[int, int]:
        """(current behaviour, behavior_feedback.status_flags) now, without a whole state:
        what a recorded state's change is judged by."""
        self._observe()
        current = self.current_behavior
        falling = current in STANDING_BEHAVIORS and self._ground.falling()
        return int(current), self.session.status_flags(current, falling)

    def state(self) -> AsiState:
        """The AtlasSimInterfaceState of the tick just run."""
        self._observe()
        sim, session = self.sim, self.session
        current = self.current_behavior
        falling = current in STANDING_BEHAVIORS and self._ground.falling()
        acting = self.library.get(current)
        feedback = ({} if acting is None else
                    acting.feedback(float(sim.data.time), self._estimator.sole_ahead_m))
        return self._report.state(
            current, session, falling,
            feedback.get('manipulate_feedback', ManipulateFeedback()),
            feedback.get('walk_feedback', WalkFeedback()),
            feedback.get('step_feedback', StepFeedback()))

    def end_step(self) -> None:
        """After each tick, whether or not a state was built."""
        self._observe()
        self.session.end_step()
        deferred, stand = self._deferred, self.stand
        if deferred is not None and stand is not None and not stand.taking_over:
            current = self.current_behavior
            if current == Behavior.STAND:
                self._request(deferred, current)
            self._deferred = None
        acting = self.library.get(BEHAVIOR_OF_MODE.get(self.sim.mode, Behavior.USER))
        handover = None if acting is None else acting.handover(self._ground.fallen())
        if handover is not None:
            assert acting is not None
            self._switch(MODE_OF_BEHAVIOR[handover.behavior])
            if handover.automatic:
                self.session.auto_switched(handover.behavior, acting.behavior)
            else:
                self.session.switched(handover.behavior, acting.behavior)
        if self._stand_deferred_by is not None \
                and BEHAVIOR_OF_MODE.get(self.sim.mode) is not self._stand_deferred_by:
            self._stand_deferred_by = None
