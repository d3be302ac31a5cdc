"""DRCSim's MudPlugin in MuJoCo: the feet and lower legs dragged while they touch the mud.

The world's mud is a box geom named `mud_atlas` that collides with nothing (contype and
conaffinity 0): it detects, it never pushes. Each step, between mj_step1 (the new positions'
kinematics and mass matrix) and mj_step2 (forces and integration), `MudDrag.update` finds
which of course.MUD_LINKS touch the box and where, and the drag of course.mud.implicit_drag
for all touching links together (as one ODE step solved the plugin's joints), moved to each
link's centre of mass. sim.body_forces adds `xfrc` to xfrc_applied for that step only; a
link that stops touching feels nothing the next step.

Where a link touches is MuJoCo's own contact list, as Gazebo's plugin read its contact
sensor's: mj_collision on a private copy of the world compiled from the same file, in which
only the mud links' collision geoms and the box collide (a runtime change of contype would
not do: a geom that collides with nothing is left out of its body's collision tree at
compile time), fed the step's poses copied from the simulation's data. The mean of a
link's contact points is its joint's anchor. A test of each geom's bounding sphere against
the box skips it all while no link is near the mud. Measured beside a bare mj_step (docs/
vrc.md#mud): the private kinematics and mj_collision cost 0.16-0.25 of it, asking
mj_geomDistance geom by geom 0.32-0.60 (its Python loop), so the contact list it is.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from tutorial_atlas_control.course import (
    MUD_DAMPING,
    MUD_LINKS,
    check_mud_damping,
    implicit_drag,
    wrench_at_com,
)
from tutorial_atlas_control.sim.model import ModelError

__all__ = ['MUD_GEOM', 'MudDrag']

#: The world's mud volume: a box geom of this name (course.MUD_BOX in the VRC worlds).
MUD_GEOM = 'mud_atlas'
#: Every mud link's geoms lie within this of the first mud link's origin (m): Atlas's feet
#: and lower legs span about 1.2 m. Farther from the box, nothing else is asked.
MUD_LINKS_SPAN_M = 2.0


class MudDrag:
    """The mud of one model, and the drag it puts on one MjData each step."""

    def __init__(self, model: mujoco.MjModel, mud_geom: int, damping: float,
                 contact_model: mujoco.MjModel) -> None:
        self.model = model
        self.mud_geom = mud_geom
        self.damping = check_mud_damping(damping)
        self.half_size_m = model.geom_size[mud_geom].copy()
        # The box is a static world geom: its centre, and the squared distance from it
        # beyond which the first mud link cannot have a geom in the box.
        self._centre_m = tuple(model.geom_pos[mud_geom].tolist())
        self._far_m2 = (float(np.linalg.norm(self.half_size_m)) + MUD_LINKS_SPAN_M) ** 2
        self.bodies, self.geoms, self.geom_link = _mud_link_geoms(model)
        self.contact_model = contact_model
        self.contact_data = mujoco.MjData(contact_model)
        #: A geom's link (index into `bodies`), -1 for the others (the box).
        self._link_of_geom = np.full(model.ngeom, -1, dtype=int)
        self._link_of_geom[self.geoms] = self.geom_link
        self._one_hot = np.eye(len(self.bodies))
        self.xfrc = np.zeros((model.nbody, 6))
        #: The last update's touching links (indices into `bodies`) and their mean contact
        #: points (world, m), for tests and tools.
        self.touching = np.zeros(0, dtype=int)
        self.points_m = np.zeros((0, 3))
        self._dragging = False
        self._jac = np.zeros((6 * len(self.bodies), model.nv))
        self._mobility = np.zeros_like(self._jac)

    @classmethod
    def for_model(cls, model: mujoco.MjModel, path: Path,
                  damping: float = MUD_DAMPING) -> MudDrag | None:
        """The mud of `model`, compiled from the MJCF at `path`, or None when it has no
        `mud_atlas` box or no mud link with a collision geom (nothing runs then).

        Raises:
            CourseError: `damping` is not a finite number >= 0.
            ModelError: the model's `mud_atlas` geom is not a box of the worldbody, or
                `path` does not compile to the same geoms.
        """
        geom = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, MUD_GEOM)
        if geom < 0:
            check_mud_damping(damping)
            return None
        if model.geom_type[geom] != mujoco.mjtGeom.mjGEOM_BOX:
            raise ModelError(f'geom {MUD_GEOM!r} must be a box (the mud volume), it is a '
                             f'{mujoco.mjtGeom(model.geom_type[geom]).name}')
        if model.geom_bodyid[geom] != 0:
            raise ModelError(f'geom {MUD_GEOM!r} must be in the worldbody (the mud is static)')
        if not len(_mud_link_geoms(model)[1]):  # no mud link that can touch: nothing to drag
            check_mud_damping(damping)
            return None
        return cls(model, geom, damping, _contact_model(model, path, geom))

    def _near(self, data: mujoco.MjData) -> bool:
        """Whether the first mud link is within MUD_LINKS_SPAN_M of the box's bounding
        sphere (in plain floats: the test of every step away from the mud)."""
        x, y, z = data.xpos[self.bodies[0]].tolist()
        cx, cy, cz = self._centre_m
        return (x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2 <= self._far_m2

    def _contact_points(self, data: mujoco.MjData) -> None:
        """`touching` and `points_m` for the current kinematics."""
        if not self._near(data):
            self.touching = self.touching[:0]
            return
        contact_model, contact_data = self.contact_model, self.contact_data
        for name in _POSE_FIELDS:
            np.copyto(getattr(contact_data, name), getattr(data, name))
        mujoco.mj_collision(contact_model, contact_data)
        count = contact_data.ncon
        if not count:
            self.touching = self.touching[:0]
            return
        pairs = contact_data.contact.geom[:count]
        # (contacts, links): 1 where the contact is the link's; then each link's mean point.
        links = self._link_of_geom[pairs].max(axis=1)
        one_hot = self._one_hot[links]
        counts = one_hot.sum(axis=0)
        self.touching = np.flatnonzero(counts)
        self.points_m = (one_hot.T @ contact_data.contact.pos[:count])[self.touching] \
            / counts[self.touching, None]

    def update(self, data: mujoco.MjData, dt_s: float) -> bool:
        """Compute `xfrc` (N, N·m at each body's centre of mass, world frame) for the step
        about to be integrated; False (and `xfrc` all zero) when no link touches the mud.

        `data` must hold the kinematics and mass matrix of its current qpos (after
        mj_step1 or mj_forward); it is only read.
        """
        self._contact_points(data)
        count = len(self.touching)
        if not count:
            if self._dragging:
                self.xfrc[:] = 0.0
                self._dragging = False
            return False
        self._dragging = True
        rows = 6 * count
        jac, mobility = self._jac[:rows], self._mobility[:rows]
        bodies = self.bodies[self.touching]
        for i, (body, point) in enumerate(zip(bodies.tolist(), self.points_m)):
            mujoco.mj_jac(self.model, data, jac[6 * i:6 * i + 3], jac[6 * i + 3:6 * i + 6],
                          point, body)
        mujoco.mj_solveM(self.model, data, mobility, jac)
        twists = (jac @ data.qvel).reshape(-1, 6)
        at_points = implicit_drag(self.damping, dt_s, twists, jac @ mobility.T)
        self.xfrc[:] = 0.0
        self.xfrc[bodies] = wrench_at_com(at_points, self.points_m, data.xipos[bodies])
        return True



#: What mj_collision reads of a step's poses (from mj_kinematics), copied to the private data:
#: the geoms' and the bodies' (a body of several geoms is bounded in its inertial frame).
_POSE_FIELDS = ('xpos', 'xmat', 'xipos', 'ximat', 'geom_xpos', 'geom_xmat')


def _mud_link_geoms(model: mujoco.MjModel) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The mud links present (body ids), their collision geoms (contype set: the soles'
    corner spheres, which touch heightfields only, are not the links' shapes), and each
    geom's link (an index into the first)."""
    found = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name) for name in MUD_LINKS]
    bodies = np.array([body for body in found if body >= 0], dtype=int)
    pairs = [(link, geom) for link, body in enumerate(bodies.tolist())
             for geom in range(model.ngeom) if model.geom_bodyid[geom] == body
             and model.geom_contype[geom]]
    return (bodies, np.array([geom for _, geom in pairs], dtype=int),
            np.array([link for link, _ in pairs], dtype=int))


def _contact_model(model: mujoco.MjModel, path: Path, mud_geom: int) -> mujoco.MjModel:
    """The world of `path` again, in which only the mud links' collision geoms (contype 1)
    and the mud box (conaffinity 1) collide.

    Raises:
        ModelError: `path` does not compile to `model`'s geoms.
    """
    spec = mujoco.MjSpec.from_file(str(path))
    spec.compile()  # the ids of the spec's geoms
    _, link_geoms, _ = _mud_link_geoms(model)
    wanted = set(link_geoms.tolist())
    for geom in spec.geoms:
        geom.contype = 1 if geom.id in wanted else 0
        geom.conaffinity = 1 if geom.id == mud_geom else 0
    private = spec.compile()
    if private.ngeom != model.ngeom or private.nbody != model.nbody \
            or not np.array_equal(private.geom_bodyid, model.geom_bodyid):
        raise ModelError(f'{path} does not compile to the simulated model\'s geoms; load the '
                         'model from that file')
    return private
