"""What a DRC-era walking client does with each AtlasSimInterfaceState, ROS-free.

Two kinds (ASI.md): a streaming client answers every state (1 kHz) with a WALK carrying
the window [next_step_index_needed, +3] of its plan; a one-shot client sends its first
four steps once. Both then watch the walk: it has walked once the behaviour, having been
Walk, is Stand again (the library's return after the last step), and has failed once the
state says ERROR_FALLING or its request was refused (a FAILED_TRANS_* status in a state after
its first request: one before it answers somebody else's); `refusal_hint` says what to do.
"""

from __future__ import annotations

import enum

from tutorial_atlas_control.asi.behaviors import Behavior, Status
from tutorial_atlas_control.asi.errors import AsiInputError
from tutorial_atlas_control.walking import QUEUE_LENGTH, Footstep, window

__all__ = ['Outcome', 'WalkClient', 'refusal_hint']

_REFUSED = frozenset({Status.FAILED_TRANS_UNKNOWN_BEHAVIOR, Status.FAILED_TRANS_ILLEGAL_BEHAVIOR,
                      Status.FAILED_TRANS_COM_POS, Status.FAILED_TRANS_COM_VEL,
                      Status.FAILED_TRANS_VEL})


class Outcome(enum.Enum):
    """How a walk ended."""

    WALKED = 'walked'
    FELL = 'fell'
    REFUSED = 'refused'


class WalkClient:
    """One walk of `plan` (step indices from 1), streamed or sent once."""

    def __init__(self, plan: list[Footstep], streaming: bool = True) -> None:
        if not plan or [step.step_index for step in plan] != list(range(1, len(plan) + 1)):
            raise AsiInputError('a plan is steps 1, 2, ... in order')
        self.plan = plan
        self.streaming = streaming
        self.outcome: Outcome | None = None
        #: The most steps the state said were taken.
        self.steps_taken = 0
        self._walking = False
        self._sent = False
        self._requested = False

    def on_state(self, current_behavior: int, status_flags: int, current_step_index: int,
                 next_step_index_needed: int) -> list[Footstep] | None:
        """One state's fields; the steps of the WALK to send now, or None (send nothing)."""
        if self.outcome is not None:
            return None
        if status_flags == Status.ERROR_FALLING:
            self.outcome = Outcome.FELL
            return None
        if status_flags in _REFUSED and self._requested:
            self.outcome = Outcome.REFUSED
            return None
        if current_behavior == Behavior.WALK:
            self._walking = True
            self.steps_taken = max(self.steps_taken, current_step_index)
        elif self._walking:
            self.outcome = Outcome.WALKED
            return None
        self._requested = True
        if self.streaming:
            return window(self.plan, max(next_step_index_needed, 1) if self._walking else 1)
        if self._sent:
            return None
        self._sent = True
        return self.plan[:QUEUE_LENGTH]


def refusal_hint(status_flags: int, current_behavior: int) -> str:
    """What a refused WALK's status means and what to do, in a few words."""
    if status_flags == Status.FAILED_TRANS_ILLEGAL_BEHAVIOR:
        if current_behavior in (Behavior.USER, Behavior.FREEZE, Behavior.STAND_PREP):
            return ("FAILED_TRANS_ILLEGAL_BEHAVIOR: WALK needs Stand; send STAND first: rostopic "
                    "pub -1 /atlas/atlas_sim_interface_command "
                    "atlas_msgs/AtlasSimInterfaceCommand '{behavior: 0}'")
        return ('FAILED_TRANS_ILLEGAL_BEHAVIOR: Walk is not served; the simulator runs with '
                'stand:=hold (launch atlas.launch without it)')
    if status_flags == Status.FAILED_TRANS_COM_POS:
        return ('FAILED_TRANS_COM_POS: the robot is down or off balance; rosservice call '
                '/gazebo/reset_world')
    if status_flags == Status.ERROR_FALLING:
        return 'ERROR_FALLING: the robot fell'
    known = status_flags in {int(s) for s in Status}
    return Status(status_flags).name if known else f'status {status_flags}'
