"""The AtlasSimInterface's behaviours over a recorded run: what the bag's copy of the state
(/atlas/asi_state_recorded, 50 Hz and every change of behaviour or status) says happened,
as a timeline of changes: Stand, Walk, Step, Manipulate, auto-transitions and refusals."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tutorial_atlas_control import topics
from tutorial_atlas_control.bags.reader import BagData
from tutorial_atlas_control.bags.records import open_bag
from tutorial_atlas_control.bags.typestore import load_typestore
from tutorial_atlas_control.errors import BagAnalysisError

__all__ = ['BehaviourChange', 'behaviour_lines', 'plot_behaviours', 'read_behaviours',
           'walk_windows']

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
    WALK commands were sent then) to WALK_ENDS_AFTER_S past the change that ended it, or to
    the next walk's window if that begins sooner: a client's step indices start at 1 again
    each walk, so one walk's window must not hold the next one's steps."""
    spans = []
    for k, change in enumerate(changes):
        if change.behaviour != WALK or (k and changes[k - 1].behaviour == WALK):
            continue
        start = changes[k - 1].t_s if k else 0.0
        end = next((later.t_s for later in changes[k + 1:] if later.behaviour != WALK),
                   float('inf'))
        spans.append((start, end + WALK_ENDS_AFTER_S))
    return [(start, min(end, spans[n + 1][0]) if n + 1 < len(spans) else end)
            for n, (start, end) in enumerate(spans)]


#: Each behaviour's colour in the plot.
_COLOURS = {0: 'tab:green', 1: '0.75', 2: 'tab:cyan', 3: 'tab:olive', 4: 'tab:blue',
            5: 'tab:purple', 6: 'tab:orange'}
#: Statuses marked on the plot: refusals, the library's own switches, falling.
_MARKED = {4, 8, 16, 32, 64, 128, 256}


def plot_behaviours(changes: list[BehaviourChange], t_s: np.ndarray,
                    pelvis_height_m: np.ndarray, path: Path) -> Path:
    """The pelvis height over the run, each behaviour's span shaded in its colour, and
    refusals, auto-transitions and ERROR_FALLING marked and named; written to `path`."""
    import matplotlib  # noqa: PLC0415 - only the plot needs it
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt  # noqa: PLC0415

    figure, ax = plt.subplots(figsize=(10.0, 4.0))
    ax.plot(t_s, pelvis_height_m, color='black', lw=1, label='pelvis height')
    end_s = float(t_s[-1]) if len(t_s) else (changes[-1].t_s if changes else 1.0)
    spans = [change for k, change in enumerate(changes)
             if k == 0 or change.behaviour != changes[k - 1].behaviour]
    shown: set[int] = set()
    for span, after in zip(spans, [*spans[1:], None]):
        colour = _COLOURS.get(span.behaviour, '0.9')
        label = None if span.behaviour in shown else _name(span.behaviour, BEHAVIOURS)
        shown.add(span.behaviour)
        ax.axvspan(span.t_s, end_s if after is None else after.t_s, color=colour, alpha=0.25,
                   lw=0, label=label)
    for number, change in enumerate(c for c in changes if c.status in _MARKED):
        ax.axvline(change.t_s, color='tab:red', lw=0.8, ls=':')
        ax.annotate(_name(change.status, STATUSES), (change.t_s, 1.0),
                    xycoords=('data', 'axes fraction'), xytext=(2, -10 - 9 * (number % 3)),
                    textcoords='offset points', fontsize=7, color='tab:red')
    ax.set_xlabel('time from the bag\'s start (s)')
    ax.set_ylabel('pelvis height (m)')
    ax.set_title('the AtlasSimInterface\'s behaviours')
    ax.legend(loc='lower left', fontsize='small', ncol=4)
    figure.tight_layout()
    figure.savefig(path, dpi=100)
    plt.close(figure)
    return path
