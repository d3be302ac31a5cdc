"""The AtlasSimInterface's behaviours over a recorded run: what the bag's copy of the state
(/atlas/asi_state_recorded, 50 Hz and every change of behaviour or status) says happened,
as a timeline of changes: Stand, Walk, Step, Manipulate, auto-transitions and refusals."""

from __future__ import annotations

from dataclasses import dataclass

from tutorial_atlas_control import topics
from tutorial_atlas_control.bags.reader import BagData
from tutorial_atlas_control.bags.records import open_bag
from tutorial_atlas_control.bags.typestore import load_typestore
from tutorial_atlas_control.errors import BagAnalysisError

__all__ = ['BehaviourChange', 'behaviour_lines', 'read_behaviours', 'walk_windows']

_STATE_TYPE = 'atlas_msgs/msg/AtlasSimInterfaceState'
WALK = 4
#: A walk's window reaches back to the change before it (its WALK may wait there for Stand)
#: and on this long past its end (s): the last foot down and settled.
WALK_ENDS_AFTER_S = 1.0
#: AtlasSimInterfaceState.current_behavior's names (ASI.md).
BEHAVIOURS = ('STAND', 'USER', 'FREEZE', 'STAND_PREP', 'WALK', 'STEP', 'MANIPULATE')
#: behavior_feedback.status_flags' names, one value at a time (ASI.md).
STATUSES = {0: 'OK', 1: 'TRANSITION_IN_PROGRESS', 2: 'TRANSITION_SUCCESS',
            4: 'FAILED_TRANS_UNKNOWN_BEHAVIOR', 8: 'FAILED_TRANS_ILLEGAL_BEHAVIOR',
            16: 'FAILED_TRANS_COM_POS', 32: 'FAILED_TRANS_COM_VEL', 64: 'FAILED_TRANS_VEL',
            128: 'WARNING_AUTO_TRANS', 256: 'ERROR_FALLING'}


def _name(number: int, names: tuple[str, ...] | dict[int, str]) -> str:
    if isinstance(names, dict):
        return names.get(number, str(number))
    return names[number] if 0 <= number < len(names) else str(number)


@dataclass(frozen=True)
class BehaviourChange:
    """A recorded state whose behaviour or status differs from the one before (s from the
    bag's start); `asked` is what the status is about (behavior_feedback's trans_to)."""

    t_s: float
    behaviour: int
    status: int
    asked: int

    def line(self) -> str:
        status = '' if self.status == 0 else f'  {_name(self.status, STATUSES)}'
        if self.status in (1, 2, 4, 8, 16, 32, 64):  # about a request: which one
            status += f' ({_name(self.asked, BEHAVIOURS)} asked for)'
        return f'  {self.t_s:9.3f} s  {_name(self.behaviour, BEHAVIOURS)}{status}'


def read_behaviours(data: BagData) -> list[BehaviourChange] | None:
    """The changes in `data`'s bag, in time order; None when it has no recorded state
    (recorded before the simulator published one, or an offline run's bag)."""
    records = open_bag(data.path)
    try:
        connections = [c for c in records.connections if c.topic == topics.ASI_STATE_RECORDED]
        if not connections:
            return None
        typestore = load_typestore(records.connections)
        bag_ns, raws = records.raw_messages(connections)
        changes: list[BehaviourChange] = []
        last: tuple[int, int] | None = None
        for t_ns, raw in zip(bag_ns.tolist(), raws):
            state = typestore.deserialize_ros1(raw, _STATE_TYPE)
            feedback = state.behavior_feedback
            key = (int(state.current_behavior), int(feedback.status_flags))
            if key != last:
                changes.append(BehaviourChange(t_ns / 1e9 - data.start_time_s, *key,
                                               int(feedback.trans_to_behavior_index)))
                last = key
    except (KeyError, ValueError, AttributeError) as err:
        raise BagAnalysisError(f'Could not read {topics.ASI_STATE_RECORDED} of {data.path}: '
                               f'{err}') from err
    finally:
        records.close()
    return changes


def behaviour_lines(changes: list[BehaviourChange]) -> list[str]:
    """The report's section: each change on a line (times from the bag's start)."""
    if not changes:
        return [f'Behaviours: {topics.ASI_STATE_RECORDED} recorded, but no state in it']
    return ['Behaviours (the AtlasSimInterface\'s state; times from bag start):'] + [
        change.line() for change in changes]


def walk_windows(changes: list[BehaviourChange]) -> list[tuple[float, float]]:
    """Each walk's window (s from the bag's start): from the change before Walk began (its
    WALK commands were sent then) to WALK_ENDS_AFTER_S past the change that ended it."""
    windows = []
    for k, change in enumerate(changes):
        if change.behaviour != WALK or (k and changes[k - 1].behaviour == WALK):
            continue
        start = changes[k - 1].t_s if k else 0.0
        end = next((later.t_s for later in changes[k + 1:] if later.behaviour != WALK),
                   float('inf'))
        windows.append((start, end + WALK_ENDS_AFTER_S))
    return windows
