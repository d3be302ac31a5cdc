"""Offline Stand trials on a slope: the whole-body solvers compared where the ground tilts.

The world is Atlas's own (sim/atlas_v1.xml) with its floor plane turned about the world's
y axis through the origin, rising along +x by the slope; the robot faces up it. It is
placed upright in DRCSim's Stand pose with the ankles pitched by the slope, so that the
soles lie on the incline, lowered until the lowest sole corner touches the ground
(sim/ground.py's rays); a start perturbation (a seed's noise) is applied before that. Then
the balancing Stand runs as the simulator's Stand behaviour, as in push_trial, and the
trial says whether the robot still stood (sim/fall.py's `standing`, from the ground under
the feet), how far the soles moved, and how near the edge of its sole each foot's pressure
centre came: MuJoCo's contact forces on each sole, their centre of pressure in the sole's
frame, its least distance to the sole's edge.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from tutorial_atlas_control.balance.push_trial import Push, TimedStand, apply_pushes, push_events
from tutorial_atlas_control.balance.sole import SoleBox, sole_corners, sole_geom_ids
from tutorial_atlas_control.balance.stand import StandGains
from tutorial_atlas_control.balance.stand_pose import place_in_stand_pose
from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.sim import (
    DEFAULT_GAINS_FILE,
    MODEL_PATH,
    SOLE_GEOMS,
    STAND_POSE_RAD,
    AtlasModel,
    AtlasSimulator,
    Ground,
    GroundUnderFeet,
    index_model,
    load_gains_yaml,
    standing,
)

__all__ = ['SLOPE_TRIAL_S', 'SlopeResult', 'place_on_slope', 'slope_model',
           'slope_stand_trial', 'sole_cop_margins']

#: How long a slope trial stands (s).
SLOPE_TRIAL_S = 10.0
#: The pressure centres are sampled every this many ticks, from this time on (s: after
#: Stand's start has brought the robot to its pose).
COP_EVERY_TICKS = 10
COP_FROM_S = 1.5
_ANKLE_PITCH = [JOINT_NAMES.index(name) for name in ('l_leg_uay', 'r_leg_uay')]

#: A start perturbation: called on the placed robot before it is lowered onto the slope.
Perturb = Callable[[AtlasModel, mujoco.MjData], None]


def slope_model(slope_rad: float) -> AtlasModel:
    """Atlas's world with its floor rising along +x by `slope_rad` (through the origin)."""
    spec = mujoco.MjSpec.from_file(str(MODEL_PATH))
    half = -0.5 * slope_rad  # a turn about y by -slope tilts the normal towards -x
    spec.geom('floor').quat = [math.cos(half), 0.0, math.sin(half), 0.0]
    return index_model(spec.compile(), MODEL_PATH)


def place_on_slope(atlas: AtlasModel, data: mujoco.MjData, slope_rad: float, ground: Ground,
                   perturb: Perturb | None = None) -> None:
    """The robot upright in the Stand pose facing +x, its ankles pitched toe up by
    `slope_rad`, perturbed by `perturb`, then lowered until its lowest sole corner touches
    `ground`; at rest but for the perturbation's rates."""
    angles = STAND_POSE_RAD.copy()
    angles[_ANKLE_PITCH] -= slope_rad
    place_in_stand_pose(atlas, data, angles)
    if perturb is not None:
        perturb(atlas, data)
    mujoco.mj_kinematics(atlas.model, data)
    corners = np.concatenate([sole_corners(atlas.model, data, name) for name in SOLE_GEOMS])
    heights, _ = ground.hits(corners[:, :2])
    data.qpos[atlas.free_qpos_adr + 2] -= float(np.min(corners[:, 2] - heights))
    mujoco.mj_forward(atlas.model, data)


def sole_cop_margins(model: mujoco.MjModel, data: mujoco.MjData,
                     soles: list[int], sole: SoleBox) -> list[float]:
    """Each sole's pressure centre's distance (m) inside its bottom face's nearest edge, from
    the contact forces MuJoCo applied (NaN for a sole that carries nothing)."""
    force = np.zeros(6)
    margins = []
    for geom in soles:
        pressing, moment = 0.0, np.zeros(3)
        for index in range(data.ncon):
            contact = data.contact[index]
            if geom not in (contact.geom1, contact.geom2):
                continue
            mujoco.mj_contactForce(model, data, index, force)
            pressing += force[0]
            moment += force[0] * contact.pos
        if pressing <= 0.0:
            margins.append(math.nan)
            continue
        rotation = data.geom_xmat[geom].reshape(3, 3)
        local = rotation.T @ (moment / pressing - data.geom_xpos[geom])
        margins.append(min(sole.half_length_m - abs(float(local[0])),
                           sole.half_width_m - abs(float(local[1]))))
    return margins


@dataclass(frozen=True)
class SlopeResult:
    """What became of the robot on a slope: `stood` = still standing after the trial
    (sim/fall.py's `standing`, from the ground under the feet) with neither sole moved
    more than `travel_limit_m`; the soles' largest displacement (m, 3-D); the least pressure
    centre margin on either sole (m) from COP_FROM_S on; the controller's and a bare
    mj_step's process time per tick (us) in the same process."""

    stood: bool
    lowest_pelvis_m: float
    sole_travel_m: float
    cop_margin_m: float
    steps: int
    controller_us: float
    mj_step_us: float
    qp_fallbacks: int


def _bare_step_us(atlas: AtlasModel, data: mujoco.MjData, steps: int = 500) -> float:
    """A bare mj_step's process time (us) on a copy of `data`, timed here."""
    scratch = mujoco.MjData(atlas.model)
    mujoco.mj_copyData(scratch, atlas.model, data)
    started = time.process_time()
    for _ in range(steps):
        mujoco.mj_step(atlas.model, scratch)
    return (time.process_time() - started) / steps * 1e6


def slope_stand_trial(slope_rad: float, gains: StandGains | None = None,
                      duration_s: float = SLOPE_TRIAL_S, perturb: Perturb | None = None,
                      pushes: Sequence[Push] = (), travel_limit_m: float = 0.02) -> SlopeResult:
    """Stand for `duration_s` on a slope of `slope_rad`, started as place_on_slope puts the
    robot (with `perturb`), pushed by `pushes` (push_trial's pelvis pushes); stops early
    once it no longer stands."""
    atlas = slope_model(slope_rad)
    sim = AtlasSimulator(atlas, load_gains_yaml(DEFAULT_GAINS_FILE), time_to_unpin_s=0.0)
    ground = GroundUnderFeet(sim.atlas, sim.data)
    place_on_slope(sim.atlas, sim.data, slope_rad, ground.ground, perturb)
    stand = TimedStand(sim.atlas, gains)
    sim.install_stand(stand)
    soles, box = sole_geom_ids(sim.atlas.model), SoleBox.of(sim.atlas.model)
    feet_start = sim.data.geom_xpos[soles].copy()
    lowest, travel, margin = math.inf, 0.0, math.inf
    steps = round(duration_s / sim.dt_s)
    events = push_events(pushes, sim.dt_s)
    done = 0
    for done in range(1, steps + 1):
        apply_pushes(sim, events, done - 1)
        sim.step()
        lowest = min(lowest, ground.clearance_m())
        travel = max(travel, float(np.max(np.linalg.norm(
            sim.data.geom_xpos[soles] - feet_start, axis=1))))
        if done % COP_EVERY_TICKS == 0 and sim.data.time >= COP_FROM_S:
            margin = min([margin] + [m for m in sole_cop_margins(
                sim.atlas.model, sim.data, soles, box) if not math.isnan(m)])
        if not standing(lowest):
            break
    assert stand.controller is not None
    return SlopeResult(standing(lowest) and travel <= travel_limit_m, lowest, travel, margin,
                       done, stand.spent_s / done * 1e6, _bare_step_us(sim.atlas, sim.data),
                       stand.controller.layer.qp_fallbacks)
