"""The behaviour library's decisions and what it reports: requests taken or refused, the
feedback status, the error code. Pure: the caller applies the control mode it returns.

Our choices where BDI's library published none (docs/controllers.md): a request of the
running behaviour changes nothing, so a client may stream it at 1 kHz; an accepted switch
reports TRANSITION_SUCCESS in the state of that step, then OK; a refusal (unknown or not
served behaviour, Walk, Step or Manipulate asked for outside a standing behaviour, a standing
behaviour with the centre of mass outside the feet) keeps the running behaviour, reports its
FAILED_TRANS_* and error code until the next request or for REFUSAL_REPORTED_TICKS ticks,
whichever comes first (never latched: a later client's first state is not an old refusal),
and says in `refusal` why and what to send instead; Stand requested during Walk is
taken once the step under way is down and the robot caught (TRANSITION_IN_PROGRESS until
then, TRANSITION_SUCCESS after); Walk's return to Stand by itself after its last step
reports WARNING_AUTO_TRANS in the state of that step, then OK (DRCSim's actionlib server
does nothing while it is reported: latched, it would wait forever);
ERROR_FALLING is reported while a standing behaviour (Walk included) is falling, ahead of
any other value (one value at a time).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from tutorial_atlas_control.asi.behaviors import (
    MODE_OF_BEHAVIOR,
    AsiError,
    Behavior,
    Status,
)
from tutorial_atlas_control.control_modes import ControlMode

__all__ = ['REFUSAL_REPORTED_TICKS', 'STANDING_BEHAVIORS', 'AsiSession', 'Refusal']

#: Behaviours that keep the robot on its feet: only they can be falling, and entering one
#: needs the centre of mass over the feet.
STANDING_BEHAVIORS = frozenset({Behavior.STAND, Behavior.MANIPULATE, Behavior.WALK,
                                Behavior.STEP})
#: Behaviours entered only from a standing one (BDI's library: Stand first).
NEEDS_STANDING = frozenset({Behavior.MANIPULATE, Behavior.WALK, Behavior.STEP})
#: How many ticks (1 ms each) a refusal stays reported without a new request: long enough
#: for a client reading every tenth state to see it, short enough that the next goal's first
#: state is not about somebody else's request (DRCSim's actionlib server aborts a new goal
#: on the error code of the first state it reads, before it sends anything).
REFUSAL_REPORTED_TICKS = 50
_KNOWN = frozenset(int(b) for b in Behavior)
_REFUSALS = frozenset({Status.FAILED_TRANS_UNKNOWN_BEHAVIOR, Status.FAILED_TRANS_ILLEGAL_BEHAVIOR,
                       Status.FAILED_TRANS_COM_POS, Status.FAILED_TRANS_COM_VEL,
                       Status.FAILED_TRANS_VEL})


def behavior_name(behavior: int) -> str:
    """STAND, WALK, ... or the number itself for one the library does not know."""
    return Behavior(behavior).name if behavior in _KNOWN else str(behavior)


@dataclass(frozen=True)
class Refusal:
    """A request the library refused: what was asked, in which behaviour, and why."""

    behavior: int
    current: Behavior
    status: Status
    reason: str

    def line(self) -> str:
        """The log line: the request, the behaviour it met, the reason and the remedy."""
        return (f'refused AtlasSimInterfaceCommand behavior {self.behavior} '
                f'({behavior_name(self.behavior)}) in {self.current.name}: '
                f'{self.status.name}, {self.reason}')


class AsiSession:
    """Requests in, feedback values out, for one simulator."""

    def __init__(self, served: Mapping[Behavior, ControlMode] = MODE_OF_BEHAVIOR) -> None:
        """`served`: the behaviours this library runs, each with the control mode it runs
        in; the others are refused as not implemented."""
        self.served = dict(served)
        self.desired_behavior = int(Behavior.STAND)
        self.error_code = AsiError.NO_ERRORS
        self.trans_from_behavior = int(Behavior.STAND)
        self.trans_to_behavior = int(Behavior.STAND)
        self._status = Status.OK
        #: The newest refusal, for the log (the caller takes it: take_refusal).
        self.refusal: Refusal | None = None
        self._refusal_ticks_left = 0

    def status_flags(self, current: Behavior, falling: bool) -> int:
        """behavior_feedback.status_flags: ERROR_FALLING while a standing behaviour is
        falling, else the outcome of the last request that changed something."""
        if falling and current in STANDING_BEHAVIORS:
            return int(Status.ERROR_FALLING)
        return int(self._status)

    def request(self, behavior: int, current: Behavior,
                feet_under_com: bool) -> ControlMode | None:
        """A requested behaviour number; returns the control mode to switch to, or None
        (the running behaviour stays). `feet_under_com`: the centre of mass is over the
        support polygon (else Stand is refused)."""
        self.desired_behavior = behavior
        if self._status in _REFUSALS:  # a new request: the old refusal is answered
            self._status, self.error_code = Status.OK, AsiError.NO_ERRORS
        if behavior == current:
            return None
        if behavior not in _KNOWN:
            return self._refuse(behavior, current, Status.FAILED_TRANS_UNKNOWN_BEHAVIOR,
                                AsiError.NO_SUCH_BEHAVIOR,
                                'not a behaviour (0 STAND, 1 USER, 2 FREEZE, 3 STAND_PREP, '
                                '4 WALK, 5 STEP, 6 MANIPULATE)')
        wanted = Behavior(behavior)
        if wanted not in self.served:
            return self._refuse(behavior, current, Status.FAILED_TRANS_ILLEGAL_BEHAVIOR,
                                AsiError.BEHAVIOR_NOT_IMPLEMENTED,
                                f'{wanted.name} is not served with the stiff hold as Stand '
                                '(atlas.launch stand:=hold): launch with stand:=balance, '
                                'the default')
        if wanted in NEEDS_STANDING and current not in STANDING_BEHAVIORS:
            return self._refuse(behavior, current, Status.FAILED_TRANS_ILLEGAL_BEHAVIOR,
                                AsiError.FAILED_TO_START_BEHAVIOR,
                                f'{wanted.name} needs Stand: send STAND (behavior 0) first')
        if wanted in STANDING_BEHAVIORS and not feet_under_com:
            return self._refuse(behavior, current, Status.FAILED_TRANS_COM_POS,
                                AsiError.FAILED_TO_START_BEHAVIOR,
                                f'{wanted.name} needs the centre of mass over the feet: the '
                                'robot is down or off balance (reset_world, or StandPrep '
                                'from the harness)')
        self._status = Status.TRANSITION_SUCCESS
        self.error_code = AsiError.NO_ERRORS
        self.trans_from_behavior, self.trans_to_behavior = int(current), behavior
        return self.served[wanted]

    def switched(self, current: Behavior, previous: Behavior) -> None:
        """The mode changed another way (/atlas/control_mode, /atlas/mode bdi_stand): the
        library saw a successful transition."""
        self.desired_behavior = int(current)
        self._status = Status.TRANSITION_SUCCESS
        self.error_code = AsiError.NO_ERRORS
        self.trans_from_behavior, self.trans_to_behavior = int(previous), int(current)

    def defer(self, behavior: Behavior, current: Behavior) -> None:
        """`behavior` asked for, taken once `current` has ended (Stand during Walk, after its
        step under way): TRANSITION_IN_PROGRESS until then."""
        self.desired_behavior = int(behavior)
        self._status = Status.TRANSITION_IN_PROGRESS
        self.error_code = AsiError.NO_ERRORS
        self.trans_from_behavior, self.trans_to_behavior = int(current), int(behavior)

    def auto_switched(self, current: Behavior, previous: Behavior) -> None:
        """The library left `previous` by itself (Walk, its steps done, to Stand):
        WARNING_AUTO_TRANS in the state of that step, then OK."""
        self.switched(current, previous)
        self._status = Status.WARNING_AUTO_TRANS

    def end_step(self) -> None:
        """A tick has passed: a success has been reported (or was not listened to); a
        refusal is reported for REFUSAL_REPORTED_TICKS ticks at most."""
        status = self._status
        if status in (Status.TRANSITION_SUCCESS, Status.WARNING_AUTO_TRANS):
            self._status = Status.OK
        elif status in _REFUSALS:
            self._refusal_ticks_left -= 1
            if self._refusal_ticks_left <= 0:
                self._status, self.error_code = Status.OK, AsiError.NO_ERRORS

    def take_refusal(self) -> Refusal | None:
        """The refusal of the last request, once (None: it was not refused)."""
        refusal, self.refusal = self.refusal, None
        return refusal

    def _refuse(self, behavior: int, current: Behavior, status: Status,
                error: AsiError, reason: str) -> None:
        self._status, self.error_code = status, error
        self._refusal_ticks_left = REFUSAL_REPORTED_TICKS
        self.trans_from_behavior, self.trans_to_behavior = int(current), behavior
        self.refusal = Refusal(behavior, current, status, reason)
