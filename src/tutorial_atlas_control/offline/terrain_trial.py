"""Offline walks on terrain other than the flat floor: the course's cases, one at a time.

Each case is Atlas's own world changed in one way, the robot placed standing in it facing
+x, Stand for a moment, then a straight walk (walking/walk_trial.py's WalkingStand, the
plan sent once) with every step placed on the ground under it as the AtlasSimInterface
places a client's steps (asi/library.py's on_ground: the surface's height and normal):

- mud (DRCSim's MudPlugin, sim/mud.py): the floor flat, a `mud_atlas` volume over the walk
  whose top is MUD_DEPTH_M above the floor (the VRC pit's mud stood 0.46 m over its floor:
  the feet and lower legs in it), its damping DRCSim's 40 N s/m or the finals' 70;
- slopes (balance/slope_trial.py's world): the floor turned to rise (or fall) along +x by the
  slope, the robot placed on it with its ankles pitched to lie on it;
- ramps (the VRC mud pit's: about 0.6 m of height over 1.5 m, 22 degrees): the floor flat,
  a ramp RAMP_START_M ahead rising RAMP_RUN_M later to a platform (up), or the robot on a
  platform and the ramp falling from it to the floor (down): flat, a bend, the slope, a
  bend, flat. Their steps are planned on the ground as a footstep planner would
  (walking/ground_strides.py: no sole across a bend, 0.1 m strides of 0.9 s on the ramp)
  over the case's `run_m`; in the slopes' 0.2 m strides, each placed where it fell, every
  ramp walk fell (docs/vrc.md).

A case's seed perturbs the start (walking/start_noise.py) and, for a pushed walk, draws the
pushes' phases and sides, so a figure is a fraction of seeds (the start's noise alone is
forgotten in the second of Stand before the walk where the walk is stable: eight seeds of
the 10 m through the mud ended within a millimetre of each other). What a walk returns is
walk_trial's WalkTrial (fell, steps, landings; its lowest pelvis over the ground under the
feet).
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass, replace
from pathlib import Path

import mujoco

from tutorial_atlas_control.asi import on_ground
from tutorial_atlas_control.balance import (
    place_in_stand_pose,
    place_on_slope,
    push_events,
    slope_model,
)
from tutorial_atlas_control.course import MUD_DAMPING, MUD_DAMPING_FINALS
from tutorial_atlas_control.sim import (
    DEFAULT_GAINS_FILE,
    MODEL_PATH,
    AtlasModel,
    AtlasSimulator,
    Ground,
    GroundUnderFeet,
    index_model,
    load_gains_yaml,
    load_model,
)
from tutorial_atlas_control.walking import (
    SETTLE_S,
    Footstep,
    GroundGait,
    WalkingError,
    WalkingStand,
    WalkTrial,
    ground_steps,
    perturb_start,
    random_pushes,
    run_walking_stand,
    straight_steps,
)

__all__ = ['MUD_DEPTH_M', 'RAMP_RISE_M', 'TERRAINS', 'Terrain', 'mud_model', 'planned_steps',
           'ramp_model', 'stairs_model', 'terrain_plan', 'terrain_walk']

#: The mud's top over the floor (m): the VRC pit's 0.46 m.
MUD_DEPTH_M = 0.46
#: The mud volume's extent along the walk (m of x, from the start) and across it (m of y).
MUD_LENGTH_M = 14.0
MUD_WIDTH_M = 3.0
#: The pit's ramps: their height (m) over their horizontal run (m), beginning this far
#: (m of x) ahead of the start; the ramps and platforms are this wide (m of y) and the
#: platforms this long (m of x).
RAMP_RISE_M = 0.6
RAMP_RUN_M = 1.5
RAMP_START_M = 0.6
RAMP_WIDTH_M = 3.0
PLATFORM_M = 4.0
#: A ramp case's walk (m): over the ramp and 1.5 m on beyond it.
RAMP_WALK_M = 3.6
#: Stairs (the issue's 0.15 m risers): this many steps, each this deep (m): a tread holds a
#: sole (0.26 m) and the planner's margins (4 cm each end) with 6 cm to spare.
STAIR_RISE_M = 0.15
STAIR_COUNT = 4
STAIR_TREAD_M = 0.4
#: A stairs case's walk (m): over the stairs and 0.6 m on beyond them.
STAIRS_WALK_M = RAMP_START_M + STAIR_COUNT * STAIR_TREAD_M + 0.6
#: After the walk has ended, the robot stands this long (s).
STAND_AFTER_S = 1.5
#: A push lasts PUSH_S (s), one in every PUSH_EVERY_S (s) of the walk.
PUSH_S = 0.1
PUSH_EVERY_S = 5.0
#: A walk may take this many times its steps' durations (the mud slows the swings) before
#: the trial ends without it.
SLOWEST_WALK = 2.0


@dataclass(frozen=True)
class Terrain:
    """One case: the floor's slope along +x (rad; negative falls), or a ramp's rise (m;
    negative: down from a platform; ramp_model), the mud's damping (N s/m; None: no mud),
    and the walk: `steps` steps of `stride_m`."""

    name: str
    slope_rad: float = 0.0
    ramp_rise_m: float = 0.0
    mud_damping: float | None = None
    steps: int = 16
    stride_m: float = 0.25
    #: When positive: the walk is this long (m), its steps planned on the ground
    #: (ground_steps, strides of at most `stride_m`), not `steps` of `stride_m`.
    run_m: float = 0.0
    #: Stairs (m, each riser; negative: down from a landing; stairs_model): STAIR_COUNT
    #: steps of STAIR_TREAD_M from RAMP_START_M ahead.
    stair_rise_m: float = 0.0
    #: How much steeper along +x than the ground the steps' surfaces are planned (rad;
    #: negative: shallower): a height map's plane a few degrees off the ground's, as the
    #: course's footprint planes were on its hills.
    surface_error_rad: float = 0.0


#: The cases by name: 10 m through the mud at DRCSim's and the finals' damping, in strides
#: of 0.15 m (at 0.25 m 7 of 8 seeds fell at 40 N s/m: docs/vrc.md); 4 m up and down slopes
#: of 8 and 16 degrees; 3.6 m up and down the pit's ramps.
TERRAINS: dict[str, Terrain] = {case.name: case for case in (
    Terrain('mud_40', mud_damping=MUD_DAMPING, steps=67, stride_m=0.15),
    Terrain('mud_70', mud_damping=MUD_DAMPING_FINALS, steps=67, stride_m=0.15),
    Terrain('up_8deg', slope_rad=math.radians(8.0), steps=20, stride_m=0.2),
    Terrain('down_8deg', slope_rad=-math.radians(8.0), steps=20, stride_m=0.2),
    Terrain('up_16deg', slope_rad=math.radians(16.0), steps=20, stride_m=0.2),
    Terrain('down_16deg', slope_rad=-math.radians(16.0), steps=20, stride_m=0.2),
    Terrain('ramp_up_22deg', ramp_rise_m=RAMP_RISE_M, stride_m=0.2, run_m=RAMP_WALK_M),
    Terrain('ramp_down_22deg', ramp_rise_m=-RAMP_RISE_M, stride_m=0.2, run_m=RAMP_WALK_M),
    Terrain('stairs_up_15cm', stair_rise_m=STAIR_RISE_M, stride_m=0.2, run_m=STAIRS_WALK_M),
    Terrain('stairs_down_15cm', stair_rise_m=-STAIR_RISE_M, stride_m=0.2, run_m=STAIRS_WALK_M),
)}


def mud_model(scratch: Path) -> AtlasModel:
    """Atlas's world with a mud volume over the walk, written where sim/mud.py can compile
    its private copy from the same file."""
    spec = mujoco.MjSpec.from_file(str(MODEL_PATH))
    half_height = (MUD_DEPTH_M + 0.05) / 2  # from 5 cm under the floor
    spec.worldbody.add_geom(
        name='mud_atlas', type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[MUD_LENGTH_M / 2, MUD_WIDTH_M / 2, half_height],
        pos=[MUD_LENGTH_M / 2 - 1.0, 0.0, MUD_DEPTH_M - half_height], contype=0,
        conaffinity=0, rgba=[0.4, 0.3, 0.2, 0.4])
    path = scratch / 'atlas_v1_mud.xml'
    path.write_text(spec.to_xml())
    return load_model(path)


def _box(spec: mujoco.MjSpec, name: str, centre: tuple[float, float, float],
         half_size: tuple[float, float, float], pitch_rad: float = 0.0) -> None:
    """A box of the floor's material and contact, welded to the world, turned about y."""
    floor = spec.geom('floor')
    half = -0.5 * pitch_rad
    spec.worldbody.add_geom(
        name=name, type=mujoco.mjtGeom.mjGEOM_BOX, size=list(half_size), pos=list(centre),
        quat=[math.cos(half), 0.0, math.sin(half), 0.0], material=floor.material,
        condim=floor.condim, contype=floor.contype, conaffinity=floor.conaffinity,
        friction=list(floor.friction), solref=list(floor.solref), solimp=list(floor.solimp))


def ramp_model(rise_m: float) -> AtlasModel:
    """Atlas's world with a ramp over RAMP_RUN_M from RAMP_START_M ahead: rising `rise_m`
    (m) from the floor to a platform, or (negative) falling from a platform under the start
    to the floor."""
    spec = mujoco.MjSpec.from_file(str(MODEL_PATH))
    height = abs(rise_m)
    top_m = RAMP_START_M + RAMP_RUN_M if rise_m > 0.0 else -PLATFORM_M
    end_m = top_m + PLATFORM_M if rise_m > 0.0 else RAMP_START_M
    width = 0.5 * RAMP_WIDTH_M
    _box(spec, 'platform', (0.5 * (top_m + end_m), 0.0, 0.5 * height),
         (0.5 * (end_m - top_m), width, 0.5 * height))
    slope = math.atan2(rise_m, RAMP_RUN_M)
    thickness = 0.1  # its top face the ramp, its body in the floor and the platform
    middle = (RAMP_START_M + 0.5 * RAMP_RUN_M, 0.5 * height)
    _box(spec, 'ramp', (middle[0] + math.sin(slope) * thickness, 0.0,
                        middle[1] - math.cos(slope) * thickness),
         (0.5 * math.hypot(RAMP_RUN_M, rise_m), width, thickness), slope)
    return index_model(spec.compile(), MODEL_PATH)


def stairs_model(rise_m: float) -> AtlasModel:
    """Atlas's world with STAIR_COUNT stairs from RAMP_START_M ahead, each riser `rise_m`
    (m) up to a landing, or (negative) down from a landing under the start to the floor:
    boxes stacked, each reaching from its riser to the far end of its side."""
    spec = mujoco.MjSpec.from_file(str(MODEL_PATH))
    width = 0.5 * RAMP_WIDTH_M
    last_m = RAMP_START_M + STAIR_COUNT * STAIR_TREAD_M
    for level in range(1, STAIR_COUNT + 1):
        if rise_m > 0.0:
            start_m, end_m = RAMP_START_M + (level - 1) * STAIR_TREAD_M, last_m + PLATFORM_M
        else:
            start_m, end_m = -PLATFORM_M, RAMP_START_M + (STAIR_COUNT - level) * STAIR_TREAD_M
        top_m = level * abs(rise_m)
        _box(spec, f'stair_{level}', (0.5 * (start_m + end_m), 0.0, 0.5 * top_m),
             (0.5 * (end_m - start_m), width, 0.5 * top_m))
    return index_model(spec.compile(), MODEL_PATH)


def _terrain_model(terrain: Terrain) -> AtlasModel:
    """The case's world without mud: a ramp, stairs, or the floor turned by the slope."""
    if terrain.ramp_rise_m != 0.0:
        return ramp_model(terrain.ramp_rise_m)
    if terrain.stair_rise_m != 0.0:
        return stairs_model(terrain.stair_rise_m)
    return slope_model(terrain.slope_rad)


def terrain_walk(terrain: Terrain, seed: int | None, push_n: float = 0.0) -> WalkTrial:
    """Walk `terrain`'s case once from a start perturbed by `seed` (None: not), pushed on
    the pelvis by `push_n` (N; 0: not) as pushed flat walks are (walk_trial.random_pushes:
    0.1 s to a side drawn from the seed, once in every PUSH_EVERY_S of the walk)."""
    shaped = terrain.slope_rad != 0.0 or terrain.ramp_rise_m != 0.0 \
        or terrain.stair_rise_m != 0.0
    if shaped and terrain.mud_damping is not None:
        raise WalkingError(f'terrain {terrain.name}: mud on a slope is not a case')
    gains = load_gains_yaml(DEFAULT_GAINS_FILE)
    with tempfile.TemporaryDirectory(prefix='terrain_walk_') as scratch:
        if terrain.mud_damping is None:
            sim = AtlasSimulator(_terrain_model(terrain), gains, time_to_unpin_s=0.0)
        else:
            sim = AtlasSimulator(mud_model(Path(scratch)), gains, time_to_unpin_s=0.0,
                                 mud_damping=terrain.mud_damping)
        ground = GroundUnderFeet(sim.atlas, sim.data)
        if not shaped:
            place_in_stand_pose(sim.atlas, sim.data)
            perturb_start(sim.atlas, sim.data, seed)
        else:
            place_on_slope(sim.atlas, sim.data, terrain.slope_rad, ground.ground,
                           lambda atlas, data: perturb_start(atlas, data, seed,
                                                             on_ground=False))
        plan = terrain_plan(terrain, ground.ground)
        behaviour = WalkingStand(sim.atlas, plan, SETTLE_S)
        sim.install_stand(behaviour)
        walk_s = sum(step.duration_s for step in plan)
        events = push_events(random_pushes(0 if seed is None else seed, SETTLE_S,
                                           SETTLE_S + walk_s, push_n, PUSH_S, PUSH_EVERY_S)
                             if push_n > 0.0 else [], sim.dt_s)
        return run_walking_stand(sim, behaviour, ground,
                                 SETTLE_S + SLOWEST_WALK * walk_s + STAND_AFTER_S, events,
                                 stand_after_s=STAND_AFTER_S)


def terrain_plan(terrain: Terrain, ground: Ground) -> list[Footstep]:
    """The case's steps from feet side by side at the origin facing +x, put on `ground` as
    the interface puts a client's (on_ground): `steps` straight strides, or (`run_m`) the
    run planned on the ground's heights."""
    if terrain.run_m > 0.0:
        steps = ground_steps(terrain.run_m, ground.height_m,
                             GroundGait(stride_m=terrain.stride_m))
    else:
        steps = straight_steps(terrain.steps, terrain.stride_m)
    placed = on_ground(steps, ground)
    if terrain.surface_error_rad == 0.0:
        return placed
    return [replace(step, normal=_pitched(step.normal, terrain.surface_error_rad))
            for step in placed]


def _pitched(normal: tuple[float, float, float],
             steeper_rad: float) -> tuple[float, float, float]:
    """`normal` turned about y so that its surface rises `steeper_rad` more along +x."""
    x, y, z = normal
    cos, sin = math.cos(steeper_rad), math.sin(steeper_rad)
    return (cos * x - sin * z, y, sin * x + cos * z)


def planned_steps(terrain: Terrain) -> int:
    """How many steps the case's walk has (a planned run's: on its world's ground)."""
    if terrain.run_m <= 0.0:
        return terrain.steps
    atlas = _terrain_model(terrain)
    data = mujoco.MjData(atlas.model)
    mujoco.mj_forward(atlas.model, data)
    return len(terrain_plan(terrain, Ground(atlas.model, data)))
