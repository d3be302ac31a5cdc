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
    'BLOCK_MASS_KG', 'FOOT_FRICTION', 'GATES', 'GATE_POST_M', 'GATE_WIDTH_M', 'HEIGHTMAP',
    'MUD_BOX', 'MUD_DAMPING', 'MUD_DAMPING_FINALS', 'MUD_FLOOR_FRICTION',
    'MUD_FLOOR_FRICTION_FINALS', 'MUD_FLOOR_Z_M', 'MUD_LINKS', 'PEN', 'STARTS',
    'TERRAIN_FRICTION', 'WORLD_NAME', 'Box', 'Gate', 'Heightmap', 'Start',
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

#: One 5 kg cinder block: five boxes inside a 0.435 × 0.203 × 0.203 m envelope.
BLOCK_MASS_KG = 5.0


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
