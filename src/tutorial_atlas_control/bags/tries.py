"""Cut a recorded run into tries: the stretches between the resets of one launch.

The tutorial's way of working is to run a trajectory, reset, and run one again without
restarting anything, so one bag often holds several tries. A try starts at the bag's
start or at a reset, which the bag shows in two ways:

* `/atlas/sim_config` is re-published after every reset (`/gazebo/reset_world`,
  `/gazebo/reset_simulation`, the viewer's reset) with the sim time of that reset; the
  first config in a bag is the one in force when recording began, not a reset.
* Sim time going back (`/gazebo/reset_simulation` sets it to 0): reader.py's epochs.
  A rewind with no config near it (an older bag) still starts a try.

Times are reader.py's run timeline (seconds from the bag's start).
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np

from tutorial_atlas_control.bags.reader import (
    BagData,
    JointCommandSeries,
    JointStateSeries,
    PelvisSeries,
    zero_order_hold,
)
from tutorial_atlas_control.bags.records import EPOCH_GAP_NS
from tutorial_atlas_control.errors import BagAnalysisError
from tutorial_atlas_control.units import NS_PER_S

__all__ = ['RESET_SIMULATION', 'RESET_WORLD', 'RUN_START', 'TIME_WENT_BACK', 'Try', 'find_tries',
           'pick_try', 'window']

#: How a try began.
RUN_START = 'start'
RESET_WORLD = 'reset_world'
RESET_SIMULATION = 'reset_simulation'
TIME_WENT_BACK = 'sim time went back'
#: A reset_world try starts this long (s) after the reset's time, half a 1 ms step: the
#: simulator's joint state stamped at that time was published before the reset.
_AFTER_RESET_S = 0.0005
#: How far (s) a recorder's clock may lag the simulator's: its record time of the config
#: a reset re-publishes can be that much before the reset (0.44 s seen under load).
RECORDER_LAG_S = 2.0
#: A rewind of sim time this close (s, run time) to a config's reset is that reset.
_SAME_RESET_S = 2.0 * EPOCH_GAP_NS / NS_PER_S


@dataclass(frozen=True)
class Try:
    """One try: number (1-based), [start, end) on the run timeline (s), how it began.

    `config` is the /atlas/sim_config text in force during the try (None: none recorded).
    """

    number: int
    start_s: float
    end_s: float
    cause: str
    config: str | None


def _last_reset_s(text: str) -> float | None:
    """The config's last_reset_time (s of sim time), None if the text has none."""
    try:
        value = json.loads(text).get('last_reset_time')
        return None if value is None else float(value)
    except (ValueError, TypeError, AttributeError):
        return None


def _reset_run_time_s(data: BagData, last_reset_s: float, t_s: float) -> float:
    """Where on the run timeline the reset_world of a config recorded at `t_s` happened: at
    its last_reset_time in the latest epoch holding that time, up to RECORDER_LAG_S after
    `t_s` (a lagging recorder's clock records the config before the reset's time); `t_s`
    when no epoch does (a config recorded after a rewind that followed its reset)."""
    for epoch in range(data.epoch_at(t_s), -1, -1):
        reset_s = data.run_time_s(last_reset_s, epoch)
        if reset_s <= t_s + RECORDER_LAG_S and data.epoch_at(reset_s) == epoch:
            return max(reset_s, 0.0)
    return t_s


def _config_resets(data: BagData) -> list[tuple[float, str, str]]:
    """(start, cause, config text) of each reset a re-published config marks."""
    resets = []
    for t_s, text in data.sim_configs[1:]:
        last_reset_s = _last_reset_s(text)
        if last_reset_s is None:
            continue
        later = [start for start in data.epoch_starts_s if start > t_s - _SAME_RESET_S]
        if last_reset_s == 0.0 and data.epoch_starts_s and later:
            # reset_simulation: the rewind nearest the config (it may arrive on either side).
            rewind_s = min(later, key=lambda start: abs(start - t_s))
            start_s = max(data.run_time_s(0.0, data.epoch_at(rewind_s)), rewind_s)
            resets.append((start_s, RESET_SIMULATION, text))
        else:
            # The joint state stamped at the reset time is the last one before it.
            start_s = _reset_run_time_s(data, last_reset_s, t_s) + _AFTER_RESET_S
            resets.append((start_s, RESET_WORLD, text))
    return resets


def find_tries(data: BagData) -> list[Try]:
    """The tries of the recorded run, in order (one try when nothing was reset)."""
    starts = _config_resets(data)
    for rewind_s in data.epoch_starts_s:
        if not any(abs(start - rewind_s) < _SAME_RESET_S for start, _, _ in starts):
            starts.append((rewind_s, TIME_WENT_BACK, None))  # type: ignore[arg-type]
    starts.sort(key=lambda start: start[0])
    first_config = data.sim_configs[0][1] if data.sim_configs else None
    starts.insert(0, (0.0, RUN_START, first_config))  # type: ignore[arg-type]
    tries = []
    config = first_config
    for number, (start_s, cause, text) in enumerate(starts, 1):
        config = text if text is not None else config
        end_s = starts[number][0] if number < len(starts) else max(data.duration_s, start_s)
        tries.append(Try(number, start_s, end_s, cause, config))
    return tries


def pick_try(tries: list[Try], number: int | None, path: object) -> Try:
    """Try `number` (1-based; negative counts from the end; None: the last).

    Raises:
        BagAnalysisError: there is no such try (the message says how many there are).
    """
    if number is None:
        return tries[-1]
    index = number - 1 if number > 0 else len(tries) + number
    if number == 0 or not 0 <= index < len(tries):
        raise BagAnalysisError(f'{path} holds {len(tries)} tr{"y" if len(tries) == 1 else "ies"}'
                               f' (1..{len(tries)}); there is no try {number}.')
    return tries[index]


def _rows(t_s: np.ndarray, start_s: float, end_s: float) -> np.ndarray:
    return (t_s >= start_s) & (t_s < end_s)


def window(data: BagData, start_s: float, end_s: float) -> BagData:
    """`data` cut to [start_s, end_s) on the run timeline, times unchanged.

    An `end_s` at or after the bag's end keeps everything to the end (its last message).
    The control mode in force at `start_s` is kept as the window's first mode, and the
    commands' held positions are re-held from the window's first command (so a try does
    not inherit the targets of the try before it).
    """
    if end_s >= data.duration_s:
        end_s = np.inf
    states = data.joint_states
    if states is not None:
        rows = _rows(states.t_s, start_s, end_s)
        states = JointStateSeries(states.t_s[rows], states.names, states.position[rows],
                                  states.velocity[rows], states.effort[rows])
    commands = data.commands
    if commands is not None:
        rows = _rows(commands.t_s, start_s, end_s)
        commands = JointCommandSeries(commands.t_s[rows], commands.position[rows],
                                      zero_order_hold(commands.position[rows]))
    pelvis = data.pelvis
    if pelvis is not None:
        rows = _rows(pelvis.t_s, start_s, end_s)
        pelvis = PelvisSeries(pelvis.t_s[rows], pelvis.position_m[rows],
                              pelvis.orientation_xyzw[rows], pelvis.linear_velocity_m_s[rows],
                              pelvis.angular_velocity_rad_s[rows])
    before = [mode for t_s, mode in data.modes if t_s < start_s]
    modes = ([(start_s, before[-1])] if before else []) + [
        (t_s, mode) for t_s, mode in data.modes if start_s <= t_s < end_s]
    return BagData(
        data.path, data.start_time_s, data.duration_s, data.topics, states, commands, pelvis,
        modes, [(t_s, text) for t_s, text in data.sim_configs if start_s <= t_s < end_s],
        list(data.warnings), [(t_s, p) for t_s, p in data.played if start_s <= t_s < end_s],
        list(data.epoch_starts_s), list(data.epoch_shifts_s),
        [(t_s, text) for t_s, text in data.sim_inputs if start_s <= t_s < end_s],
        [(t_s, fall) for t_s, fall in data.logged_falls if start_s <= t_s < end_s])
