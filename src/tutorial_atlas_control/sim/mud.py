"""DRCSim's MudPlugin in MuJoCo: the feet and lower legs dragged while they touch the mud.

The world's mud is a box geom named `mud_atlas` that collides with nothing (contype and
conaffinity 0): it detects, it never pushes. Each step, between mj_step1 (the new positions'
kinematics and mass matrix) and mj_step2 (forces and integration), `MudDrag.update` finds
which of course.MUD_LINKS touch the box (a collision geom of the link penetrating it, by
mj_geomDistance; a cheap test of each geom's bounding sphere against the box first), the
mean of their contact points (each the middle of the penetration segment MuJoCo reports),
and the drag of course.mud.implicit_drag for all touching links together, as one ODE step
solved the plugin's joints, moved to each link's centre of mass. sim.body_forces adds `xfrc`
to xfrc_applied for that step only; a link that stops touching feels nothing the next step.

Measured (Atlas, one process, see docs/vrc.md#mud): mj_geomDistance on the six geoms costs
about 3 us each, a private model's kinematics and mj_collision for the same question about
2 times as much, so the geoms are asked directly, and only those whose bounding sphere
reaches the box.
"""

from __future__ import annotations

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


class MudDrag:
    """The mud of one model, and the drag it puts on one MjData each step."""

    def __init__(self, model: mujoco.MjModel, mud_geom: int, damping: float) -> None:
        self.model = model
        self.mud_geom = mud_geom
        self.damping = check_mud_damping(damping)
        self.half_size_m = model.geom_size[mud_geom].copy()
        bodies = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
                  for name in MUD_LINKS]
        #: The links the mud drags, and each one's collision geoms (what can touch the mud).
        self.bodies = np.array([body for body in bodies if body >= 0], dtype=int)
        geoms = [(link, geom) for link, body in enumerate(self.bodies)
                 for geom in range(model.ngeom) if model.geom_bodyid[geom] == body
                 and (model.geom_contype[geom] or model.geom_conaffinity[geom])]
        self.geom_link = np.array([link for link, _ in geoms], dtype=int)
        self.geoms = np.array([geom for _, geom in geoms], dtype=int)
        self.geom_reach_m = model.geom_rbound[self.geoms][:, None] + self.half_size_m[None, :]
        self.xfrc = np.zeros((model.nbody, 6))
        #: The last update's touching links (indices into `bodies`) and their mean contact
        #: points (world, m), for tests and tools.
        self.touching = np.zeros(0, dtype=int)
        self.points_m = np.zeros((0, 3))
        self._fromtos = np.zeros((len(self.geoms), 6))
        self._hits = np.zeros(len(self.geoms), dtype=bool)
        #: (links, geoms): 1 where the geom is the link's.
        self._membership = (self.geom_link[None, :]
                            == np.arange(len(self.bodies))[:, None]).astype(float)
        self._dragging = False
        self._jac = np.zeros((6 * len(self.bodies), model.nv))
        self._mobility = np.zeros_like(self._jac)

    @classmethod
    def for_model(cls, model: mujoco.MjModel, damping: float = MUD_DAMPING) -> MudDrag | None:
        """The mud of `model`, or None when it has no `mud_atlas` box (nothing runs then).

        Raises:
            CourseError: `damping` is not a finite number >= 0.
            ModelError: the model's `mud_atlas` geom is not a box.
        """
        geom = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, MUD_GEOM)
        if geom < 0:
            check_mud_damping(damping)
            return None
        if model.geom_type[geom] != mujoco.mjtGeom.mjGEOM_BOX:
            raise ModelError(f'geom {MUD_GEOM!r} must be a box (the mud volume), it is a '
                             f'{mujoco.mjtGeom(model.geom_type[geom]).name}')
        return cls(model, geom, damping)

    def _contact_points(self, data: mujoco.MjData) -> None:
        """`touching` and `points_m` for the current kinematics."""
        centre = data.geom_xpos[self.mud_geom]
        rotation = data.geom_xmat[self.mud_geom].reshape(3, 3)
        local = (data.geom_xpos[self.geoms] - centre) @ rotation
        near = np.flatnonzero((np.abs(local) <= self.geom_reach_m).all(axis=1))
        hits = self._hits
        hits[:] = False
        fromtos, model, mud = self._fromtos, self.model, self.mud_geom
        for index in near.tolist():
            hits[index] = mujoco.mj_geomDistance(model, data, int(self.geoms[index]), mud,
                                                 0.0, fromtos[index]) < 0.0
        if not hits.any():
            self.touching = self.touching[:0]
            return
        # Each link's mean of its penetrating geoms' points (the middles of their segments).
        counts = self._membership @ hits
        sums = self._membership @ (0.5 * (fromtos[:, 0:3] + fromtos[:, 3:6]) * hits[:, None])
        self.touching = np.flatnonzero(counts)
        self.points_m = sums[self.touching] / counts[self.touching, None]

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

