"""A course walker's streamed walk on a VRC world, offline and scored: how far the walk gets.

The run is the course's as the node runs it (DRCSim's `bdi_stand` start: pinned, released at
1 s, the balancing Stand at 2 s; the AtlasSimInterface; the course's scorer in lockstep),
its start perturbed by a seed (walking/start_noise.py: the joints' angles and rates, the pin
holding the pelvis). Once Stand has held until `walk_at_s`, a streaming client
(asi/walk_client.py) walks the legs (course/legs.py: by default those from the start to
`to_gate`, as vrc_walker.py walks them live) one after another, each leg's steps
(walking/route.py) planned from where the feet are as it begins, as a DRC-era client plans
from `foot_pos_est`: every state is answered with the window of steps from
`next_step_index_needed`. A leg ends when its walk has ended (back in Stand, or
ERROR_FALLING, or refused), the robot has fallen (sim/fall.py, asked every 10 ms), or the
leg's time has run out; the run ends after the last leg or the first that did not end back
in Stand, then it stands `stand_after_s` more. What it returns: the walk's outcome and
steps, the scorer's gate messages with their sim times, completion and falls, the fall if
any, where each leg came closest to a fall (LegFigures), and the CPU the run took. The world
is the qualification's, or one of the finals' variants (course/variants.py: the mud floor's
friction, the mud's damping, the rubble rearranged).
"""

from __future__ import annotations

import math
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from tutorial_atlas_control.asi import (
    AtlasSimInterface,
    Outcome,
    WalkClient,
    walk_command,
    yaw_of_quaternion,
)
from tutorial_atlas_control.course import (
    CLEARANCE_M,
    COURSE_VARIANTS,
    LEG_PAUSE_S,
    SHORTCUT_SLACK_M,
    SOLE_CLEARANCE_M,
    Block,
    CourseVariant,
    Leg,
    ScoreRow,
    course_height_m,
    leg_waypoints,
    legs_ahead,
    point_clearances_m,
    rest_of_leg,
    sole_clearances_m,
)
from tutorial_atlas_control.offline.course_variant import variant_model
from tutorial_atlas_control.offline.laser_terrain import (
    LaserLegFigures,
    LaserTerrain,
    PlanningGround,
    level_footstep,
    seen_prefix,
)
from tutorial_atlas_control.offline.world import named_world
from tutorial_atlas_control.sim import (
    DEFAULT_GAINS_FILE,
    SOLE_GEOMS,
    AtlasSimulator,
    GroundUnderFeet,
    VrcMode,
    load_gains_yaml,
    load_model,
)
from tutorial_atlas_control.stepping import CourseScoring, Tick
from tutorial_atlas_control.units import NS_PER_S
from tutorial_atlas_control.walking import (
    SOLE_HALF_LENGTH_M,
    SOLE_HALF_WIDTH_M,
    Footstep,
    HeightField,
    RouteGait,
    WalkGains,
    centre_line_xy,
    feet_origin,
    perturb_start,
    route_steps,
)

__all__ = ['PLANNING_GROUNDS', 'WALK_OVERHEAD_S', 'CourseWalk', 'LegFigures', 'around_blocks',
           'course_walk', 'leg_plan', 'resumed_leg', 'walk_time_limit_s']

#: The grounds a walker plans on: the world's (offline: MuJoCo's rays on the world) or its
#: head laser's height map (laser_terrain.py).
PLANNING_GROUNDS = ('world', 'laser')

#: A leg planned on the laser's map stops to look again at most this many times.
MAX_LOOKS = 12
#: The fall criterion is asked this often (ticks).
FALL_CHECK_TICKS = 10
#: A route's steps may take this long each, on average, before the run gives up (s).
SECONDS_PER_STEP = 0.9
#: A walk's own time besides its steps (s): the sway onto the first stance foot and the
#: longest catch after the last. Without it a look of four steep steps (0.9 s each) ran out
#: of time while the robot caught itself, and the run stopped at that leg's end, standing.
WALK_OVERHEAD_S = WalkGains().sway_s + WalkGains().longest_catch_s
#: The lowest CoM height (m over the ground) the capture point's LIPM frequency is taken at.
LOWEST_LIPM_HEIGHT_M = 0.3
GRAVITY_M_S2 = 9.81
#: Among the blocks the strides step down by at most this much (m) a step into a corner's
#: turning steps (0.15 -> 0.115 -> 0.08): turned at once from full strides, the stance foot
#: tipped onto its toe as the first turning step began (docs/vrc.md).
CORNER_SLOWDOWN_M = 0.035
#: A sole whose centre is this close (m) to the ground under it carries the robot.
SOLE_ON_GROUND_M = 0.03


@dataclass(frozen=True)
class LegFigures:
    """Where a leg came closest to a fall, from the fall checks' samples (every
    FALL_CHECK_TICKS): the pelvis's lowest height over the ground under the lower sole, and
    the capture point's widest excursion, its horizontal distance (m) from the support's
    spine (the segment between the centres of the soles on the ground, or the one sole's
    centre; the capture point is CoM + velocity / omega of the linear inverted pendulum at
    the CoM's height over the ground; while a foot swings it leads the stance foot towards
    the next step: 0.175 m in the pen's calm 0.1 m strides), each with the pelvis's (x, y)
    then."""

    gate: str
    lowest_pelvis_m: float
    lowest_at: tuple[float, float]
    widest_capture_m: float
    widest_at: tuple[float, float]


@dataclass(frozen=True)
class CourseWalk:
    """How one walk went. `outcome`: the last leg's; `steps_*`: over the legs begun; `gates`:
    the scorer's event messages with their sim times (s); `fell_at_s`: when sim/fall.py's
    criterion first held (None: it never did)."""

    seed: int | None
    outcome: str | None         # WalkClient's Outcome value; None: the time ran out
    legs_walked: int
    steps_planned: int
    steps_taken: int
    gates: tuple[tuple[float, str], ...]
    completion: int
    scorer_falls: int
    fell_at_s: float | None
    pelvis_xy: tuple[float, float]
    sim_s: float
    cpu_s: float
    variant: str = 'qualification'
    legs: tuple[LegFigures, ...] = ()
    #: The scorer's clock: sim time (s) from gate_0 to the last gate passed (0 before gate_0).
    course_clock_s: float = 0.0
    terrain: str = 'world'
    #: Each leg planned on the laser's map: its figures (terrain 'laser').
    laser_legs: tuple[LaserLegFigures, ...] = ()


class _Closest:
    """The leg's LegFigures so far, from samples of the robot's state."""

    def __init__(self, sim: AtlasSimulator, ground: GroundUnderFeet) -> None:
        self.sim, self.ground = sim, ground
        self._soles = [sim.model.geom(name).id for name in SOLE_GEOMS]
        self._last: tuple[float, np.ndarray] | None = None  # (time, CoM) of the last sample
        self.gate = ''
        self.lowest: tuple[float, tuple[float, float]] = (math.inf, (0.0, 0.0))
        self.widest: tuple[float, tuple[float, float]] = (0.0, (0.0, 0.0))

    def start(self, gate: str) -> LegFigures | None:
        """Begin the leg to `gate`; the last leg's figures (None before the first)."""
        last = self.figures() if self.gate else None
        self.gate = gate
        self.lowest, self.widest = (math.inf, (0.0, 0.0)), (0.0, (0.0, 0.0))
        return last

    def figures(self) -> LegFigures:
        return LegFigures(self.gate, round(self.lowest[0], 4), self.lowest[1],
                          round(self.widest[0], 4), self.widest[1])

    def sample(self) -> None:
        data = self.sim.data
        pelvis = data.xpos[self.sim.atlas.pelvis_body_id]
        at = (round(float(pelvis[0]), 3), round(float(pelvis[1]), 3))
        ground_m = self.ground.height_m()
        clearance = self.ground.pelvis_z_m() - ground_m
        if clearance < self.lowest[0]:
            self.lowest = (clearance, at)
        com = data.subtree_com[self.sim.atlas.pelvis_body_id].copy()
        if self._last is not None and data.time > self._last[0]:
            velocity = (com - self._last[1]) / (data.time - self._last[0])
            omega = math.sqrt(GRAVITY_M_S2 / max(float(com[2]) - ground_m, LOWEST_LIPM_HEIGHT_M))
            excursion = _distance_to_segment(com[:2] + velocity[:2] / omega,
                                             *self._support(ground_m))
            if excursion > self.widest[0]:
                self.widest = (excursion, at)
        self._last = (data.time, com)

    def _support(self, ground_m: float) -> tuple[np.ndarray, np.ndarray]:
        """The support's spine: the centres (x, y) of the soles on the ground (within
        SOLE_ON_GROUND_M of the ground under them; both when neither is)."""
        centres = [self.sim.data.geom_xpos[sole] for sole in self._soles]
        down = [c for c in centres
                if c[2] - self.ground.ground.height_m(float(c[0]), float(c[1]))
                < SOLE_ON_GROUND_M] or centres
        return down[0][:2], down[-1][:2]


def _distance_to_segment(point: np.ndarray, start: np.ndarray, end: np.ndarray) -> float:
    """The distance (m) from `point` to the segment start..end (a point when they meet)."""
    along = end - start
    length2 = float(along @ along)
    t = 0.0 if length2 == 0.0 else min(1.0, max(0.0, float((point - start) @ along) / length2))
    return float(np.hypot(*(point - (start + t * along))))


class _Streamer:
    """The client's side of each tick: the newest WALK before the step, the state after."""

    def __init__(self, sim: AtlasSimulator, interface: AtlasSimInterface,
                 laser: LaserTerrain | None = None) -> None:
        self.sim, self.interface, self.laser = sim, interface, laser
        self.client: WalkClient | None = None
        self.pending: list[Footstep] | None = None
        self.ground = GroundUnderFeet(sim.atlas, sim.data)
        self.closest = _Closest(sim, self.ground)
        self.fell_at_s: float | None = None
        self.ticks = 0

    def before_step(self) -> None:
        if self.pending is not None:
            self.interface.apply(walk_command(self.pending))  # the links' poses
            self.pending = None

    def after_step(self) -> None:
        self.ticks += 1
        if self.laser is not None:
            self.laser.after_step()
        if self.client is not None:
            state = self.interface.state()
            steps = self.client.on_state(state.current_behavior,
                                         state.behavior_feedback.status_flags,
                                         state.walk_feedback.current_step_index,
                                         state.walk_feedback.next_step_index_needed)
            if steps:
                self.pending = steps
        if self.ticks % FALL_CHECK_TICKS == 0 and self.fell_at_s is None:
            self.closest.sample()
            if self.ground.fallen():
                self.fell_at_s = self.sim.sim_time_ns / NS_PER_S


def _feet(interface: AtlasSimInterface) -> tuple[tuple[float, float], float]:
    """The foot links' midpoint (x, y) and mean heading, from foot_pos_est."""
    left, right = ((float(foot[0]), float(foot[1]), yaw_of_quaternion(*foot[3:7]))
                   for foot in interface.state().foot_poses)
    return feet_origin(left, right)


def course_walk(seed: int | None, legs: Sequence[Leg] | None = None, to_gate: str = 'gate_1',
                world_name: str = 'vrc_task_2', gait: RouteGait | None = None,
                walk_at_s: float = 3.0, stand_after_s: float = 3.0,
                score_dir: Path | None = None, variant: CourseVariant | None = None,
                terrain: str = 'world') -> CourseWalk:
    """Walk `legs` (None: the course's legs from the start to `to_gate`) on the world
    `world_name` (its start) changed as `variant` says (None: the world as shipped) from its
    start perturbed by `seed` (None: unperturbed), each leg planned on the `terrain` (one of
    PLANNING_GROUNDS); score.log goes to `score_dir` (None: a temporary directory)."""
    if terrain not in PLANNING_GROUNDS:
        raise ValueError(f'terrain {terrain!r} is not one of {", ".join(PLANNING_GROUNDS)}')
    sim = _course_simulator(world_name, variant)
    if legs is None:
        pelvis = sim.data.xpos[sim.atlas.pelvis_body_id]
        legs = legs_ahead(float(pelvis[0]), float(pelvis[1]), to_gate)
    perturb_start(sim.atlas, sim.data, seed, on_ground=False)
    interface = AtlasSimInterface(sim, hold_at_start=True)
    laser = LaserTerrain(sim, seed or 0) if terrain == 'laser' else None
    streamer = _Streamer(sim, interface, laser)
    rows: list[ScoreRow] = []
    laser_legs: list[LaserLegFigures] = []
    figures: list[LegFigures] = []
    started = time.process_time()
    planned = taken = walked = 0
    with tempfile.TemporaryDirectory(prefix='course_walk_') as scratch:
        scoring = CourseScoring(sim, score_dir or Path(scratch), rows.append)
        tick = Tick(sim, streamer, streamer.after_step, interface.end_step, score=scoring)
        _run_until(tick, sim, walk_at_s, streamer)
        for number, leg in enumerate(legs):
            if number > 0:
                _run_until(tick, sim, sim.sim_time_ns / NS_PER_S + LEG_PAUSE_S, streamer)
            if streamer.fell_at_s is not None:
                break
            figures += [done] if (done := streamer.closest.start(leg.gate)) else []
            client, sent, stepped = _walk_leg(tick, sim, interface, streamer, leg, gait,
                                              (variant or COURSE_VARIANTS[0]).blocks, laser_legs)
            planned, taken = planned + sent, taken + stepped
            if client.outcome is not Outcome.WALKED:
                break
            walked += 1
        _run_until(tick, sim, sim.sim_time_ns / NS_PER_S + stand_after_s, streamer)
        scoring.close()
    figures += [streamer.closest.figures()] if streamer.closest.gate else []
    client = streamer.client
    pelvis = sim.data.xpos[sim.atlas.pelvis_body_id]
    last = rows[-1] if rows else None
    return CourseWalk(
        seed=seed, outcome=None if client is None or client.outcome is None
        else client.outcome.value, legs_walked=walked, steps_planned=planned,
        steps_taken=taken,
        gates=tuple((row.sim_time_ns / NS_PER_S, row.message.strip()) for row in rows
                    if row.message),
        completion=0 if last is None else last.completion,
        scorer_falls=0 if last is None else last.falls, fell_at_s=streamer.fell_at_s,
        pelvis_xy=(float(pelvis[0]), float(pelvis[1])), sim_s=sim.sim_time_ns / NS_PER_S,
        cpu_s=time.process_time() - started,
        variant=(variant or COURSE_VARIANTS[0]).name, legs=tuple(figures),
        course_clock_s=0.0 if last is None else last.sim_since_gate0_ns / NS_PER_S,
        terrain=terrain, laser_legs=tuple(laser_legs))


def _course_simulator(world_name: str, variant: CourseVariant | None) -> AtlasSimulator:
    """The world's simulator, DRCSim's `bdi_stand` start, the variant's world and mud."""
    world = named_world(world_name)
    atlas = load_model(world.model_path) if variant is None else variant_model(variant)
    return AtlasSimulator(atlas, load_gains_yaml(DEFAULT_GAINS_FILE),
                          startup_mode=VrcMode.BDI_STAND, start=world.start,
                          mud_damping=world.mud_damping if variant is None
                          else variant.mud_damping)


def leg_plan(leg: Leg, origin: tuple[float, float], heading_rad: float, gait: RouteGait,
             blocks: Sequence[Block], ground: HeightField,
             obstacles: np.ndarray | None = None) -> list[Footstep]:
    """A leg's steps from feet side by side at `origin` facing `heading_rad`: its waypoints
    (around `blocks` and the points of `obstacles` (n, 2) across the rubble, on gentle
    ground over the hills: leg_waypoints), the straight runs fitted to `ground` when the gait
    says so (the offline walker's world, the live one's course description); among the
    blocks as around_blocks turns its corners.

    Raises:
        CourseError: no way around the blocks or over the hills.
        WalkingError: a waypoint the route cannot reach.
    """
    waypoints = leg_waypoints(leg, *origin, blocks, obstacles)
    fitted = ground if gait.fit_ground else None
    if leg.clear_of_blocks:
        return around_blocks(origin, heading_rad, waypoints, gait, blocks, fitted, obstacles)
    return route_steps(origin, heading_rad, waypoints, gait, ground=fitted)


def around_blocks(origin: tuple[float, float], heading_rad: float,
                   waypoints: Sequence[tuple[float, float]], gait: RouteGait,
                   blocks: Sequence[Block], ground: HeightField | None,
                   obstacles: np.ndarray | None) -> list[Footstep]:
    """The way around the blocks with its corners turned in strides, slowing into each
    (an on-the-spot turn after full strides tipped the stance foot onto its toe:
    docs/vrc.md), the first one and any the strides cannot face on the spot, when every
    sole keeps SOLE_CLEARANCE_M from the blocks and obstacles from the first step whose
    centre keeps the way's clearance (before it a walker beside a block steps out); else
    every corner turned on the spot."""
    strides = replace(gait, start_in_place=True, inside_in_place=True,
                      turn_slowdown_m=CORNER_SLOWDOWN_M)
    plan = route_steps(origin, heading_rad, waypoints, strides, ground=ground)
    centres = [centre_line_xy(step, gait.width_m) for step in plan]
    way_m = CLEARANCE_M - SHORTCUT_SLACK_M  # what the way's straight lines keep
    clear = point_clearances_m(np.array(centres), blocks, obstacles) >= way_m
    out = int(np.argmax(clear)) if clear.any() else len(plan)
    nearest = sole_clearances_m([(step.x_m, step.y_m, step.yaw_rad) for step in plan[out:]],
                                blocks, (SOLE_HALF_LENGTH_M, SOLE_HALF_WIDTH_M), obstacles)
    if nearest.min(initial=np.inf) >= SOLE_CLEARANCE_M:
        return plan
    return route_steps(origin, heading_rad, waypoints, gait.turning_in_place(), ground=ground)


def resumed_leg(leg: Leg, gait: RouteGait, began: tuple[float, float],
                here: tuple[float, float]) -> tuple[Leg, RouteGait]:
    """What a walker that began `leg` at `began` and stopped at `here` (to look again) plans
    next: the rest of the leg (rest_of_leg), with `gait` facing the next waypoint from rest
    on the spot, or one inside its turning strides' circle."""
    return (rest_of_leg(leg, began, here),
            replace(gait, start_in_place=True, inside_in_place=True))


def _walk_leg(tick: Tick, sim: AtlasSimulator, interface: AtlasSimInterface,
              streamer: _Streamer, leg: Leg, gait: RouteGait | None,
              blocks: Sequence[Block], laser_legs: list[LaserLegFigures]
              ) -> tuple[WalkClient, int, int]:
    """One leg planned from where the feet are now (around `blocks` across the rubble) on
    the world's ground or the laser's map (its figures appended to `laser_legs`), streamed
    until it ends, the robot falls or a walk's time (walk_time_limit_s) runs out. On the
    map, only as far as it has seen (seen_prefix): there the robot stands LEG_PAUSE_S,
    looking, and the rest is planned again. Returns the last walk's client and the steps
    sent and taken over the leg."""
    gait = gait or RouteGait()
    sent = taken = 0
    began, _ = _feet(interface)
    for look in range(MAX_LOOKS):
        if look:  # stand and look at what the last part walked towards
            _run_until(tick, sim, sim.sim_time_ns / NS_PER_S + LEG_PAUSE_S, streamer)
        origin, heading = _feet(interface)
        rest, gait = resumed_leg(leg, gait, began, origin) if look else (leg, gait)
        if streamer.laser is None:
            plan = leg_plan(rest, origin, heading, gait, blocks, streamer.ground.ground.height_m)
            walked = len(plan)
        else:
            ground = PlanningGround(streamer.laser.map)
            plan = leg_plan(rest, origin, heading, gait, (), ground,
                            streamer.laser.map.grid.obstacle_xy())
            laser_legs.append(streamer.laser.leg_figures(
                leg.gate, plan, leg_plan(rest, origin, heading, gait, blocks, course_height_m),
                ground))
            walked = seen_prefix(plan, streamer.laser.map, level_footstep(ground))
        client = streamer.client = WalkClient(plan[:walked], streaming=True)
        limit_ns = sim.sim_time_ns + math.floor(walk_time_limit_s(walked) * NS_PER_S)
        while client.outcome is None and streamer.fell_at_s is None \
                and sim.sim_time_ns < limit_ns:
            tick()
        sent, taken = sent + walked, taken + client.steps_taken
        if walked == len(plan) or client.outcome is not Outcome.WALKED:
            break
    return client, sent, taken


def walk_time_limit_s(steps: int) -> float:
    """How long (s of sim time) a walk of `steps` steps may take before the run gives up
    on it: SECONDS_PER_STEP a step and the walk's sway and catch (WALK_OVERHEAD_S)."""
    return steps * SECONDS_PER_STEP + WALK_OVERHEAD_S


def _run_until(tick: Tick, sim: AtlasSimulator, until_s: float, streamer: _Streamer) -> None:
    """Tick until sim time `until_s` or a fall."""
    until_ns = math.floor(until_s * NS_PER_S)
    while sim.sim_time_ns < until_ns and streamer.fell_at_s is None:
        tick()
