"""Offline replay: re-simulate a recorded run from its bag, without ROS, and compare.

The simulator publishes, after every 1 ms step k, the joint state at sim time k·dt with
`effort` = the torque applied during that step. Replaying therefore means: start from the
state the simulator started from and drive the same :meth:`AtlasSimulator.step` with each
recorded effort in place of the controller law's torque, so the torso pin
(`time_to_unpin` after `last_reset_time`, from `/atlas/sim_config`) and the divergence check
are the node's own code. The positions and velocities are float64, serialized exactly, so
the same MuJoCo build reproduces them bit for bit.

Two details make that exact:
* The replay starts at the reset the simulator started from (`last_reset_time`), never
  from a recorded mid-run state: MuJoCo's solver warm-start (and the free joint's
  velocity) are not in the bag.
* The inputs that act on the physics beside the torques (VRCPlugin's modes, teleports,
  cmd_vel, the pelvis wrench, kinematic playback) are re-applied from /atlas/sim_inputs
  before the very step they first acted in; a bag that lacks one of them after the last
  reset is refused.
* A bag with resets holds several tries (bags.tries); one try is replayed, by default
  the last, from its reset with the config re-published then: the sim time of a try is
  its own (after a /gazebo/reset_simulation it starts again from 0).
* `rosbag record` usually starts a few hundred steps after the simulator. The steps before
  the first recorded joint state are re-created with :class:`AtlasSimulator` itself in
  Stand mode with the gains of config/atlas_controller.yaml (what the simulator does
  until somebody changes the mode), and checked against the first recorded torque.

Times in the report are sim time (s), as stamped by the simulator.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from tutorial_atlas_control import topics
from tutorial_atlas_control.bags import (
    BagData,
    LaserScans,
    ScoreEntry,
    Try,
    find_tries,
    pick_try,
    read_bag,
    read_laser_scans,
    read_scores,
    window,
)
from tutorial_atlas_control.course import CourseError
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.offline.replay_scan import ScanComparison, ScanReplay
from tutorial_atlas_control.offline.replay_score import ScoreComparison, ScoreReplay
from tutorial_atlas_control.offline.world import recorded_world
from tutorial_atlas_control.sim import (
    DEFAULT_GAINS_FILE,
    DEFAULT_TIME_TO_UNPIN_S,
    STARTUP_MODES,
    AtlasSimulator,
    InputError,
    InputEvent,
    PhysicsDivergenceError,
    SimConfig,
    SimConfigError,
    VrcMode,
    load_gains_yaml,
    load_model,
    parse_sim_config,
)
from tutorial_atlas_control.units import NS_PER_S

__all__ = [
    'DEFAULT_TOLERANCE',
    'Deviation',
    'Recording',
    'ReplayError',
    'ReplayResult',
    'format_report',
    'load_recording',
    'replay',
    'replay_bag',
]

SIM_CONFIG_TOPIC = topics.SIM_CONFIG
JOINT_STATES_TOPIC = topics.JOINT_STATES
ODOM_TOPIC = topics.GROUND_TRUTH_ODOM
#: The replay counts as reproducing the run when every deviation is at most this.
DEFAULT_TOLERANCE = 1e-6
#: When the bag predates /atlas/sim_config: the simulator's defaults, no reset after start (s).
DEFAULT_LAST_RESET_S = 0.0
#: A stamp further than this fraction of a step from the step grid is not a simulator stamp.
_GRID_TOLERANCE_STEPS = 1e-3


class ReplayError(AtlasControlError):
    """The bag cannot be replayed; the message says what is missing or unsupported."""


# ---------------------------------------------------------------------------- recording


@dataclass(frozen=True)
class Recording:
    """What replay needs from a bag; stamps are sim time (ns).

    `state_*` rows are /atlas/joint_states in tutorial joint order; `odom_*` rows are
    /ground_truth_odom (quaternion w x y z, as MuJoCo stores it).
    """

    path: Path
    config: SimConfig
    resets_in_bag: int
    state_stamp_ns: np.ndarray
    position_rad: np.ndarray
    velocity_rad_s: np.ndarray
    effort_nm: np.ndarray
    odom_stamp_ns: np.ndarray
    odom_position_m: np.ndarray
    odom_quat_wxyz: np.ndarray
    has_odom: bool
    warnings: list[str] = field(default_factory=list)
    inputs: list[InputEvent] = field(default_factory=list)  # since the try's reset, in order
    try_number: int = 1
    tries: int = 1
    try_asked: bool = False  # --try given: the report's 'try N of M' says it, no warning
    scores: list[ScoreEntry] | None = None  # /vrc_score of a scored run (the whole bag's)
    scans: LaserScans | None = None  # the head laser's scans, when comparable


def _read_sim_configs(data: BagData) -> list[dict[str, Any]]:
    """Every /atlas/sim_config message of `data`, in record order, as JSON objects."""
    try:
        return [parse_sim_config(text) for _, text in data.sim_configs]
    except SimConfigError as err:
        raise ReplayError(f'{data.path}: {SIM_CONFIG_TOPIC} {err}') from err


def _sim_config(path: Path, raw_configs: list[dict[str, Any]], chosen: dict[str, Any] | None,
                resets: int, warnings: list[str],
                assume_defaults: bool = False) -> tuple[SimConfig, int]:
    """The config in force for the chosen try, and how many resets the bag shows.

    Without /atlas/sim_config the pin time and the last reset are unknown: refused unless
    `assume_defaults` (the simulator's defaults, with a warning).
    """
    if not raw_configs:
        if not assume_defaults:
            raise ReplayError(
                f'{path} has no {SIM_CONFIG_TOPIC} (not recorded by atlas.launch, or before '
                'the simulator published it): the pin time and the last reset are unknown; '
                f'--assume-defaults replays it with time_to_unpin = {DEFAULT_TIME_TO_UNPIN_S} s '
                f'and no reset after t = {DEFAULT_LAST_RESET_S} s.')
        warnings.append(f'the bag has no {SIM_CONFIG_TOPIC} (recorded before the simulator '
                        f'published it): assuming time_to_unpin = {DEFAULT_TIME_TO_UNPIN_S} s '
                        f'and no reset after t = {DEFAULT_LAST_RESET_S} s.')
        return SimConfig(None, None, None, DEFAULT_TIME_TO_UNPIN_S, DEFAULT_LAST_RESET_S,
                         recorded=False), 0
    try:
        config = SimConfig.from_dict(raw_configs[-1] if chosen is None else chosen)
    except SimConfigError as err:
        raise ReplayError(f'{path}: {SIM_CONFIG_TOPIC} {err}') from None
    return config, resets


#: The topics whose messages become /atlas/sim_inputs when applied.
CHEAT_TOPICS = (topics.MODE, topics.SET_POSE, topics.CMD_VEL, topics.APPLY_PELVIS_FORCE,
                topics.JOINT_TRAJECTORY)


def _input_events(path: Path, data: BagData, config: SimConfig,
                  warnings: list[str]) -> list[InputEvent]:
    """The applied inputs of the last segment, all of them from the first, in order.

    Raises:
        ReplayError: an /atlas/sim_inputs text is not an input, or one is missing.
    """
    reset_ns = int(round(config.last_reset_time_s * NS_PER_S))
    events = []
    for _, text in data.sim_inputs:
        try:
            event = InputEvent.from_json(text)
        except InputError as err:
            raise ReplayError(f'{path}: {topics.SIM_INPUTS} {err}.') from None
        if event.reset_ns == reset_ns:
            events.append(event)
    events.sort(key=lambda event: event.seq)
    for expected, event in enumerate(events):
        if event.seq != expected:
            raise ReplayError(
                f'{path} lacks {topics.SIM_INPUTS} input #{expected} after the reset at '
                f'{reset_ns / NS_PER_S:.3f} s (the recorder started after it or dropped it); '
                'the run cannot be replayed exactly.')
    if not data.sim_inputs:
        sent = [topic for topic in CHEAT_TOPICS
                if topic in data.topics and data.topics[topic].count]
        if sent:
            warnings.append(f'the bag has {", ".join(sent)} but no {topics.SIM_INPUTS}: if '
                            'the simulator applied any of them, the replay deviates.')
    return events


def _stamps_ns(data: BagData, t_s: np.ndarray) -> np.ndarray:
    """Sim time stamps (ns) from BagData's seconds-from-bag-start (run timeline)."""
    epochs = np.searchsorted(data.epoch_starts_s, t_s, side='right')
    sim_s = data.start_time_s + t_s - np.asarray(data.epoch_shifts_s)[epochs]
    return np.round(sim_s * NS_PER_S).astype(np.int64)


def _chosen_try(data: BagData, try_number: int | None) -> tuple[BagData, Try, int]:
    """(`data` cut to the chosen try, the try, how many tries the bag holds)."""
    tries = find_tries(data)
    chosen = pick_try(tries, try_number, data.path)
    return window(data, chosen.start_s, chosen.end_s), chosen, len(tries)


def _to_steps(stamps_ns: np.ndarray, step_ns: int, what: str) -> np.ndarray:
    """Stamps (ns) as step indices; every simulator stamp lies on the step grid."""
    steps = (stamps_ns + step_ns // 2) // step_ns
    off_grid = np.abs(stamps_ns - steps * step_ns) > _GRID_TOLERANCE_STEPS * step_ns
    if off_grid.any():
        t_s = int(stamps_ns[np.argmax(off_grid)]) / NS_PER_S
        raise ReplayError(f'{what} stamp {t_s:.9f} s is not a multiple of the timestep '
                          f'{step_ns / NS_PER_S} s: not stamped by this simulator.')
    return steps


def load_recording(path: Path | str, data: BagData | None = None,
                   try_number: int | None = None, assume_defaults: bool = False) -> Recording:
    """Read what replay needs from the bag at `path` (`data`: an already read BagData).

    The bag is opened once: /atlas/sim_config comes with the series in `data`.
    `try_number`: the try to replay (1-based, negative from the end; None: the last).
    `assume_defaults`: replay a bag without /atlas/sim_config with the simulator's defaults
    (otherwise refused).

    Raises:
        ReplayError / BagAnalysisError: unreadable bag, no such try, missing joint states or
            joints, a sim_config without the needed keys, stamps off the step grid.
    """
    path = Path(path)
    data = read_bag(path) if data is None else data
    warnings: list[str] = []
    raw_configs = _read_sim_configs(data)
    data, chosen, tries = _chosen_try(data, try_number)
    states = data.joint_states
    if states is None or not len(states.t_s):
        where = '' if tries == 1 else f' in try {chosen.number}'
        raise ReplayError(f'{path} has no {JOINT_STATES_TOPIC}{where}: the replay needs the '
                          'recorded torques (effort) of every step.')
    chosen_config = (None if chosen.config is None or not raw_configs
                     else parse_sim_config(chosen.config))
    config, resets = _sim_config(path, raw_configs, chosen_config, tries - 1, warnings,
                                 assume_defaults)
    tests = data.topics.get(topics.ATLAS_TEST)
    if tests is not None and tests.count:
        # Its damping changes the model, which the recorded torques do not carry.
        warnings.append(f'the run has {tests.count} {topics.ATLAS_TEST} message(s): joint '
                        'damping they set is not re-applied offline, so the replay deviates '
                        'from the first that set it.')
    columns = _joint_columns(path, states.names)
    state_stamp_ns = _stamps_ns(data, states.t_s)
    effort = states.effort[:, columns]
    position = states.position[:, columns]
    velocity = states.velocity[:, columns]
    if not (np.isfinite(effort).all() and np.isfinite(position).all()):
        raise ReplayError(f'{JOINT_STATES_TOPIC} in {path} has missing (NaN) positions or '
                          'efforts; every message must carry all 28 joints.')
    odom_stamp_ns, odom_position, odom_quat = _pelvis_series(data, warnings)
    inputs = _input_events(path, data, config, warnings)
    return Recording(path, config, resets, state_stamp_ns, position, velocity, effort,
                     odom_stamp_ns, odom_position, odom_quat, len(odom_stamp_ns) > 0, warnings,
                     inputs, chosen.number, tries, try_asked=try_number is not None,
                     scores=read_scores(data), scans=_comparable_scans(data, warnings))


def _probe(recording: Recording, sim: AtlasSimulator, odom_steps: np.ndarray,
           reset_step: int, last_step: int, warnings: list[str]) -> _OdomProbe:
    """What watches each replayed step: the odometry's poses, the score, the laser's scans."""
    probe = _OdomProbe(odom_steps, reset_step, last_step)
    probe.score = _score_replay(recording, sim, reset_step, warnings)
    probe.scans = ScanReplay.of(sim, _scans_from(recording.scans, reset_step, warnings),
                                recording.config.sensor_seed)
    return probe


def _scans_from(scans: LaserScans | None, reset_step: int,
                warnings: list[str]) -> LaserScans | None:
    """The scans a replay from `reset_step` can compare: a commanded spindle's only from sim
    time 0 (its speed at a later reset is not recorded)."""
    if scans is not None and scans.spindle_commands and reset_step != 0:
        warnings.append(f'{topics.LASER_SCAN} is not compared: the spindle was commanded and '
                        'the replayed try begins at a reset, where its speed is not recorded.')
        return None
    return scans


def _comparable_scans(data: BagData, warnings: list[str]) -> LaserScans | None:
    """The bag's laser scans, if it has any that replay can compare (a bag without any is
    not opened again)."""
    if not getattr(data.topics.get(topics.LASER_SCAN), 'count', 0):
        return None
    scans = read_laser_scans(data.path)
    return scans if ScanReplay.comparable(scans, warnings) else None


def _joint_columns(path: Path, names: Sequence[str]) -> list[int]:
    """Where each of the 28 joints (tutorial order) is in the recorded joint states.

    Raises:
        ReplayError: some joints are missing (the message names them).
    """
    missing = [name for name in JOINT_NAMES if name not in names]
    if missing:
        raise ReplayError(f'{JOINT_STATES_TOPIC} in {path} lacks joints {", ".join(missing)}; '
                          'the replay needs the torque of all 28.')
    return [names.index(name) for name in JOINT_NAMES]


def _pelvis_series(data: BagData,
                   warnings: list[str]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The recorded pelvis pose: stamps (ns), positions (m), quaternions (w, x, y, z); all
    empty, with a warning, when the bag has no odometry."""
    pelvis = data.pelvis
    if pelvis is None or not len(pelvis.t_s):
        warnings.append(f'the bag has no {ODOM_TOPIC}: the pelvis pose is not compared.')
        return np.empty(0, dtype=np.int64), np.empty((0, 3)), np.empty((0, 4))
    return (_stamps_ns(data, pelvis.t_s), pelvis.position_m,
            pelvis.orientation_xyzw[:, [3, 0, 1, 2]])


# ---------------------------------------------------------------------------- replay


@dataclass(frozen=True)
class Deviation:
    """Largest |replayed - recorded| over `samples`, when (sim time, s) and where (joint)."""

    max_abs: float
    time_s: float | None
    joint: str | None
    samples: int


@dataclass(frozen=True)
class ReplayResult:
    """The outcome of one replay (units: rad, rad/s, m; times are sim time in s)."""

    bag: Path
    config: SimConfig
    resets_in_bag: int
    model_sha1_matches: bool | None
    start_time_s: float          # the reset the replay starts from
    end_time_s: float            # sim time after the last replayed step
    reconstructed_steps: int     # steps before the recording, re-created in Stand mode
    recorded_steps: int          # steps driven by the recorded torques
    joint_position: Deviation
    joint_velocity: Deviation
    pelvis_position: Deviation | None
    pelvis_orientation: Deviation | None
    tolerance: float
    warnings: list[str]
    try_number: int = 1          # the try replayed (bags.tries), of
    tries: int = 1               # the tries the bag holds
    score: ScoreComparison | None = None  # a scored run's /vrc_score against the replay's
    scans: ScanComparison | None = None  # the laser's scans cast again against the recorded


    @property
    def reproduced(self) -> bool:
        """Every compared deviation is within the tolerance."""
        compared = [self.joint_position, self.joint_velocity, self.pelvis_position,
                    self.pelvis_orientation]
        return (all(d.max_abs <= self.tolerance for d in compared if d is not None)
                and (self.score is None or self.score.same)
                and (self.scans is None or self.scans.same))

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict (keys documented in replay_bag.py --help)."""
        def deviation(value: Deviation | None) -> dict[str, Any] | None:
            if value is None:
                return None
            return {'max': value.max_abs, 'time': value.time_s, 'joint': value.joint,
                    'samples': value.samples}

        config = self.config
        return {
            'bag': str(self.bag),
            'sim_config': {'recorded': config.recorded, **config.to_dict()},
            'resets_in_bag': self.resets_in_bag,
            'try': self.try_number,
            'tries': self.tries,
            'model_sha1_matches': self.model_sha1_matches,
            'start_time': self.start_time_s,
            'end_time': self.end_time_s,
            'reconstructed_steps': self.reconstructed_steps,
            'recorded_steps': self.recorded_steps,
            'joint_position': deviation(self.joint_position),
            'joint_velocity': deviation(self.joint_velocity),
            'pelvis_position': deviation(self.pelvis_position),
            'pelvis_orientation': deviation(self.pelvis_orientation),
            'tolerance': self.tolerance,
            'reproduced': self.reproduced,
            'vrc_score': None if self.score is None else self.score.to_dict(),
            'laser_scans': None if self.scans is None else self.scans.to_dict(),
            'warnings': list(self.warnings),
        }


def _quat_angle_rad(a_wxyz: np.ndarray, b_wxyz: np.ndarray) -> np.ndarray:
    """Rotation angle (rad) between rows of unit quaternions, robust near 0."""
    a = a_wxyz / np.linalg.norm(a_wxyz, axis=1, keepdims=True)
    b = b_wxyz / np.linalg.norm(b_wxyz, axis=1, keepdims=True)
    dot = np.abs(np.sum(a * b, axis=1))
    # |a - b| or |a + b| (same rotation), whichever is smaller, gives the half-angle chord.
    chord = np.minimum(np.linalg.norm(a - b, axis=1), np.linalg.norm(a + b, axis=1))
    return np.where(dot < 0.9, 2.0 * np.arccos(np.clip(dot, 0.0, 1.0)),
                    4.0 * np.arcsin(np.clip(chord / 2.0, 0.0, 1.0)))


def _deviation(replayed: np.ndarray, recorded: np.ndarray, steps: np.ndarray, step_ns: int,
               names: Sequence[str] | None = None) -> Deviation:
    """The largest deviation; where and when only if there is one."""
    if not len(steps):
        return Deviation(0.0, None, None, 0)
    error = np.abs(replayed - recorded)
    if error.ndim == 1:
        error = error[:, None]
    row, column = divmod(int(np.argmax(error)), error.shape[1])
    largest = float(error[row, column])
    if largest == 0.0:
        return Deviation(0.0, None, None, len(steps))
    joint = names[column] if names is not None else None
    return Deviation(largest, int(steps[row]) * step_ns / NS_PER_S, joint, len(steps))


def _segment(recording: Recording, steps: np.ndarray, reset_step: int, dt_s: float,
             warnings: list[str]) -> np.ndarray:
    """Row indices of the joint states to replay: after the reset, contiguous steps."""
    if np.any(np.diff(steps) <= 0):
        at = int(np.argmax(np.diff(steps) <= 0))
        raise ReplayError(
            f'{JOINT_STATES_TOPIC} stamps go backwards or repeat at {steps[at + 1] * dt_s:.3f} s '
            '(a /gazebo/reset_simulation during the recording?); replay supports runs whose '
            'sim time only moves forward: cut the bag with `rosbag filter` after the reset.')
    rows = np.flatnonzero(steps > reset_step)
    if not len(rows):
        raise ReplayError(f'{recording.path} has no {JOINT_STATES_TOPIC} after the last reset '
                          f'at {reset_step * dt_s:.3f} s; nothing to replay.')
    gaps = np.flatnonzero(np.diff(steps[rows]) != 1)
    if len(gaps):
        last = rows[gaps[0]]
        missing = int(steps[rows[gaps[0] + 1]] - steps[last] - 1)
        warnings.append(
            f'{missing} joint state(s) missing after {steps[last] * dt_s:.3f} s (the recorder '
            'dropped messages; their torques are unknown): replayed only up to there.')
        rows = rows[:gaps[0] + 1]
    return rows


class _OdomProbe:
    """Collects the replayed pelvis pose at the steps /ground_truth_odom was recorded."""

    def __init__(self, odom_steps: np.ndarray, reset_step: int, last_step: int) -> None:
        self.row_at = {int(step): row for row, step in enumerate(odom_steps.tolist())
                       if reset_step < step <= last_step}
        self.rows: list[int] = []
        self.xpos: list[np.ndarray] = []
        self.xquat: list[np.ndarray] = []
        #: The course's scoring of each replayed step (a scored run's), or None.
        self.score: ScoreReplay | None = None
        #: The laser's scans cast again after each replayed step, or None.
        self.scans: ScanReplay | None = None

    def after_step(self, sim: AtlasSimulator, step: int) -> None:
        """Called after replaying step `step` (the state at sim time step * dt)."""
        if self.score is not None:
            self.score()
        if self.scans is not None:
            self.scans()
        # After mj_step, xpos/xquat describe the step's start; the simulator stamps its
        # odometry with that time, so the pose belongs to the previous step's number.
        row = self.row_at.get(step - 1)
        if row is not None:
            body = sim.atlas.pelvis_body_id
            self.rows.append(row)
            self.xpos.append(sim.data.xpos[body].copy())
            self.xquat.append(sim.data.xquat[body].copy())

    def deviations(self, recording: Recording, odom_steps: np.ndarray,
                   step_ns: int) -> tuple[Deviation, Deviation]:
        """(pelvis position, pelvis orientation) deviations over the collected poses."""
        rows = np.array(self.rows, dtype=np.int64)
        steps = odom_steps[rows]
        xpos = np.array(self.xpos).reshape(-1, 3)
        xquat = np.array(self.xquat).reshape(-1, 4)
        position = _deviation(xpos, recording.odom_position_m[rows], steps, step_ns)
        angles = (_quat_angle_rad(xquat, recording.odom_quat_wxyz[rows])
                  if len(rows) else np.empty(0))
        return position, _deviation(angles, np.zeros(len(angles)), steps, step_ns)


def _check_model(config: SimConfig, sim: AtlasSimulator, warnings: list[str]) -> bool | None:
    """Whether the model is the recorded one (None: not recorded); a timestep must match.

    Raises:
        ReplayError: the run was simulated with another timestep.
    """
    if config.timestep_s is not None and config.timestep_s != sim.dt_s:
        raise ReplayError(f'the run was simulated with timestep {config.timestep_s} s but '
                          f'{sim.atlas_path.name} has {sim.dt_s} s; replay with the same model.')
    if not config.model_sha1:
        return None
    if sim.atlas_sha1 != config.model_sha1:
        warnings.append(f'{sim.atlas_path} differs from the model the run was recorded with '
                        f'(sha1 {config.model_sha1[:12]}); expect deviations.')
        return False
    return True


def _reset_step(config: SimConfig, step_ns: int) -> int:
    """The step number of the reset the replay starts from."""
    reset_ns = int(round(config.last_reset_time_s * NS_PER_S))
    if reset_ns % step_ns:
        raise ReplayError(f'last_reset_time {config.last_reset_time_s} s is not on the step grid.')
    return reset_ns // step_ns


class _InputQueue:
    """The recorded inputs, each applied right before the step it first acted in."""

    def __init__(self, events: Sequence[InputEvent]) -> None:
        self.events = list(events)
        self.next = 0

    def apply_due(self, sim: AtlasSimulator) -> None:
        events = self.events
        while self.next < len(events) and events[self.next].time_ns <= sim.sim_time_ns:
            event = events[self.next]
            if event.time_ns < sim.sim_time_ns:  # pragma: no cover - stamps are checked
                raise ReplayError(f'{topics.SIM_INPUTS} #{event.seq} at '
                                  f'{event.time_ns / NS_PER_S:.3f} s is off the step grid.')
            sim.apply_input(event.item)
            self.next += 1


def _recreate_prefix(sim: AtlasSimulator, config: SimConfig, reset_step: int, first_step: int,
                     first_effort_nm: np.ndarray, probe: _OdomProbe,
                     warnings: list[str], inputs: _InputQueue) -> int:
    """Step the simulator's Stand law up to the first recorded step; return how many steps.

    Raises:
        ReplayError: steps are missing after a mid-run reset (the mode then is unknown).
    """
    prefix = first_step - reset_step - 1
    if prefix <= 0:
        return 0
    if reset_step != 0:
        raise ReplayError(
            f'the recording starts {prefix} steps after the reset at '
            f'{config.last_reset_time_s:.3f} s, and the control mode then is unknown; '
            'only the steps before the recording of a run that starts at t = 0 can be '
            're-created (Stand mode).')
    for step in range(1, first_step):
        inputs.apply_due(sim)
        _step(sim)
        probe.after_step(sim, step)
    # The first recorded torque must be what the Stand law gives, or the run had left
    # Stand mode (or used other gains) before the recorder started.
    mismatch = float(np.max(np.abs(sim.next_law_torque() - first_effort_nm)))
    if mismatch > 0.0:
        warnings.append(
            f'the first recorded torque differs by up to {mismatch:.3g} N m from the '
            'Stand-mode law: the mode or the gains changed before the recording began, '
            f'so the {prefix} steps before it cannot be re-created exactly.')
    return prefix


def _step(sim: AtlasSimulator, torque_nm: np.ndarray | None = None) -> None:
    """One simulator step; a divergence becomes a ReplayError saying what it means here."""
    try:
        sim.step(torque_nm)
    except PhysicsDivergenceError as err:
        raise ReplayError(
            f'in the replay, {err}; if the recorded run diverged too, the simulator reset the '
            f'robot there, which the bag does not mark ({SIM_CONFIG_TOPIC} is not re-published '
            'on a divergence reset).') from None


def _replay_recorded(sim: AtlasSimulator, steps: np.ndarray, effort_nm: np.ndarray,
                     probe: _OdomProbe, inputs: _InputQueue) -> tuple[np.ndarray, np.ndarray]:
    """Apply the recorded torques; the joint positions and velocities after each step."""
    position = np.empty((len(steps), NUM_JOINTS))
    velocity = np.empty((len(steps), NUM_JOINTS))
    for index, step in enumerate(steps.tolist()):
        inputs.apply_due(sim)
        _step(sim, effort_nm[index])
        position[index] = sim.joint_positions()
        velocity[index] = sim.joint_velocities()
        probe.after_step(sim, step)
    return position, velocity


def replay(recording: Recording, tolerance: float = DEFAULT_TOLERANCE,
           gains_file: Path = DEFAULT_GAINS_FILE,
           model_path: Path | None = None) -> ReplayResult:
    """Re-simulate `recording` and measure how far it strays from the recorded run: in the
    world its config names (offline.world), or the model at `model_path`; in a world with
    mud, with the config's mud_damping.

    Raises:
        ReplayError: unsupported recording (timestep differs from the model's; steps before
            the recording after a mid-run reset; nothing after the last reset; divergence).
    """
    warnings = list(recording.warnings)
    config = recording.config
    if config.startup_mode not in STARTUP_MODES:
        raise ReplayError(f'{SIM_CONFIG_TOPIC} startup_mode {config.startup_mode!r} is not '
                          f'one of {", ".join(STARTUP_MODES)}.')
    try:
        world = recorded_world(config)
    except CourseError as err:
        raise ReplayError(f'{err}.') from None
    sim = AtlasSimulator(load_model(model_path or world.model_path),
                         load_gains_yaml(gains_file), config.time_to_unpin_s,
                         startup_mode=VrcMode(config.startup_mode), start=world.start,
                         mud_damping=world.mud_damping)
    sha1_matches = _check_model(config, sim, warnings)
    step_ns = sim.step_ns
    reset_step = _reset_step(config, step_ns)
    sim.reset_simulation(reset_step * step_ns)
    if recording.resets_in_bag and not recording.try_asked:
        which = ('the last segment' if recording.try_number == recording.tries
                 else f'try {recording.try_number} of {recording.tries}')
        warnings.append(f'the bag holds {recording.resets_in_bag} reset(s); replaying {which}, '
                        f'from the reset at {config.last_reset_time_s:.3f} s (sim time).')
    all_steps = _to_steps(recording.state_stamp_ns, step_ns, JOINT_STATES_TOPIC)
    odom_steps = _to_steps(recording.odom_stamp_ns, step_ns, ODOM_TOPIC)
    rows = _segment(recording, all_steps, reset_step, sim.dt_s, warnings)
    steps, effort = all_steps[rows], recording.effort_nm[rows]
    probe = _probe(recording, sim, odom_steps, reset_step, int(steps[-1]), warnings)
    inputs = _InputQueue(recording.inputs)
    prefix = _recreate_prefix(sim, config, reset_step, int(steps[0]), effort[0], probe, warnings,
                              inputs)
    position, velocity = _replay_recorded(sim, steps, effort, probe, inputs)
    pelvis_position, pelvis_orientation = (probe.deviations(recording, odom_steps, step_ns)
                                           if recording.has_odom else (None, None))
    return ReplayResult(
        bag=recording.path, config=config, resets_in_bag=recording.resets_in_bag,
        model_sha1_matches=sha1_matches, start_time_s=reset_step * step_ns / NS_PER_S,
        end_time_s=int(steps[-1]) * step_ns / NS_PER_S, reconstructed_steps=prefix,
        recorded_steps=len(steps),
        joint_position=_deviation(position, recording.position_rad[rows], steps, step_ns,
                                  JOINT_NAMES),
        joint_velocity=_deviation(velocity, recording.velocity_rad_s[rows], steps, step_ns,
                                  JOINT_NAMES),
        pelvis_position=pelvis_position, pelvis_orientation=pelvis_orientation,
        tolerance=tolerance, warnings=warnings, try_number=recording.try_number,
        tries=recording.tries,
        score=probe.score.compare(int(steps[-1]) * step_ns) if probe.score else None,
        scans=probe.scans.compare() if probe.scans else None)


def _score_replay(recording: Recording, sim: AtlasSimulator, reset_step: int,
                  warnings: list[str]) -> ScoreReplay | None:
    """The replay's scorer, for a scored run replayed from its start (else None)."""
    if recording.scores is None:
        return None
    if reset_step != 0 or recording.tries != 1:
        warnings.append(f'{topics.VRC_SCORE} is not compared: the score runs over the whole '
                        'run and a replay from a reset cannot score it again.')
        return None
    return ScoreReplay(sim, recording.scores)


def replay_bag(path: Path | str, tolerance: float = DEFAULT_TOLERANCE,
               try_number: int | None = None, assume_defaults: bool = False,
               model_path: Path | None = None) -> ReplayResult:
    """:func:`load_recording` (of try `try_number`, None: the last) then :func:`replay`."""
    return replay(load_recording(path, try_number=try_number,
                                 assume_defaults=assume_defaults), tolerance,
                  model_path=model_path)


# ---------------------------------------------------------------------------- report


def _describe(label: str, value: Deviation | None, unit: str) -> str:
    if value is None:
        return f'  {label:<20} not compared'
    if not value.samples:
        return f'  {label:<20} no samples'
    where = f' ({value.joint})' if value.joint else ''
    at = f' at {value.time_s:.3f} s{where}' if value.max_abs > 0.0 else ''
    return f'  {label:<20} max |diff| {value.max_abs:.3g} {unit}{at}, {value.samples} samples'


def format_report(result: ReplayResult) -> str:
    """The text report."""
    config = result.config
    source = 'from /atlas/sim_config' if config.recorded else 'assumed (no /atlas/sim_config)'
    model = {True: 'same model file as recorded', False: 'model file DIFFERS from the recording',
             None: 'model checksum not recorded'}[result.model_sha1_matches]
    which = '' if result.tries == 1 else f', try {result.try_number} of {result.tries}'
    lines = [
        f'Replay of {result.bag}{which}',
        f'  reset at {result.start_time_s:.3f} s, torso pinned {config.time_to_unpin_s:g} s '
        f'({source}); {model}',
        f'  replayed {result.reconstructed_steps + result.recorded_steps} steps to '
        f'{result.end_time_s:.3f} s: {result.reconstructed_steps} before the recording '
        f're-created in Stand mode, {result.recorded_steps} with the recorded torques',
        _describe('joint positions', result.joint_position, 'rad'),
        _describe('joint velocities', result.joint_velocity, 'rad/s'),
        _describe('pelvis position', result.pelvis_position, 'm'),
        _describe('pelvis orientation', result.pelvis_orientation, 'rad'),
    ]
    if result.score is not None:
        lines.append(result.score.line())
    if result.scans is not None:
        lines.append(result.scans.line())
    lines += [f'  warning: {text}' for text in result.warnings]
    verdict = 'REPRODUCED' if result.reproduced else 'DEVIATES'
    lines.append(f'{verdict} (tolerance {result.tolerance:g})')
    return '\n'.join(lines)
