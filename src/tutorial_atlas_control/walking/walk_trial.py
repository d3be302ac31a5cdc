"""Offline walking trials: the robot placed standing, Stand for a moment, then a plan of
footsteps walked, then Stand again; what happened, step by step.

The figures the tests and the bench judge: whether it fell (the pelvis less than
sim.fall's STANDING_PELVIS_M above the ground under the feet), how many steps it took, where
each foot came down against its target and where the pelvis was then, the lowest pelvis,
where the pelvis ended, how much the legs' torques jump from one 1 ms tick to the next while
walking (a controller unstable at 1 kHz chatters between the effort limits), and the
controller's CPU per tick.

A trial's `seed` perturbs its start (start_noise: the joints' angles and rates) and, for
pushed walks, draws the pushes' phases and sides: a figure is then a fraction of seeds.
Seed None is today's deterministic run.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import mujoco
import numpy as np

from tutorial_atlas_control.balance import (
    BalanceState,
    Push,
    StandBehaviour,
    apply_pushes,
    push_events,
    standing_simulator,
)
from tutorial_atlas_control.sim import (
    STANDING_PELVIS_M,
    AtlasModel,
    AtlasSimulator,
    GroundUnderFeet,
)
from tutorial_atlas_control.walking.footsteps import (
    STEP_DURATION_S,
    Footstep,
    straight_steps,
    window,
    wrap_angle,
)
from tutorial_atlas_control.walking.leg_tasks import LEG_JOINTS, foot_pose
from tutorial_atlas_control.walking.start_noise import (
    DEFAULT_START_NOISE,
    StartNoise,
    perturb_start,
)
from tutorial_atlas_control.walking.walk import WalkController, WalkGains
from tutorial_atlas_control.walking.walk_behaviour import WalkBehaviour

#: Stand before the walk begins (s).
SETTLE_S = 1.0
#: Walking ticks whose leg torques are kept before their changes are summed.
JUMP_BLOCK_TICKS = 4096


@dataclass(frozen=True)
class Landing:
    """Where a step came down against where it was sent (m, rad)."""

    step_index: int
    foot_index: int
    error_m: float
    yaw_error_rad: float
    #: Where the pelvis was (world x, y, m).
    pelvis_xy: tuple[float, float] = (0.0, 0.0)
    #: How far it came down from the step as Walk took it (after the clamp to the step
    #: limits and any step adjustment: what step_queue_saturated said) (m).
    taken_error_m: float = 0.0
    #: How far ahead of its target it came down, along the target's heading (m; negative:
    #: short of it): a bias here is the swing servo's, not scatter.
    ahead_m: float = 0.0
    #: How far its sole lay off its step's surface as Walk took the next step (rad): a
    #: swing foot lagging in the ankle comes down heel first.
    tilt_rad: float = 0.0


@dataclass
class WalkTrial:
    """What a walking trial did."""

    fell: bool = False
    steps: int = 0
    landings: list[Landing] = field(default_factory=list)
    lowest_pelvis_m: float = math.inf
    pelvis_end: np.ndarray = field(default_factory=lambda: np.zeros(3))
    walk_ended_s: float | None = None
    #: Where the pelvis was when the walk began (world x, y, m).
    pelvis_start_xy: tuple[float, float] = (0.0, 0.0)
    #: The largest, over the leg joints, of a joint's mean |torque change| per 1 ms tick
    #: while walking (N m).
    leg_torque_jump_nm: float = 0.0
    controller_cpu_s: float = 0.0
    control_ticks: int = 0

    @property
    def worst_landing_m(self) -> float:
        return max((landing.error_m for landing in self.landings), default=0.0)

    @property
    def cost_per_step_us(self) -> float:
        return self.controller_cpu_s / max(self.control_ticks, 1) * 1e6

    @property
    def mean_ahead_m(self) -> float:
        """The landings' mean error along their steps (m; + ahead): their bias."""
        return (sum(landing.ahead_m for landing in self.landings)
                / max(len(self.landings), 1))


class WalkingStand:
    """Stand, then the plan walked from `walk_at_s` (WalkBehaviour), then Stand where the
    walk ended; the simulator's Stand behaviour for a trial."""

    def __init__(self, atlas: AtlasModel, plan: Sequence[Footstep], walk_at_s: float,
                 gains: WalkGains | None = None, streaming: bool = False) -> None:
        self.stand = StandBehaviour(atlas)
        self.walking = WalkBehaviour(self.stand, gains)
        self.plan = list(plan)
        #: Sent as a streaming client does: the window from next_step_index_needed, every
        #: step (1 kHz); else the whole plan once.
        self.streaming = streaming
        self.walk_at_s = walk_at_s
        self.trial = WalkTrial()
        self._phase = 'stand'  # then 'walk', then 'stand again'
        #: The legs' walking torques, a block of ticks at a time (row 0: the last of the
        #: block before), and their |changes| summed over the blocks before, with their count.
        self._legs_block = np.empty((JUMP_BLOCK_TICKS + 1, LEG_JOINTS.stop - LEG_JOINTS.start))
        self._legs_rows = 0
        self._jump_sums = np.zeros(self._legs_block.shape[1])
        self._jump_count = 0

    @property
    def walk(self) -> WalkController | None:
        return self.walking.walk

    def start(self, data: mujoco.MjData) -> None:
        self.stand.start(data)

    def torque(self, data: mujoco.MjData) -> np.ndarray:
        started = time.process_time()
        try:
            torque = self._torque(data)
        finally:
            self.trial.controller_cpu_s += time.process_time() - started
            self.trial.control_ticks += 1
        if self._phase == 'walk':
            self._note_jump(torque)  # the trial's own figure: not the controller's cost
        return torque

    def _torque(self, data: mujoco.MjData) -> np.ndarray:
        time_s = float(data.time)
        walking = self.walking
        if self._phase == 'stand' and time_s >= self.walk_at_s:
            walking.next_steps = window(self.plan, 1) if self.streaming else self.plan
            walking.start(data)
            self._phase = 'walk'
            pelvis = data.xpos[self.stand.atlas.pelvis_body_id]
            self.trial.pelvis_start_xy = (float(pelvis[0]), float(pelvis[1]))
        if self._phase != 'walk':
            return self.stand.torque(data)
        walk = walking.walk
        assert walk is not None  # started above
        if walk.done:
            self.trial.walk_ended_s = time_s
            self._phase = 'stand again'
            self.stand.start(data)
            return self.stand.torque(data)
        if self.streaming:
            walking.offer(window(self.plan, walk.queue.next_step_index_needed))
        taken, taking = walk.queue.current_step_index, walk.step
        torque = walking.torque(data)
        if walk.queue.current_step_index > taken:
            state = walking.last_state
            assert state is not None and taking is not None  # set by the torque call
            self._landed(walk, state, taking)
        return torque

    def _note_jump(self, torque: np.ndarray) -> None:
        """Keep this walking step's leg torques (a row a tick: the offline walk's every tick;
        their changes are summed a block at a time)."""
        rows = self._legs_rows
        self._legs_block[rows] = torque[LEG_JOINTS]
        self._legs_rows = rows + 1
        if rows + 1 == len(self._legs_block):
            self._sum_jumps()

    def _sum_jumps(self) -> None:
        """The block's |changes| added to the sums, tick after tick (cumsum's order, from the
        sums so far: what adding each tick's in place gave, bit for bit)."""
        rows = self._legs_rows
        if rows < 2:
            return
        block = self._legs_block[:rows]
        jumps = np.abs(np.diff(block, axis=0))
        self._jump_sums = np.cumsum(np.vstack([self._jump_sums[None], jumps]), axis=0)[-1]
        self._jump_count += rows - 1
        self._legs_block[0] = block[-1]
        self._legs_rows = 1

    def note_jumps(self) -> None:
        """The trial's leg_torque_jump_nm from the changes so far: the largest over the leg
        joints of a joint's summed |changes|, per change."""
        self._sum_jumps()
        if self._jump_count:
            self.trial.leg_torque_jump_nm = float(np.max(self._jump_sums)) / self._jump_count

    def _landed(self, walk: WalkController, state: BalanceState, taken: Footstep) -> None:
        """Note the step just down against its target and against `taken`, the step as
        Walk took it."""
        index = walk.queue.current_step_index
        target = next((s for s in self.plan if s.step_index == index), None)
        if target is None:
            return
        down = foot_pose(state, target.foot_index)
        self.trial.steps = index
        dx, dy = down.x_m - target.x_m, down.y_m - target.y_m
        self.trial.landings.append(Landing(
            index, target.foot_index, math.hypot(dx, dy),
            abs(wrap_angle(down.yaw_rad - target.yaw_rad)),
            (float(state.pelvis_position[0]), float(state.pelvis_position[1])),
            math.hypot(down.x_m - taken.x_m, down.y_m - taken.y_m),
            math.cos(target.yaw_rad) * dx + math.sin(target.yaw_rad) * dy,
            _tilt_rad(state.sole_rotations[target.foot_index], target.normal)))


def _tilt_rad(sole_rotation: np.ndarray, normal: Sequence[float]) -> float:
    """The angle (rad) between a sole's normal and a surface's unit `normal`."""
    cosine = float(sole_rotation[:, 2] @ np.asarray(normal, dtype=float))
    return math.acos(min(max(cosine, -1.0), 1.0))


def walk_trial(plan: Sequence[Footstep], duration_s: float, gains: WalkGains | None = None,
               streaming: bool = False, pushes: Sequence[Push] = (), seed: int | None = None,
               noise: StartNoise = DEFAULT_START_NOISE) -> WalkTrial:
    """Place the robot in the Stand pose (perturbed by `noise` drawn from `seed`; None:
    not), stand SETTLE_S, walk `plan` (sent once, or `streaming` its window every tick),
    stand; with `pushes` on the pelvis (their times in sim time from the start); run for
    `duration_s` (s) of sim time or until it falls."""
    sim = standing_simulator()
    perturb_start(sim.atlas, sim.data, seed, noise)
    behaviour = WalkingStand(sim.atlas, plan, SETTLE_S, gains, streaming)
    sim.install_stand(behaviour)
    return run_walking_stand(sim, behaviour, GroundUnderFeet(sim.atlas, sim.data), duration_s,
                             push_events(pushes, sim.dt_s))


def run_walking_stand(sim: AtlasSimulator, behaviour: WalkingStand, ground: GroundUnderFeet,
                      duration_s: float, events: Sequence[tuple[int, Sequence[float]]] = (),
                      stand_after_s: float | None = None) -> WalkTrial:
    """Step `sim` under its installed `behaviour` for `duration_s` (s) of sim time, pushed
    by `events`, until the robot is no longer standing over `ground` or (`stand_after_s`
    not None) that long after the walk ended; the behaviour's trial, its lowest pelvis
    measured over the ground."""
    trial = behaviour.trial
    data = sim.data
    # Per tick in plain floats (the pelvis's height from a view kept, a level world's ground
    # read once): GroundUnderFeet's clearance and standing test, the same subtraction.
    pelvis_z = data.qpos[sim.atlas.free_qpos_adr + 2:sim.atlas.free_qpos_adr + 3]
    level = ground.ground.level_m
    lowest = trial.lowest_pelvis_m
    for tick in range(round(duration_s / sim.dt_s)):
        if stand_after_s is not None and trial.walk_ended_s is not None \
                and data.time >= trial.walk_ended_s + stand_after_s:
            break
        if events and events[0][0] == tick:
            apply_pushes(sim, events, tick)
        sim.step()
        clearance = pelvis_z.item() - (ground.height_m() if level is None else level)
        lowest = min(lowest, clearance)
        if clearance < STANDING_PELVIS_M:  # fall.standing's test
            trial.fell = True
            break
    trial.lowest_pelvis_m = lowest
    trial.pelvis_end = data.xpos[sim.atlas.pelvis_body_id].copy()
    behaviour.note_jumps()
    return trial


#: The pushes' stream of a seed (its start noise is default_rng(seed) itself).
PUSH_STREAM = 1


def random_pushes(seed: int, start_s: float, end_s: float, force_n: float, push_s: float,
                  every_s: float) -> list[Push]:
    """One sideways pelvis push of `force_n` (N) for `push_s` (s) in each `every_s` (s)
    from `start_s` that ends before `end_s`, at a phase within it and to a side drawn from
    default_rng((seed, PUSH_STREAM))."""
    rng = np.random.default_rng((seed, PUSH_STREAM))
    pushes, t = [], start_s
    while t + every_s <= end_s:
        at = t + float(rng.uniform(0.0, every_s - push_s))
        side = 1.0 if rng.random() < 0.5 else -1.0
        pushes.append(Push(at, (0.0, side * force_n, 0.0), push_s))
        t += every_s
    return pushes


def walk_started_s(gains: WalkGains | None = None) -> float:
    """Sim time (s) at which a trial's first step begins: after SETTLE_S and the sway."""
    return SETTLE_S + (gains or WalkGains()).sway_s


def straight_walk_trial(steps: int, stride_m: float, step_duration_s: float = STEP_DURATION_S,
                        seed: int | None = None, after_s: float = 1.5) -> WalkTrial:
    """`steps` straight steps of `stride_m` (m) at `step_duration_s` (s), sent once, from
    a start perturbed by `seed`, then `after_s` (s) to catch and stand."""
    plan = straight_steps(steps, stride_m, duration_s=step_duration_s)
    return walk_trial(plan, walk_started_s() + steps * step_duration_s + after_s, seed=seed)


def pushed_walk_trial(seed: int | None, steps: int = 20, stride_m: float = 0.25,
                      force_n: float = 150.0, push_s: float = 0.1, every_s: float = 5.0,
                      gains: WalkGains | None = None, after_s: float = 2.5
                      ) -> tuple[WalkTrial, list[Push]]:
    """`steps` straight steps of `stride_m` at STEP_DURATION_S, streamed, pushed by
    random_pushes over the steps (seed None: drawn from seed 0, the start unperturbed),
    then `after_s` (s) to catch and stand; the trial and its pushes."""
    start_s = walk_started_s(gains)
    walk_s = steps * STEP_DURATION_S
    pushes = random_pushes(0 if seed is None else seed, start_s, start_s + walk_s, force_n,
                           push_s, every_s)
    trial = walk_trial(straight_steps(steps, stride_m), start_s + walk_s + after_s, gains,
                       streaming=True, pushes=pushes, seed=seed)
    return trial, pushes
