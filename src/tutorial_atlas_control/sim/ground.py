"""The ground from the loaded world: its height and unit normal under a world (x, y).

Today's world is the plane at z = 0; the VRC course (a heightfield, boxes, loose cinder
blocks) will sit under the same robot, so nothing that asks "where is the ground" may
assume z = 0. The ground is every geom that is not the robot's (the subtree of the
floating base `pelvis`) and that can touch it (contype/conaffinity against the robot's
geoms, or an explicit contact pair): a visual-only decoration is not ground, an invisible
collision box is.

The answer is a vertical ray cast down on each such geom with MuJoCo's own per-geom ray
functions (`mju_rayGeom` for planes and primitives, `mj_rayHfield`, `mj_rayMesh`), from
above the geom's highest point, the highest hit winning: the first surface a ray from
above the whole world meets, unless it is overhead: a surface whose geom's underside has
more than OVERHEAD_CLEARANCE_M of free space below it, down to the next surface (a VRC
gate's bar, 4 m over the course), is not the ground under it: the surface below is.
Per geom, not `mj_ray`, because `mj_ray` skips by visibility (transparent geoms) and
group, not by collision, and excludes one body, not the robot's subtree. Geoms whose
bounding sphere is not above (x, y) are culled first.
Planes are cast as unbounded (size 0), as MuJoCo collides them, not as rendered.

The normal is MuJoCo's: the installed MuJoCo (4.0.0) returns the hit surface's unit
normal from these ray functions (plane: its z axis; box: the face hit; heightfield: the
triangle hit; mesh: the face hit). On a level heightfield's exact edge MuJoCo's ray can
miss the edge triangles, so a point there is moved 1 nm inside.

Cost, measured on this 2-core machine (timeit, best of 5 x 10k calls): 4 us a height on the
Atlas world (the floor plane; `mj_ray` over the whole model costs 3 us), 4 us beside and
8 us on a box on a plane, 5 us a point batched (`hits`).
Deterministic: geoms of bodies welded to the world are placed once at construction; loose
bodies' geoms are read from the MjData given (as last computed by mj_forward/mj_step).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import mujoco
import numpy as np

from tutorial_atlas_control.errors import AtlasControlError

__all__ = ['Ground', 'GroundError', 'GroundHit', 'ROBOT_ROOT_BODY']

#: The robot's floating base: it and every body under it are the robot, never ground.
ROBOT_ROOT_BODY = 'pelvis'
#: A surface is overhead, not ground, when its geom's underside is more than this (m) above
#: the next ground surface below it: a robot under it stands on that one (walking under a
#: VRC gate's bar, the fall criterion, the Stand's height and Walk's steps took the bar
#: 4 m up for the ground). Cinder blocks and the pen's floor rest on what is below them.
OVERHEAD_CLEARANCE_M = 1.0
_OVERHEAD_TOLERANCE_M = 1e-6  # a surface touching an underside is under it
#: The rays start this far (m) above a geom's highest point.
_RAY_MARGIN_M = 1.0
_DOWN = np.array([0.0, 0.0, -1.0])
_UNBOUNDED = np.zeros(3)  # a plane's size for the ray: infinite, as its collisions are
_PRIMITIVES = frozenset(int(t) for t in (
    mujoco.mjtGeom.mjGEOM_SPHERE, mujoco.mjtGeom.mjGEOM_CAPSULE,
    mujoco.mjtGeom.mjGEOM_ELLIPSOID, mujoco.mjtGeom.mjGEOM_CYLINDER,
    mujoco.mjtGeom.mjGEOM_BOX))
#: A point this close (m) to a heightfield's edge is moved this far inside it.
_BORDER_M = 1e-9
#: With more geoms than this welded to the world (or loose), numpy culls them (else a Python
#: loop).
_NUMPY_CULL_FROM = 16
_PLANE = int(mujoco.mjtGeom.mjGEOM_PLANE)
_HFIELD = int(mujoco.mjtGeom.mjGEOM_HFIELD)
_MESH = int(mujoco.mjtGeom.mjGEOM_MESH)


class GroundError(AtlasControlError):
    """The world holds ground this module cannot cast rays on (e.g. an SDF geom)."""


class GroundHit(NamedTuple):
    """The ground under a point: height (m, world z), unit normal (3,), the geom's id.
    Nothing below: height -inf, normal NaN, geom -1."""

    height_m: float
    normal: np.ndarray
    geom_id: int


def robot_bodies(model: mujoco.MjModel, root: str = ROBOT_ROOT_BODY) -> frozenset[int]:
    """The ids of `root` and every body under it (empty when the model has no `root`)."""
    root_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, root)
    if root_id < 0:
        return frozenset()
    bodies = set()
    for body in range(model.nbody):
        walk = body
        while walk > 0 and walk != root_id:
            walk = int(model.body_parentid[walk])
        if walk == root_id:
            bodies.add(body)
    return frozenset(bodies)


def ground_geoms(model: mujoco.MjModel, robot: frozenset[int]) -> list[int]:
    """Geoms outside `robot` that can touch it: by contype/conaffinity against any robot
    geom, or by a contact pair; with no robot, any geom with contype or conaffinity."""
    body = model.geom_bodyid
    mine = np.array([int(body[g]) in robot for g in range(model.ngeom)], dtype=bool)
    contype, conaffinity = model.geom_contype, model.geom_conaffinity
    if mine.any():
        robot_type = np.bitwise_or.reduce(contype[mine])
        robot_affinity = np.bitwise_or.reduce(conaffinity[mine])
        touches = ((contype & robot_affinity) != 0) | ((conaffinity & robot_type) != 0)
    else:
        touches = (contype != 0) | (conaffinity != 0)
    for first, second in zip(model.pair_geom1, model.pair_geom2):
        if mine[first] != mine[second]:
            touches[second if mine[first] else first] = True
    return [g for g in range(model.ngeom) if touches[g] and not mine[g]]


class _Cast(NamedTuple):
    """One ground geom, ready for rays: its id, type, the MjData holding its pose, views of
    that pose, the size the ray takes, its bounding sphere's radius."""

    geom: int
    kind: int
    data: mujoco.MjData
    pos: np.ndarray
    mat: np.ndarray
    size: np.ndarray
    rbound: float
    aabb: np.ndarray  # its bounding box in its own frame: centre (3,), half sizes (3,)

    def top_m(self) -> float:
        """The highest point (m) of its bounding box, as placed now."""
        return float(_box_tops(self.pos[None, 2], self.mat[None, 6:9], self.aabb[None])[0])

    def bottom_m(self) -> float:
        """The lowest point (m) of its bounding box, as placed now (-inf for a plane)."""
        if self.kind == _PLANE:
            return -math.inf
        up = self.mat[6:9]
        return float(self.pos.item(2) + up @ self.aabb[:3] - np.abs(up) @ self.aabb[3:])


def _box_tops(z: np.ndarray, up: np.ndarray, aabb: np.ndarray) -> np.ndarray:
    """The highest points (m) of bounding boxes (n,): centres' world z (n,), the world z rows
    of their rotations (n, 3), the boxes in their own frames (n, 6: centre, half sizes).
    Sums written out in one order, so that one box and many give the same bits."""
    centre = up * aabb[:, :3]
    half = np.abs(up) * aabb[:, 3:]
    return (z + (centre[:, 0] + centre[:, 1] + centre[:, 2])
            + (half[:, 0] + half[:, 1] + half[:, 2]))


def _inside_border(cast: _Cast, x: float, y: float) -> tuple[float, float]:
    """(x, y) moved _BORDER_M inside a level heightfield's edge when it is on the edge:
    there MuJoCo's ray can miss the edge triangles and report the field's zero level."""
    mat = cast.mat
    if mat.item(8) != 1.0:
        return x, y
    px, py, _ = cast.pos.tolist()
    m00, m01, _, m10, m11 = mat[:5].tolist()
    local_x, local_y = m00 * (x - px) + m10 * (y - py), m01 * (x - px) + m11 * (y - py)
    reach_x, reach_y = cast.size.item(0) - _BORDER_M, cast.size.item(1) - _BORDER_M
    if abs(local_x) <= reach_x and abs(local_y) <= reach_y:
        return x, y
    if reach_x < abs(local_x) <= reach_x + 2 * _BORDER_M:
        local_x = math.copysign(reach_x, local_x)
    if reach_y < abs(local_y) <= reach_y + 2 * _BORDER_M:
        local_y = math.copysign(reach_y, local_y)
    return px + m00 * local_x + m01 * local_y, py + m10 * local_x + m11 * local_y


class Ground:
    """The ground of `model`'s world under world points; `data` gives the poses of loose
    (not welded to the world) bodies, else they stay where the model puts them."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData | None = None,
                 robot_root: str = ROBOT_ROOT_BODY) -> None:
        self.model = model
        self.geom_ids = tuple(ground_geoms(model, robot_bodies(model, robot_root)))
        fixed = mujoco.MjData(model)  # world-welded geoms' poses do not depend on qpos
        mujoco.mj_kinematics(model, fixed)
        self._fixed = fixed
        loose_data = data if data is not None else fixed
        body = model.geom_bodyid
        welded = (model.body_weldid[body] == 0) & (model.body_mocapid[body] < 0)
        casts = [self._prepare(geom, fixed if welded[geom] else loose_data)
                 for geom in self.geom_ids]
        self._planes = [c for c in casts if c.kind == _PLANE]
        #: The heightfields among them (the course's terrain).
        self.hfield_geoms = frozenset(c.geom for c in casts if c.kind == _HFIELD)
        self._static = [c for c in casts if c.kind != _PLANE and welded[c.geom]]
        self._loose = [c for c in casts if c.kind != _PLANE and not welded[c.geom]]
        # The loose geoms as arrays, for numpy (the course's 30 blocks are 150 boxes).
        self._loose_data = loose_data
        self._loose_ids = np.array([c.geom for c in self._loose], dtype=int)
        self._loose_r2 = np.array([c.rbound for c in self._loose]) ** 2
        self._loose_aabb = np.array([c.aabb for c in self._loose]).reshape(-1, 6)
        self._loose_bodies = np.unique(model.geom_bodyid[self._loose_ids])
        self._static_xy = np.array([c.pos[:2] for c in self._static]).reshape(-1, 2)
        self._static_r2 = np.array([c.rbound for c in self._static]) ** 2
        self._static_disc = [(*self._static_xy[i].tolist(), self._static_r2[i].item())
                             for i in range(len(self._static))]
        self._pnt = np.zeros(3)
        self._last_key: tuple[float, float, bytes] | None = None  # height_m's last question
        self._last_height_m = -math.inf
        self._normal = np.zeros(3)
        level = [c.pos.item(2) for c in self._planes if c.mat.item(8) == 1.0]
        tilted = len(level) < len(self._planes)
        #: The ground's height (m) everywhere when it is level planes only (today's world),
        #: else None: callers skip the rays.
        flat = level and not tilted and not self._static and not self._loose
        self.level_m: float | None = max(level) if flat else None
        self._static_top_m = max([-math.inf] + level + [c.top_m() for c in self._static])
        if tilted:
            self._static_top_m = math.inf

    def top_m(self) -> float:
        """No ground is higher than this (m), anywhere (inf under a tilted plane): a point
        higher above it than a threshold is that high above the ground, without rays."""
        top = self._static_top_m
        if len(self._loose) > _NUMPY_CULL_FROM:
            ids, data = self._loose_ids, self._loose_data
            tops = _box_tops(data.geom_xpos[ids, 2], data.geom_xmat[ids, 6:9], self._loose_aabb)
            return max(top, float(tops.max()))
        for cast in self._loose:
            top = max(top, cast.top_m())
        return top

    def clear_above(self, z_m: float, clearance_m: float) -> bool:
        """Whether `z_m` is at least `clearance_m` above every ground surface, without
        rays: `z_m - top_m() >= clearance_m`, the world-welded geoms' bound tried first (the
        course's gate bars fail it: the loose blocks are then not looked at)."""
        if z_m - self._static_top_m < clearance_m:
            return False
        return z_m - self.top_m() >= clearance_m

    def _prepare(self, geom: int, data: mujoco.MjData) -> _Cast:
        model = self.model
        kind = int(model.geom_type[geom])
        if kind not in _PRIMITIVES and kind not in (_PLANE, _HFIELD, _MESH):
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, geom)
            raise GroundError(f'geom {geom} ({name}) is ground of type '
                              f'{mujoco.mjtGeom(kind).name}, which the ground cannot cast '
                              'rays on')
        size = _UNBOUNDED if kind == _PLANE else model.geom_size[geom].copy()
        if kind == _HFIELD:
            size = model.hfield_size[model.geom_dataid[geom]][:3].copy()
        return _Cast(geom, kind, data, data.geom_xpos[geom], data.geom_xmat[geom], size,
                     float(model.geom_rbound[geom]) + 1e-9, model.geom_aabb[geom].copy())

    def _candidates(self, x: float, y: float) -> list[_Cast]:
        """Planes, and the bounded geoms whose bounding sphere is above (x, y)."""
        found = list(self._planes)
        if len(self._static) > _NUMPY_CULL_FROM:
            near = ((self._static_xy[:, 0] - x) ** 2 + (self._static_xy[:, 1] - y) ** 2
                    <= self._static_r2)
            found += [self._static[i] for i in np.flatnonzero(near)]
        else:
            found += [cast for cast, (cx, cy, r2) in zip(self._static, self._static_disc)
                      if (cx - x) ** 2 + (cy - y) ** 2 <= r2]
        if len(self._loose) > _NUMPY_CULL_FROM:
            xy = self._loose_data.geom_xpos[self._loose_ids, :2]
            near = (xy[:, 0] - x) ** 2 + (xy[:, 1] - y) ** 2 <= self._loose_r2
            found += [self._loose[i] for i in np.flatnonzero(near)]
            return found
        for cast in self._loose:
            cx, cy, _ = cast.pos.tolist()
            if (cx - x) ** 2 + (cy - y) ** 2 <= cast.rbound ** 2:
                found.append(cast)
        return found

    @staticmethod
    def _top_m(cast: _Cast, x: float, y: float) -> float:
        """A height (m) above the geom's surface over (x, y): a plane's there, bounded by
        its tilt; else its bounding sphere's top."""
        px, py, pz = cast.pos.tolist()
        if cast.kind != _PLANE:
            return pz + cast.rbound
        up = cast.mat.item(8)  # the plane normal's world z
        if up <= 1e-9:
            return math.inf  # upright or facing down: no vertical ray from above hits it
        if up == 1.0:
            return pz
        return pz + math.sqrt(1.0 - up * up) / up * math.hypot(x - px, y - py)

    def _cast(self, cast: _Cast, x: float, y: float) -> float:
        """The height (m) where a vertical ray down at (x, y) meets the geom (-inf: it
        misses); its normal left in self._normal."""
        top = self._top_m(cast, x, y)
        if top == math.inf:
            return -math.inf
        pnt = self._pnt
        pnt[0], pnt[1], pnt[2] = x, y, top + _RAY_MARGIN_M
        if cast.kind == _HFIELD:
            pnt[0], pnt[1] = _inside_border(cast, x, y)
            distance = mujoco.mj_rayHfield(self.model, cast.data, cast.geom, pnt, _DOWN,
                                           self._normal)
        elif cast.kind == _MESH:
            distance = mujoco.mj_rayMesh(self.model, cast.data, cast.geom, pnt, _DOWN,
                                         self._normal)
        else:
            distance = mujoco.mju_rayGeom(cast.pos, cast.mat, cast.size, pnt, _DOWN,
                                          cast.kind, self._normal)
        return -math.inf if distance < 0 else (top + _RAY_MARGIN_M) - distance

    def _highest(self, x: float, y: float) -> tuple[float, int, np.ndarray | None]:
        """The highest surface under (x, y) that is not overhead (OVERHEAD_CLEARANCE_M)."""
        candidates = self._candidates(x, y)
        found = self._highest_below(candidates, x, y, math.inf)
        while found[2] is not None:
            cast = found[3]
            if cast is None or cast.kind in (_PLANE, _HFIELD):
                break  # nothing lies under a plane or a heightfield's surface
            underside = cast.bottom_m()
            below = self._highest_below(candidates, x, y, underside)
            if below[2] is None or underside - below[0] <= OVERHEAD_CLEARANCE_M:
                break
            found = below
        return found[0], found[1], found[2]

    def _highest_below(self, candidates: list[_Cast], x: float, y: float, below_m: float
                       ) -> tuple[float, int, np.ndarray | None, _Cast | None]:
        """The highest hit under (x, y) at or below `below_m`: height, geom, normal, cast."""
        best, best_geom, normal, best_cast = -math.inf, -1, None, None
        for cast in candidates:
            height = self._cast(cast, x, y)
            if best < height <= below_m + _OVERHEAD_TOLERANCE_M:
                best, best_geom, normal, best_cast = height, cast.geom, self._normal.copy(), cast
        return best, best_geom, normal, best_cast

    def hit(self, x: float, y: float) -> GroundHit:
        """The highest ground surface under world (x, y): height, normal, geom."""
        height, geom, normal = self._highest(x, y)
        return GroundHit(height, np.full(3, np.nan) if normal is None else normal, geom)

    def height_m(self, x: float, y: float) -> float:
        """The ground's height (m) under world (x, y); -inf over no ground.

        The last answer is kept with its question (the point and the loose geoms' poses):
        the node's fall watch and the AtlasSimInterface ask the same one each step."""
        key = (x, y, self._loose_poses())
        if key != self._last_key:
            self._last_key, self._last_height_m = key, self._highest(x, y)[0]
        return self._last_height_m

    def _loose_poses(self) -> bytes:
        """The loose geoms' bodies' world poses now (xpos, xquat), as bytes: what a height
        depends on besides the point (the welded geoms never move; a geom's pose is its
        body's composed with a fixed offset). Bodies: 30 on the course, not 150 geoms."""
        bodies, data = self._loose_bodies, self._loose_data
        return data.xpos[bodies].tobytes() + data.xquat[bodies].tobytes()

    def normal(self, x: float, y: float) -> np.ndarray:
        """The ground's unit normal (3,) under world (x, y); NaN over no ground."""
        return self.hit(x, y).normal

    def hits(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Heights (n,) and normals (n, 3) under the world points `xy` (n, 2)."""
        points = np.asarray(xy, dtype=float).reshape(-1, 2)
        heights = np.empty(len(points))
        normals = np.empty((len(points), 3))
        for row, (x, y) in enumerate(points.tolist()):
            heights[row], normals[row], _ = self.hit(x, y)
        return heights, normals
