"""DRCSim's VRC Task 2 walking course, as figures: the one description the world's model,
the mud, the scoring and the course walkers read.

The figures are DRCSim 2.7.0's `vrc_task_2*.world` and the gazebo_models of June 2013
(`gate`, `starting_pen`, `mud_atlas`, `cinder_block`, `vrc_heightmap_2`), both Apache-2.0.
World frame as DRCSim's: x east, y north (the course runs from the pen at y -38 north to
gate_4 at y 18), z up, yaw about z from +x.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = [
    'BLOCKS', 'BLOCK_ENVELOPE_M', 'BLOCK_INERTIA', 'BLOCK_MASS_KG', 'BLOCK_WALLS',
    'FOOT_FRICTION', 'GATES', 'GATE_POST_M', 'GATE_WIDTH_M', 'HEIGHTMAP', 'MUD_BOX',
    'MUD_DAMPING', 'MUD_DAMPING_FINALS', 'MUD_FLOOR_FRICTION', 'MUD_FLOOR_FRICTION_FINALS',
    'MUD_FLOOR_Z_M', 'MUD_LINKS', 'PEN', 'PEN_FLOOR', 'PEN_FLOOR_FRICTION', 'PEN_POSE',
    'PEN_WALLS', 'STARTS', 'TERRAIN_FRICTION', 'WORLD_NAME', 'Block', 'Box', 'Gate',
    'Heightmap', 'Start',
]

#: The world's name: DRCSim's scoring is active in a world of this name only.
WORLD_NAME = 'vrc_task_2'


@dataclass(frozen=True)
class Heightmap:
    """Gazebo's heightmap: a square grey image over `size_m`, placed with its centre at
    (0, 0, z0_m); a pixel's height is z0 + relief · grey / brightest (Gazebo scales by the
    image's brightest pixel). The image's top row is +y, its left column -x."""

    pixels: int = 513
    size_m: float = 100.0
    relief_m: float = 3.5
    z0_m: float = -0.6
    brightest: int = 250

    @property
    def cell_m(self) -> float:
        """The distance between two pixels' centres (m)."""
        return self.size_m / (self.pixels - 1)

    def height_m(self, grey: float) -> float:
        """The height (m) of a pixel of grey level `grey`."""
        return self.z0_m + self.relief_m * grey / self.brightest


HEIGHTMAP = Heightmap()


@dataclass(frozen=True)
class Gate:
    """A gate: two posts and a bar, `width_m` across, its frame at (x, y) turned by yaw.
    DRCSim's scoring takes a gate's width as the larger side of its bounding box."""

    name: str
    x_m: float
    y_m: float
    yaw_rad: float
    width_m: float = 5.2


#: Each post is a 0.2 × 0.2 × 4 m box at ±2.5 m, the bar 0.2 × 5.2 × 0.2 m on top (z 4.1).
GATE_POST_M = (0.2, 0.2, 4.0)
GATE_WIDTH_M = 5.2

#: The gates in scoring order: gate_0 starts the clock, gates 1–4 a point each.
GATES: tuple[Gate, ...] = (
    Gate('gate_0', 1.0, -38.0, 0.0),
    Gate('gate_1', 0.0, -22.0, 1.5707),
    Gate('gate_2', 0.0, -10.5, 1.5707),
    Gate('gate_3', 6.0, 6.5, 1.5707),
    Gate('gate_4', 6.0, 18.0, 1.5707),
)


@dataclass(frozen=True)
class Box:
    """An axis-aligned box by its centre and full size (m)."""

    centre_m: tuple[float, float, float]
    size_m: tuple[float, float, float]

    def contains(self, x: float, y: float, z: float) -> bool:
        """Whether the world point is inside the box (its faces included)."""
        return all(abs(p - c) <= s / 2 for p, c, s in
                   zip((x, y, z), self.centre_m, self.size_m))


#: `mud_atlas`: the mud volume, 8 × 10 × 0.5 m centred at z -0.38 (the world's include sets
#: the model's pose), top at -0.13 m; it detects contact without pushing back.
MUD_BOX = Box((0.5, -16.6, -0.38), (8.0, 10.0, 0.5))
#: The MudPlugin's links and its viscous damping (N·s/m and N·m·s/rad); the finals' value.
MUD_LINKS: tuple[str, ...] = ('l_foot', 'r_foot', 'l_lleg', 'r_lleg')
MUD_DAMPING = 40.0
MUD_DAMPING_FINALS = 70.0
#: `mud_ground_plane`: the pit's real floor, a plane at z -0.59, mu 0.5 (the finals' 0.3).
MUD_FLOOR_Z_M = -0.59
MUD_FLOOR_FRICTION = 0.5
MUD_FLOOR_FRICTION_FINALS = 0.3

#: Atlas's feet (DRCSim's atlas model) and everything left unset (ODE's default).
FOOT_FRICTION = 1.5
TERRAIN_FRICTION = 1.0

#: `starting_pen` at (-8.27, -38, 0.02), yaw -90°: a 20 × 16 × 0.01 m floor within
#: 4.28 m walls, spanning x -8.3…2, y -43.9…-32.1, open east towards gate_0.
PEN = Box((-3.15, -38.0, 0.02), (10.3, 11.8, 0.01))

#: The pen model's frame in the world: (x, y, z) and yaw (rad), DRCSim's -1.5707.
PEN_POSE = ((-8.27, -38.0, 0.02), -1.5707)
#: Its collision boxes in its own frame (centre, full size; m), model.sdf's figures: seven
#: 4.28 m walls, the arrow sign on the outer wall, and the 20 × 16 × 0.01 m floor, last.
PEN_WALLS: tuple[Box, ...] = (
    Box((0.0, 0.0, 2.14), (12.15, 0.31, 4.28)),
    Box((-5.28, 14.3205, 2.14), (14.8, 0.46, 4.28)),
    Box((-5.91, 5.0, 2.14), (0.385, 10.3, 4.28)),
    Box((5.91, 5.161, 2.14), (0.385, 10.66, 4.28)),
    Box((3.9, 10.285, 2.14), (4.38, 0.45, 4.28)),
    Box((-4.0, 9.95, 2.14), (4.25, 0.45, 4.28)),
    Box((1.94, 12.3, 2.14), (0.45, 4.5, 4.28)),
    Box((-0.232, 14.03, 2.46), (3.33, 0.12, 1.16)),
)
PEN_FLOOR = Box((-3.21, 7.355, 0.0), (20.0, 16.0, 0.01))
#: The pen floor's mu (mu2 50): ODE took the smaller of it and the feet's 1.5.
PEN_FLOOR_FRICTION = 100.0

#: One 5 kg cinder block: five boxes inside a 0.435 × 0.203 × 0.203 m envelope, its frame
#: at the envelope's bottom centre (model.sdf of cinder_block).
BLOCK_MASS_KG = 5.0
BLOCK_ENVELOPE_M = (0.435, 0.203, 0.203)
#: The five walls (centre, full size; m) in the block's frame: two long sides, the two
#: ends and the middle web; hollow between them.
BLOCK_WALLS: tuple[Box, ...] = (
    Box((0.0, -0.08465, 0.1016), (0.43495, 0.0339, 0.2032)),
    Box((0.0, 0.08465, 0.1016), (0.43495, 0.0339, 0.2032)),
    Box((0.18625, 0.0, 0.1016), (0.0339, 0.1354, 0.203)),
    Box((0.0, 0.0, 0.1016), (0.0339, 0.1354, 0.203)),
    Box((-0.18625, 0.0, 0.1016), (0.0339, 0.1354, 0.203)),
)
#: Its inertia about its centre of mass (0, 0, 0.1016): model.sdf's diagonal (kg m²).
BLOCK_INERTIA = (0.028705, 0.073708, 0.06908)


@dataclass(frozen=True)
class Block:
    """A loose cinder block where the world file puts it: its frame's (x, y, z) and
    Gazebo's roll, pitch, yaw (fixed axes x, y, z; rad). Gazebo let it settle on the ground
    from there; z is above z 0, not above the heightmap."""

    name: str
    x_m: float
    y_m: float
    z_m: float
    roll_rad: float
    pitch_rad: float
    yaw_rad: float


#: The 30 blocks of the rubble (`vrc_task_2.world`), lying flat (roll and pitch 0), on a
#: side (roll 1.57) or on end (pitch 1.57).
BLOCKS: tuple[Block, ...] = (
    Block('cinder_block', 5.0, 12.5548, 0.118705, 1.57, 0.0, 1.0),
    Block('cinder_block_0', 8.0, 13.5719, 0.0, 0.0, 0.0, 0.2),
    Block('cinder_block_1', 8.0, 11.0, 0.217475, 0.0, 1.57, -1.3),
    Block('cinder_block_2', 6.0, 11.0, 0.217475, 0.0, 1.57, 0.2),
    Block('cinder_block_3', 5.41703, 14.5289, 0.118279, 1.57, 0.0, 0.05),
    Block('cinder_block_4', 7.44313, 15.0, 0.217475, 0.0, 1.57, 0.8),
    Block('cinder_block_5', 7.0, 12.4875, 0.0, 0.0, 0.0, 2.0),
    Block('cinder_block_6', 8.0, 8.0, 0.0, 0.0, 0.0, 3.0),
    Block('cinder_block_7', 5.0, 8.0, 0.217475, 0.0, 1.57, -2.0),
    Block('cinder_block_8', 5.0, 14.5, 0.11853, 1.57, 0.0, -0.5),
    Block('cinder_block_9', 6.7, 9.0, 0.0, 0.0, 0.0, 2.6),
    Block('cinder_block_10', 4.0, 16.4525, 0.0, 0.0, 0.0, 1.2),
    Block('cinder_block_11', 4.44348, 9.51062, 0.11853, 1.57, 0.0, 0.0),
    Block('cinder_block_12', 9.0, 16.0, 0.0, 0.0, 0.0, 0.3),
    Block('cinder_block_13', 4.52065, 16.0, 0.0, 0.0, 0.0, 0.1),
    Block('cinder_block_14', 9.0, 11.5289, 0.118707, 1.57, 0.0, 1.0),
    Block('cinder_block_15', 8.0, 9.57994, 0.0, 0.0, 0.0, 0.0),
    Block('cinder_block_16', 5.0, 16.0, 0.0, 0.0, 0.0, 0.8),
    Block('cinder_block_17', 5.7, 16.5948, 0.217475, 0.0, 1.57, -0.8),
    Block('cinder_block_18', 5.0, 11.0, 0.0, 0.0, 0.0, -0.005),
    Block('cinder_block_19', 8.0, 7.58666, 0.217475, 0.0, 1.57, 0.5),
    Block('cinder_block_20', 3.53091, 8.50047, 0.0, 0.0, 0.0, -0.1),
    Block('cinder_block_21', 9.0, 8.59824, 0.217475, 0.0, 1.57, 2.3),
    Block('cinder_block_22', 9.0, 15.4024, 0.0, 0.0, 0.0, 2.8),
    Block('cinder_block_23', 5.0, 14.0, 0.217475, 0.0, 1.57, -1.9),
    Block('cinder_block_24', 8.0, 12.0, 0.0, 0.0, 0.0, 1.9),
    Block('cinder_block_25', 8.0, 13.0, 0.0, 0.0, 0.0, 0.3),
    Block('cinder_block_26', 6.0, 7.5, 0.0, 0.0, 0.0, 0.1),
    Block('cinder_block_27', 7.42157, 9.0, 0.0, 0.0, 0.0, 0.0),
    Block('cinder_block_28', 4.0, 10.0, 0.0, 0.0, 0.0, 1.2),
)


@dataclass(frozen=True)
class Start:
    """Where a VRC Task 2 world starts Atlas: the pelvis (x, y, z) and yaw."""

    name: str
    x_m: float
    y_m: float
    z_m: float
    yaw_rad: float


#: DRCSim's four Task 2 worlds differ only in where Atlas starts.
STARTS: dict[str, Start] = {start.name: start for start in (
    Start('vrc_task_2', -3.0, -38.0, 1.1, 0.0),
    Start('vrc_task_2_mud_start', -0.29, -23.02, 0.927, math.pi / 2),
    Start('vrc_task_2_uneven_start', -0.24, -11.24, 0.928, math.pi / 2),
    Start('vrc_task_2_rubble_start', 5.49, 6.02, 0.930, math.pi / 2),
)}
