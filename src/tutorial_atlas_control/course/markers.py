"""The course as shapes a viewer draws (rviz's markers), from the compiled world, without ROS.

rviz cannot read an MJCF, so the course's static geometry is handed to it as plain arrays:
each heightfield as a triangle mesh through its own vertices (a sub-grid over the area
walked, every `stride`-th vertex, so that the mesh stays within a triangle budget rviz
draws at once), coloured by height, and each box welded to the world (gates, the pen's
walls and floor, the mud volume) with its pose, full size and material colour. Loose bodies
(the cinder blocks) move and are left out; so are planes (the pit's floor plane lies under
the terrain everywhere but in the pit) and boxes whose top lies under the terrain at their
centre (the pen's floor, 5 mm under the flat ground: drawn, it flickers through the mesh).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from tutorial_atlas_control.course.errors import CourseError

__all__ = ['COURSE_AREA', 'MAX_TRIANGLES', 'Area', 'BoxShape', 'CourseShapes', 'TerrainMesh',
           'course_shapes', 'height_colours', 'terrain_mesh']


@dataclass(frozen=True)
class Area:
    """A rectangle of the world's (x, y) plane (m), bounds included."""

    x_min: float
    x_max: float
    y_min: float
    y_max: float


#: The VRC Task 2 course's walked area: the pen (x from -8.3, y from -43.9) to past gate_4
#: (y 18), the rubble's east side (x 9) with a margin.
COURSE_AREA = Area(-12.0, 14.0, -45.0, 22.0)
#: At most this many triangles in a terrain's mesh: rviz draws ~20k at once, smoothly,
#: even with software OpenGL.
MAX_TRIANGLES = 20_000
#: Height colours, low to high: the pit's dark mud, grass, light dry hilltops (rgb).
_HEIGHT_RAMP = np.array([[0.30, 0.22, 0.12], [0.40, 0.50, 0.25], [0.85, 0.80, 0.62]])


@dataclass(frozen=True)
class TerrainMesh:
    """A heightfield's triangles over an area: `triangles` (n, 3, 3) world points, each
    triangle counter-clockwise seen from above; `colours` (n, 3, 4) rgba per corner;
    `stride` heightfield vertices between two mesh vertices, `cell_m` their spacing (m)."""

    name: str
    triangles: np.ndarray
    colours: np.ndarray
    stride: int
    cell_m: float


@dataclass(frozen=True)
class BoxShape:
    """A box geom: its centre (3,), orientation as a quaternion (w, x, y, z), full size (3,)
    and rgba (4,), all in the world frame."""

    name: str
    centre: np.ndarray
    quat: np.ndarray
    size: np.ndarray
    rgba: np.ndarray


@dataclass(frozen=True)
class CourseShapes:
    """The course's static shapes: the terrains' meshes and the boxes welded to the world."""

    terrains: tuple[TerrainMesh, ...]
    boxes: tuple[BoxShape, ...]


def course_shapes(model: mujoco.MjModel, area: Area = COURSE_AREA,
                  max_triangles: int = MAX_TRIANGLES) -> CourseShapes:
    """The static shapes of `model` in its initial pose (qpos0).

    Raises:
        CourseError: a heightfield has fewer than 2 x 2 vertices inside `area`, or the
            budget is below 2 triangles.
    """
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    static = [g for g in range(model.ngeom)
              if model.body_weldid[model.geom_bodyid[g]] == 0]
    fields = [g for g in static if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_HFIELD]
    terrains = tuple(terrain_mesh(model, data, g, area, max_triangles) for g in fields)
    grids = [_hfield_vertices(model, data, g).reshape(-1, 3) for g in fields]
    boxes = tuple(box for box in (_box(model, data, g) for g in static
                                  if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX)
                  if not _under_terrain(box, grids))
    return CourseShapes(terrains, boxes)


def _under_terrain(box: BoxShape, grids: list[np.ndarray]) -> bool:
    """Whether the box's highest corner lies under a terrain's vertex nearest its centre."""
    rotation = np.zeros(9)
    mujoco.mju_quat2Mat(rotation, box.quat)
    top = box.centre[2] + np.abs(rotation.reshape(3, 3)[2]) @ box.size / 2
    for grid in grids:
        nearest = np.argmin(np.sum((grid[:, :2] - box.centre[:2]) ** 2, axis=1))
        if top < grid[nearest, 2]:
            return True
    return False


def _geom_name(model: mujoco.MjModel, geom: int) -> str:
    return mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, geom) or f'geom_{geom}'


def _rgba(model: mujoco.MjModel, geom: int) -> np.ndarray:
    """The colour MuJoCo draws the geom in: its material's, else its own."""
    material = model.geom_matid[geom]
    return (model.mat_rgba[material] if material >= 0 else model.geom_rgba[geom]).copy()


def _box(model: mujoco.MjModel, data: mujoco.MjData, geom: int) -> BoxShape:
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, data.geom_xmat[geom])
    return BoxShape(_geom_name(model, geom), data.geom_xpos[geom].copy(), quat,
                    2 * model.geom_size[geom], _rgba(model, geom))


def _hfield_vertices(model: mujoco.MjModel, data: mujoco.MjData, geom: int) -> np.ndarray:
    """The heightfield's vertices in the world, (nrow, ncol, 3): row 0 at -y, column 0 at
    -x of the geom's frame, as MuJoCo lays out hfield_data."""
    field = model.geom_dataid[geom]
    nrow, ncol = int(model.hfield_nrow[field]), int(model.hfield_ncol[field])
    radius_x, radius_y, top, _base = model.hfield_size[field]
    start = model.hfield_adr[field]
    heights = model.hfield_data[start:start + nrow * ncol].reshape(nrow, ncol) * top
    x = np.linspace(-radius_x, radius_x, ncol)
    y = np.linspace(-radius_y, radius_y, nrow)
    local = np.stack(np.broadcast_arrays(x[None, :], y[:, None], heights), axis=-1)
    rotation = data.geom_xmat[geom].reshape(3, 3)
    return local @ rotation.T + data.geom_xpos[geom]


def _strided(indices: np.ndarray, stride: int) -> np.ndarray:
    """Every `stride`-th of `indices`, the last one always kept (the area's edge)."""
    picked = indices[::stride]
    return picked if picked[-1] == indices[-1] else np.append(picked, indices[-1])


def _stride_within(rows: int, cols: int, max_triangles: int) -> int:
    """The smallest stride whose mesh has at most `max_triangles` triangles."""
    stride = 1
    while 2 * (-(-(rows - 1) // stride)) * (-(-(cols - 1) // stride)) > max_triangles:
        stride += 1
    return stride


def terrain_mesh(model: mujoco.MjModel, data: mujoco.MjData, geom: int, area: Area,
                 max_triangles: int = MAX_TRIANGLES) -> TerrainMesh:
    """Heightfield geom `geom` over `area` as triangles through its own vertices, each cell
    split along its (-x, -y)-(+x, +y) diagonal as MuJoCo splits it.

    Raises:
        CourseError: fewer than 2 x 2 of its vertices lie inside `area`, or the budget is
            below 2 triangles.
    """
    name = _geom_name(model, geom)
    if max_triangles < 2:
        raise CourseError(f'terrain {name}: a mesh needs at least 2 triangles, '
                          f'{max_triangles} allowed')
    vertices = _hfield_vertices(model, data, geom)
    inside = ((vertices[..., 0] >= area.x_min) & (vertices[..., 0] <= area.x_max)
              & (vertices[..., 1] >= area.y_min) & (vertices[..., 1] <= area.y_max))
    rows, cols = np.nonzero(inside.any(axis=1))[0], np.nonzero(inside.any(axis=0))[0]
    if len(rows) < 2 or len(cols) < 2:
        raise CourseError(f'terrain {name}: fewer than 2 x 2 of its vertices lie in x '
                          f'{area.x_min}..{area.x_max}, y {area.y_min}..{area.y_max} m')
    stride = _stride_within(len(rows), len(cols), max_triangles)
    grid = vertices[np.ix_(_strided(rows, stride), _strided(cols, stride))]
    corner00, corner01 = grid[:-1, :-1], grid[:-1, 1:]   # (-x, -y), (+x, -y)
    corner10, corner11 = grid[1:, :-1], grid[1:, 1:]     # (-x, +y), (+x, +y)
    triangles = np.concatenate([
        np.stack([corner00, corner01, corner11], axis=2).reshape(-1, 3, 3),
        np.stack([corner00, corner11, corner10], axis=2).reshape(-1, 3, 3)])
    field = model.geom_dataid[geom]
    cell_m = 2 * float(model.hfield_size[field][0]) / (model.hfield_ncol[field] - 1) * stride
    return TerrainMesh(name, triangles, height_colours(triangles[..., 2]), stride, cell_m)


def height_colours(heights: np.ndarray) -> np.ndarray:
    """Opaque rgba (..., 4) for heights (...): a ramp from the lowest to the highest."""
    low, high = float(np.min(heights)), float(np.max(heights))
    scaled = (heights - low) / (high - low) if high > low else np.zeros_like(heights)
    position = scaled * (len(_HEIGHT_RAMP) - 1)
    index = np.minimum(position.astype(int), len(_HEIGHT_RAMP) - 2)
    fraction = (position - index)[..., None]
    rgb = _HEIGHT_RAMP[index] * (1 - fraction) + _HEIGHT_RAMP[index + 1] * fraction
    return np.concatenate([rgb, np.ones(heights.shape + (1,))], axis=-1)
