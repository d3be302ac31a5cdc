"""Static steps onto, across and off a cinder block, offline, as a DRC-era client takes them.

The world is Atlas's own (sim/atlas_v1.xml) with one loose VRC cinder block on its floor
(course/vrc_task_2.py's: 5 kg, hollow, five walls in a 0.435 x 0.203 x 0.203 m envelope,
mu 1 as ODE took it against the feet's 1.5), its long side across the robot's path, 7 cm
ahead of the toes, lying flat (its holes upright: the soles land on its walls' 0.034 m
rims) or on its side (its holes level: one solid long wall on top); either way its top is
0.203 m up. The robot stands in DRCSim's Stand pose at the origin facing +x, its start
perturbed by a seed (walking/start_noise.py), and the balancing Stand holds it for
STAND_FIRST_S. Then a client streams STEP through the AtlasSimInterface, as the walking
tutorial's did: its next target at every state, the next one once it sees SWAYING after
STEPPING. The targets say x, y and yaw; the interface places each on the world's surface
under it (asi/library.py's on_ground), and Step on the highest ground under the sole's
footprint (the block's top, or the floor), as a client's z is the foot link's or none.

The plans (block_plan): 'back', the left foot onto the block and back down where it stood;
'across', left then right onto the block, then left then right down its far side (today
the robot falls as the right foot lifts from the floor: docs/vrc.md). What the trial
reports: whether the robot still stands (sim/fall.py's `standing`, over the ground under the
lower sole, every 10 ms) and took every step, each sole's pose against its goal (x, y, z of
the bottom face's centre, yaw) once its step is over, and how far the block moved.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field

import mujoco
import numpy as np

from tutorial_atlas_control.asi import AtlasSimInterface, Behavior, step_data_of
from tutorial_atlas_control.balance import place_in_stand_pose, sole_geom_ids
from tutorial_atlas_control.course import (
    BLOCK_ENVELOPE_M,
    BLOCK_INERTIA,
    BLOCK_MASS_KG,
    BLOCK_WALLS,
)
from tutorial_atlas_control.msgs import AsiCommand, ManipulateParams, StepData
from tutorial_atlas_control.sim import (
    DEFAULT_GAINS_FILE,
    MODEL_PATH,
    AtlasModel,
    AtlasSimulator,
    GroundUnderFeet,
    index_model,
    load_gains_yaml,
    standing,
)
from tutorial_atlas_control.walking import (
    STEP_DURATION_S,
    STEPPING,
    SWAYING,
    Footstep,
    perturb_start,
    wrap_angle,
)

__all__ = ['BLOCK_NAME', 'PLANS', 'BlockRun', 'BlockStep', 'CinderBlock', 'block_model',
           'block_plan', 'block_step_trial']

#: The block's body in the trial's world.
BLOCK_NAME = 'cinder_block'
#: Stand before the first STEP (s), the longest one step may take (s), the fall check's
#: period (ticks).
STAND_FIRST_S = 1.0
LONGEST_STEP_S = 8.0
FALL_CHECK_TICKS = 10
#: The contact the world's floor has (sim/atlas_v1.xml): the block's walls get the same,
#: and mu 1 (ODE's min of the feet's 1.5 and the block's unset 1).
_FRICTION = (1.0, 0.02, 0.0001)
_SOLREF = (0.005, 1.0)
_SOLIMP = (0.95, 0.99, 0.001, 0.5, 2.0)
#: The feet's centres across (m): the Stand pose's.
_HALF_WIDTH_M = 0.12
#: The block starts this far (m) above the floor and settles while the robot stands.
_DROP_M = 0.001


@dataclass(frozen=True)
class CinderBlock:
    """Where the block lies: its centre's x (m, ahead of the robot's start: by default its
    near edge 7 cm ahead of the Stand pose's toes, its middle a 0.3 m step ahead) and y,
    its long side across the path; `on_side`: on a long side (holes level), not flat."""

    x_m: float = 0.32
    y_m: float = 0.0
    on_side: bool = False

    @property
    def top_m(self) -> float:
        """Its top's height (m): the envelope's 0.203 m either way."""
        return BLOCK_ENVELOPE_M[2]

    @property
    def depth_m(self) -> float:
        """Its extent along the path (m)."""
        return BLOCK_ENVELOPE_M[1]


def block_model(block: CinderBlock) -> AtlasModel:
    """Atlas's world with `block` lying on its floor, loose (a free joint)."""
    spec = mujoco.MjSpec.from_file(str(MODEL_PATH))
    # Its long axis (its frame's x) along the world's y; on its side, rolled a quarter turn
    # about that axis. Its frame is at the envelope's bottom centre: placed so that the
    # envelope's centre is over (x, y), its lowest face on the floor.
    roll = 0.5 * math.pi if block.on_side else 0.0
    rotation = _rotation_z(0.5 * math.pi) @ _rotation_x(roll)
    centre = np.array([0.0, 0.0, 0.5 * BLOCK_ENVELOPE_M[2]])
    position = np.array([block.x_m, block.y_m, centre[2] + _DROP_M]) - rotation @ centre
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, rotation.reshape(-1))
    body = spec.worldbody.add_body(name=BLOCK_NAME, pos=position.tolist(), quat=quat.tolist())
    body.add_freejoint(name=f'{BLOCK_NAME}_free')
    body.mass = BLOCK_MASS_KG
    body.ipos = centre.tolist()
    body.inertia = list(BLOCK_INERTIA)
    body.explicitinertial = True
    for index, wall in enumerate(BLOCK_WALLS):
        body.add_geom(name=f'{BLOCK_NAME}_{index}', type=mujoco.mjtGeom.mjGEOM_BOX,
                      size=[s / 2 for s in wall.size_m], pos=list(wall.centre_m),
                      contype=1, conaffinity=1, condim=6, friction=list(_FRICTION),
                      solref=list(_SOLREF), solimp=list(_SOLIMP), rgba=[0.6, 0.6, 0.6, 1])
    return index_model(spec.compile(), MODEL_PATH)


def _rotation_x(angle_rad: float) -> np.ndarray:
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _rotation_z(angle_rad: float) -> np.ndarray:
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


#: The trial's plans (block_plan).
PLANS = ('back', 'across')


def block_plan(block: CinderBlock, feet: np.ndarray, plan: str = 'back',
               gap_m: float = 0.06, half_length_m: float = 0.13) -> list[Footstep]:
    """The sole steps (their centres, facing +x), z each surface's: 'back', the left foot
    onto the block's middle (along the path) and back where it started (`feet`: (2, 2), the
    soles' centres); 'across', left then right onto the block, then left then right down
    `gap_m` beyond its far edge."""
    if plan not in PLANS:
        raise ValueError(f'block plan {plan!r} is not one of {PLANS}')
    top, on_block = block.top_m, block.x_m
    if plan == 'back':
        left = (float(feet[0][0]), float(feet[0][1]))
        return [Footstep(1, 0, on_block, block.y_m + _HALF_WIDTH_M, 0.0, STEP_DURATION_S,
                         z_m=top),
                Footstep(2, 0, left[0], left[1], 0.0, STEP_DURATION_S)]
    beyond = block.x_m + 0.5 * block.depth_m + half_length_m + gap_m
    steps = []
    for index, (foot, x, z) in enumerate(((0, on_block, top), (1, on_block, top),
                                          (0, beyond, 0.0), (1, beyond, 0.0)), start=1):
        y = block.y_m + (_HALF_WIDTH_M if foot == 0 else -_HALF_WIDTH_M)
        steps.append(Footstep(index, foot, x, y, 0.0, STEP_DURATION_S, z_m=z))
    return steps


@dataclass(frozen=True)
class BlockStep:
    """One step: its goal, where the sole's bottom face lies once the step is over (x, y, z
    m, yaw rad: landed and settled, the weight back between the feet), and the landing's
    errors (m: across the ground, height; rad)."""

    goal: Footstep
    landed: tuple[float, float, float, float]

    @property
    def horizontal_error_m(self) -> float:
        return math.hypot(self.landed[0] - self.goal.x_m, self.landed[1] - self.goal.y_m)

    @property
    def height_error_m(self) -> float:
        return abs(self.landed[2] - self.goal.z_m)

    @property
    def yaw_error_rad(self) -> float:
        return abs(wrap_angle(self.landed[3] - self.goal.yaw_rad))


@dataclass
class BlockRun:
    """A trial's outcome: `stood` (standing throughout, sampled every FALL_CHECK_TICKS, and
    all the steps taken), the steps as landed, the pelvis's lowest clearance above the
    ground under the lower sole (m), how far the block's centre moved (m) and turned (rad),
    the simulated time (s) and the process time per tick (us) against a bare mj_step's."""

    stood: bool = False
    steps: list[BlockStep] = field(default_factory=list)
    lowest_clearance_m: float = math.inf
    block_moved_m: float = 0.0
    block_turned_rad: float = 0.0
    sim_s: float = 0.0
    tick_us: float = 0.0
    mj_step_us: float = 0.0

    def worst(self) -> tuple[float, float, float]:
        """The worst landing's horizontal, height (m) and yaw (rad) errors."""
        if not self.steps:
            return (math.nan, math.nan, math.nan)
        return (max(s.horizontal_error_m for s in self.steps),
                max(s.height_error_m for s in self.steps),
                max(s.yaw_error_rad for s in self.steps))


def _step_command(step: Footstep, sole_ahead_m: float) -> AsiCommand:
    """STEP with `step` as its desired step (the foot link's pose, step_index 1, without a
    duration, as DRCSim's actionlib server sent it)."""
    desired = step_data_of(Footstep(1, step.foot_index, step.x_m, step.y_m, step.yaw_rad),
                           sole_ahead_m)
    desired = dataclasses.replace(desired, duration_s=0.0)
    return AsiCommand(0, Behavior.STEP, (StepData(),) * 4, False, desired, False,
                      ManipulateParams(), None, 0)


def _soles(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """Each sole's bottom face centre and yaw (2, 4): x, y, z (m), yaw (rad)."""
    poses = np.zeros((2, 4))
    for foot, geom in enumerate(sole_geom_ids(model)):
        rotation = data.geom_xmat[geom].reshape(3, 3)
        poses[foot, 0:3] = data.geom_xpos[geom] - rotation[:, 2] * model.geom_size[geom][2]
        poses[foot, 3] = math.atan2(rotation[1, 0], rotation[0, 0])
    return poses


def _block_pose(model: mujoco.MjModel, data: mujoco.MjData) -> tuple[np.ndarray, float]:
    body = model.body(BLOCK_NAME).id
    rotation = data.xmat[body].reshape(3, 3)
    return data.xipos[body].copy(), math.atan2(rotation[1, 0], rotation[0, 0])


def _bare_step_us(model: mujoco.MjModel, data: mujoco.MjData, steps: int = 500) -> float:
    scratch = mujoco.MjData(model)
    mujoco.mj_copyData(scratch, model, data)
    started = time.process_time()
    for _ in range(steps):
        mujoco.mj_step(model, scratch)
    return (time.process_time() - started) / steps * 1e6


class _Trial:
    """A trial's simulator, its interface and what it has seen so far."""

    def __init__(self, block: CinderBlock, seed: int | None) -> None:
        self.sim = AtlasSimulator(block_model(block), load_gains_yaml(DEFAULT_GAINS_FILE),
                                  time_to_unpin_s=0.0)
        place_in_stand_pose(self.sim.atlas, self.sim.data)
        perturb_start(self.sim.atlas, self.sim.data, seed)
        self.interface = AtlasSimInterface(self.sim, True)
        self.ground = GroundUnderFeet(self.sim.atlas, self.sim.data)
        self.run = BlockRun()
        self.ticks = 0

    def tick(self, command: AsiCommand | None = None) -> int:
        """One step with `command` applied first; step_feedback's status after it."""
        if command is not None:
            self.interface.apply(command)
        self.sim.step()
        flags = self.interface.state().step_feedback.status_flags
        self.interface.end_step()
        self.ticks += 1
        if self.ticks % FALL_CHECK_TICKS == 0:
            run = self.run
            run.lowest_clearance_m = min(run.lowest_clearance_m, self.ground.clearance_m())
        return flags

    def step_through(self, steps: list[Footstep]) -> None:
        """The client: STEP with its next target at every state, the next once it sees
        SWAYING after STEPPING (a touchdown); each step's sole noted once the step is over."""
        interface, run = self.interface, self.run
        model, data = self.sim.atlas.model, self.sim.data
        assert interface.stand is not None and interface.stepping is not None  # balance
        ahead, stepping = interface.stand.estimator.sole_ahead_m, interface.stepping
        target, previous = 0, SWAYING
        for _ in range(round(len(steps) * LONGEST_STEP_S / self.sim.dt_s)):
            if not standing(run.lowest_clearance_m):
                return
            done = stepping.steps_taken
            flags = self.tick(_step_command(steps[target], ahead) if target < len(steps)
                              else None)
            if previous == STEPPING and flags == SWAYING:
                target += 1
            previous = flags
            if stepping.steps_taken > done:
                x, y, z, yaw = _soles(model, data)[steps[done].foot_index].tolist()
                run.steps.append(BlockStep(steps[done], (x, y, z, yaw)))
            if len(run.steps) == len(steps) and stepping.static_step is None:
                return


def block_step_trial(block: CinderBlock, seed: int | None = None, plan: str = 'back',
                     stand_after_s: float = 2.0) -> BlockRun:
    """block_plan's `plan` stepped from a start perturbed by `seed`, then Stand for
    `stand_after_s`; stops early once it no longer stands."""
    trial = _Trial(block, seed)
    sim, run = trial.sim, trial.run
    model, data = sim.atlas.model, sim.data
    started = time.process_time()
    for _ in range(round(STAND_FIRST_S / sim.dt_s)):
        trial.tick()
    block_start, block_yaw = _block_pose(model, data)
    steps = block_plan(block, _soles(model, data)[:, 0:2], plan)
    trial.step_through(steps)
    for _ in range(round(stand_after_s / sim.dt_s)):
        if not standing(run.lowest_clearance_m):
            break
        trial.tick()
    run.stood = standing(run.lowest_clearance_m) and len(run.steps) == len(steps)
    block_end, block_end_yaw = _block_pose(model, data)
    run.block_moved_m = float(np.linalg.norm(block_end - block_start))
    run.block_turned_rad = abs(wrap_angle(block_end_yaw - block_yaw))
    run.sim_s = float(data.time)
    run.tick_us = (time.process_time() - started) / max(trial.ticks, 1) * 1e6
    run.mj_step_us = _bare_step_us(model, data)
    return run
