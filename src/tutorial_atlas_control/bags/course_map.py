"""The VRC Task 2 course from above with a recorded run on it, as a PNG: the terrain's
heights shaded, the start pen's walls, the five gates (posts, the line between them, their
names), the mud box, the cinder blocks where the world file puts them, the pelvis's path,
the feet's landings, the falls and the score's events.

The course's figures are course/vrc_task_2.py's, the terrain the package's image with
course.HEIGHTMAP's scaling; the run's are bags/course_run.py's. The layout is fixed (no
tight_layout): MAP_SCALE_PX_PER_M pixels a metre over COURSE_EXTENT_M, so `map_pixel` says
where a world point lands in the image.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from tutorial_atlas_control.bags.course_run import CourseRun
from tutorial_atlas_control.bags.course_terrain import terrain_heights
from tutorial_atlas_control.bags.footprints import sole_patch
from tutorial_atlas_control.course import (
    BLOCK_ENVELOPE_M,
    BLOCKS,
    GATES,
    HEIGHTMAP,
    MUD_BOX,
    PEN_POSE,
    PEN_WALLS,
    Block,
    Box,
    Gate,
)
from tutorial_atlas_control.errors import BagAnalysisError

__all__ = ['COURSE_EXTENT_M', 'MAP_SIZE_PX', 'map_pixel', 'plot_course_map']

#: The area drawn (m): x from, x to, y from, y to; the pen, the gates, the pit, the rubble.
COURSE_EXTENT_M = (-12.0, 14.0, -45.0, 22.0)
#: Pixels a metre, and the margins (px) around the map: left, right, bottom, top.
MAP_SCALE_PX_PER_M = 20
MAP_MARGINS_PX = (70, 20, 60, 40)
_DPI = 100
#: The gates' and the path's colours, chosen away from the terrain's greens and browns.
GATE_COLOUR = '#d01cd0'
PATH_COLOUR = '#1060ff'
FOOT_COLOURS = ('#00d0ff', '#ff8000')


def _size_px() -> tuple[int, int]:
    x0, x1, y0, y1 = COURSE_EXTENT_M
    left, right, bottom, top = MAP_MARGINS_PX
    return (int(round((x1 - x0) * MAP_SCALE_PX_PER_M)) + left + right,
            int(round((y1 - y0) * MAP_SCALE_PX_PER_M)) + bottom + top)


#: The image's width and height (px).
MAP_SIZE_PX = _size_px()


def map_pixel(x_m: float, y_m: float) -> tuple[int, int]:
    """The image's column and row (from the top) of world point (x, y)."""
    x0, _x1, _y0, y1 = COURSE_EXTENT_M
    left, _right, _bottom, top = MAP_MARGINS_PX
    return (int(left + (x_m - x0) * MAP_SCALE_PX_PER_M),
            int(top + (y1 - y_m) * MAP_SCALE_PX_PER_M))


def _shaded_terrain(ax: Any) -> None:
    """The heights under COURSE_EXTENT_M, lit from the north-west, coloured by height."""
    import matplotlib.pyplot as plt  # noqa: PLC0415
    from matplotlib.colors import LightSource  # noqa: PLC0415

    heights = terrain_heights()
    half, cell = HEIGHTMAP.size_m / 2.0, HEIGHTMAP.cell_m
    x0, x1, y0, y1 = COURSE_EXTENT_M
    cols = slice(int(np.floor((x0 + half) / cell)), int(np.ceil((x1 + half) / cell)) + 1)
    rows = slice(int(np.floor((half - y1) / cell)), int(np.ceil((half - y0) / cell)) + 1)
    crop = heights[rows, cols]
    extent = (cols.start * cell - half, (cols.stop - 1) * cell - half,
              half - (rows.stop - 1) * cell, half - rows.start * cell)
    top = HEIGHTMAP.z0_m + HEIGHTMAP.relief_m
    rgb = LightSource(azdeg=315, altdeg=40).shade(
        crop, cmap=plt.get_cmap('gist_earth'), vert_exag=4.0, dx=cell, dy=cell,
        blend_mode='soft', vmin=HEIGHTMAP.z0_m - 0.5, vmax=top)
    ax.imshow(rgb, extent=extent, origin='upper', interpolation='bilinear', zorder=0)


def _box_corners(box: Box, x_m: float, y_m: float, yaw_rad: float) -> np.ndarray:
    """A box's footprint corners (4, 2) in the world, the box in a frame at (x, y, yaw)."""
    (cx, cy, _cz), (sx, sy, _sz) = box.centre_m, box.size_m
    local = np.array([(cx - sx / 2, cy - sy / 2), (cx + sx / 2, cy - sy / 2),
                      (cx + sx / 2, cy + sy / 2), (cx - sx / 2, cy + sy / 2)])
    c, s = np.cos(yaw_rad), np.sin(yaw_rad)
    return local @ np.array([[c, s], [-s, c]]) + np.array([x_m, y_m])


def _block_corners(block: Block) -> np.ndarray:
    """A cinder block's footprint as the world file sets it down: its envelope turned by
    roll and pitch, bounded in its yawed frame (exact for the file's 0 and 1.57 rad)."""
    cr, sr = np.cos(block.roll_rad), np.sin(block.roll_rad)
    cp, sp = np.cos(block.pitch_rad), np.sin(block.pitch_rad)
    turn = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]]) @ np.array(
        [[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    size = np.array(BLOCK_ENVELOPE_M)
    extent = np.abs(turn[:2]) @ size
    centre = turn[:2] @ np.array([0.0, 0.0, size[2] / 2])  # its frame is at the bottom
    box = Box((float(centre[0]), float(centre[1]), 0.0), (float(extent[0]),
                                                          float(extent[1]), 0.0))
    return _box_corners(box, block.x_m, block.y_m, block.yaw_rad)


def _gate_posts(gate: Gate) -> np.ndarray:
    """The two posts' centres (2, 2): ±2.5 m along the gate frame's y."""
    c, s = np.cos(gate.yaw_rad), np.sin(gate.yaw_rad)
    return np.array([(gate.x_m - s * k, gate.y_m + c * k) for k in (-2.5, 2.5)])


def draw_course(ax: Any) -> None:
    """The course's fixed parts over the shaded terrain: pen, mud box, blocks, gates."""
    from matplotlib.patches import Polygon  # noqa: PLC0415

    (px, py, _pz), pen_yaw = PEN_POSE
    for number, wall in enumerate(PEN_WALLS):
        ax.add_patch(Polygon(_box_corners(wall, px, py, pen_yaw), closed=True, fill=False,
                             edgecolor='white', lw=1.2, zorder=2,
                             label='start pen' if number == 0 else None))
    (mx, my, _mz), (msx, msy, _msz) = MUD_BOX.centre_m, MUD_BOX.size_m
    ax.add_patch(Polygon(_box_corners(Box((0, 0, 0), (msx, msy, 0)), mx, my, 0.0),
                         closed=True, fill=False, edgecolor='#7a3b00', lw=1.5, ls='--',
                         zorder=2, label='mud box'))
    for number, block in enumerate(BLOCKS):
        ax.add_patch(Polygon(_block_corners(block), closed=True, facecolor='0.55',
                             edgecolor='black', lw=0.5, zorder=2,
                             label='cinder blocks (as placed)' if number == 0 else None))
    draw_gates(ax)


def draw_gates(ax: Any) -> None:
    """Each gate: the line between its posts, the posts, its name."""
    from matplotlib.patches import Rectangle  # noqa: PLC0415

    for number, gate in enumerate(GATES):
        posts = _gate_posts(gate)
        ax.plot(posts[:, 0], posts[:, 1], color=GATE_COLOUR, lw=3, zorder=3,
                solid_capstyle='butt', label='gates' if number == 0 else None)
        for x, y in posts:
            ax.add_patch(Rectangle((x - 0.2, y - 0.2), 0.4, 0.4, color='black', zorder=4))
        _label_gate(ax, gate.name, number, posts)


def _label_gate(ax: Any, name: str, number: int, posts: np.ndarray) -> None:
    """The gate's name, and the number score.log gives it, beyond its east or north post
    (off the line, the path and the events' notes, which stand west of the path)."""
    along = posts[1] - posts[0]
    horizontal = abs(along[0]) >= abs(along[1])
    end = posts[int(np.argmax(posts[:, 0] if horizontal else posts[:, 1]))]
    ax.annotate(f'{name}\n(log: gate {number + 1})', tuple(end), fontsize=8,
                xytext=(8, 0) if horizontal else (0, 8), textcoords='offset points',
                ha='left' if horizontal else 'center', va='center' if horizontal else 'bottom',
                fontweight='bold', zorder=5, color='white',
                bbox={'boxstyle': 'round,pad=0.15', 'fc': GATE_COLOUR, 'ec': 'none'})


def _draw_run(ax: Any, run: CourseRun) -> None:
    """The pelvis's path, the landings, the falls and the events."""
    from matplotlib.patches import Rectangle  # noqa: PLC0415

    path = run.pelvis_xy
    ax.plot(path[:, 0], path[:, 1], color=PATH_COLOUR, lw=1.5, zorder=6, label='pelvis')
    ax.plot(path[:1, 0], path[:1, 1], 'o', color=PATH_COLOUR, mec='white', ms=4, zorder=7,
            label='start')
    if run.sole is not None:
        for landing in run.landings:
            ax.add_patch(sole_patch(run.sole, landing.x_m, landing.y_m, landing.yaw_rad,
                                    Rectangle, facecolor=FOOT_COLOURS[landing.foot_index % 2],
                                    edgecolor='black', lw=0.3, zorder=6))
        ax.plot([], [], 's', color=FOOT_COLOURS[0], label='left foot landed')
        ax.plot([], [], 's', color=FOOT_COLOURS[1], label='right foot landed')
    for number, fall in enumerate(run.falls):
        ax.plot(fall.x_m, fall.y_m, 'X', color='red', mec='white', ms=12, zorder=8,
                label='falls' if number == 0 else None)
        ax.annotate(f'{fall.text}, {fall.sim_time_s:.1f} s', (fall.x_m, fall.y_m),
                    xytext=(8, -12), textcoords='offset points', fontsize=7, color='red',
                    zorder=9, bbox={'fc': 'white', 'ec': 'none', 'alpha': 0.8, 'pad': 1})
    for number, event in enumerate(run.events):
        ax.plot(event.x_m, event.y_m, 'o', color='yellow', mec='black', ms=6, zorder=8)
        ax.annotate(f'{event.sim_time_s:.1f} s {event.text}', (event.x_m, event.y_m),
                    xytext=(-8, 6 + 11 * (number % 2)), textcoords='offset points',
                    ha='right', fontsize=7, zorder=9,
                    bbox={'fc': 'lightyellow', 'ec': 'none', 'alpha': 0.85, 'pad': 1})


def _title(run: CourseRun | None) -> str:
    last = None if run is None else run.last_score
    if last is None:
        return 'VRC Task 2 (no /vrc_score in the bag)'
    return (f'VRC Task 2: score {last.completion}, falls {last.falls}, '
            f'{last.sim_elapsed_s:.1f} s since gate 1 (sim time {last.sim_time_s:.1f} s)')


def plot_course_map(run: CourseRun | None, path: Path | str,
                    cloud: np.ndarray | None = None) -> Path:
    """The map of `run` (None: the course alone), written to `path` (PNG, MAP_SIZE_PX);
    with `cloud`, the laser's points (x, y, z in the world, m) over it, coloured by height.

    Raises:
        BagAnalysisError: The image cannot be written.
    """
    import matplotlib  # noqa: PLC0415 - only the map needs it

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt  # noqa: PLC0415

    width, height = MAP_SIZE_PX
    left, right, bottom, top = MAP_MARGINS_PX
    figure = plt.figure(figsize=(width / _DPI, height / _DPI), dpi=_DPI)
    ax = figure.add_axes((left / width, bottom / height, 1 - (left + right) / width,
                          1 - (bottom + top) / height))
    _shaded_terrain(ax)
    draw_course(ax)
    if run is not None:
        _draw_run(ax, run)
    if cloud is not None and len(cloud):
        ax.scatter(cloud[:, 0], cloud[:, 1], c=cloud[:, 2], s=0.3, cmap='viridis', zorder=5,
                   linewidths=0, label=f'laser points ({len(cloud)})')
    x0, x1, y0, y1 = COURSE_EXTENT_M
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect('auto')
    ax.set_xlabel('x (m, east)')
    ax.set_ylabel('y (m, north)')
    ax.set_title(_title(run), fontsize=9)
    ax.legend(loc='lower right', fontsize=7, framealpha=0.85)
    try:
        figure.savefig(path, dpi=_DPI)
    except OSError as err:
        raise BagAnalysisError(f'Could not write the course map to {path}: '
                               f'{err.strerror or err}.') from err
    finally:
        plt.close(figure)
    return Path(path)
