#!/usr/bin/env python3
"""Generate sim/atlas_v1.xml (MJCF) and sim/atlas_v1.urdf from one table of Atlas v1 figures.

The figures below are typed in from DRCSim 2.5.2's Atlas v1 description
(atlas.urdf for joints, masses and inertias; the simple-shapes URDF for the
primitive collision shapes; multisense_sl.urdf for the `head` link that
neck_ay moves). Keeping them in one table lets the unit tests compare the
compiled MuJoCo model against the same numbers without the reference files.

The URDF (for robot_state_publisher and rviz) has the same links, joints, limits, masses,
inertias, shapes and colours; test/unit/sim/test_urdf.py compares the two, kinematics included.

Usage: python3 tools/make_atlas_mjcf.py [OUTPUT]   (default: sim/atlas_v1.xml; the URDF
       is written beside it, same name, suffix .urdf)
"""

from __future__ import annotations

import sys
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

REPO_ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO_ROOT / 'src'))
from tutorial_atlas_control.joints import JOINT_NAMES  # noqa: E402
from tutorial_atlas_control.sensors.frames import (  # noqa: E402
    HEAD_FRAMES,
    HOKUYO_AXIS,
    HOKUYO_JOINT,
)

DEFAULT_OUTPUT = REPO_ROOT / 'sim' / 'atlas_v1.xml'


@dataclass(frozen=True)
class Link:
    """Rigid-body figures of one URDF link, in the link frame (SI units)."""

    mass_kg: float
    com_m: tuple[float, float, float]
    # URDF order: ixx iyy izz ixy ixz iyz (kg m^2) about the centre of mass.
    inertia: tuple[float, float, float, float, float, float]


@dataclass(frozen=True)
class Joint:
    """One revolute joint: parent/child links, origin in the parent, limits."""

    parent: str
    child: str
    origin_m: tuple[float, float, float]
    axis: tuple[float, float, float]
    lower_rad: float
    upper_rad: float
    effort_nm: float
    velocity_rad_s: float
    damping_nms: float = 0.1


ROOT_LINK = 'pelvis'

LINKS: dict[str, Link] = {
    'pelvis': Link(14.2529, (0.0111, 0, 0.0271),
                   (0.1244, 0.0958, 0.1167, 0.0008, -0.0007, -0.0005)),
    'ltorso': Link(1.92, (-0.0112984, -3.15366e-06, 0.0746835),
                   (0.0039092, 0.00341694, 0.00174492, -5.04491e-08, -0.000342157, 4.87119e-07)),
    'mtorso': Link(0.55, (-0.00816266, -0.0131245, 0.0305974),
                   (0.000454181, 0.000483282, 0.000444215, -6.10764e-05, 3.94009e-05, 5.27463e-05)),
    'utorso': Link(18.484, (0.02, -0.001, 0.211), (0.395, 1.089, 0.327, 0, 0.083, -0.003)),
    # multisense_sl.urdf, first `head` link.
    'head': Link(1.41984, (-0.075493, 3.3383e-05, 0.02774),
                 (0.0036053766, 0.002080106, 0.001782985, -1.5797e-06, -0.00089293, -6.8415e-07)),
    'l_uglut': Link(0.5166, (0.00529262, -0.00344732, 0.00313046),
                    (0.00074276, 0.000688179, 0.00041242, -3.79607e-08, -2.79549e-05, -3.2735e-08)),
    'l_lglut': Link(0.69, (0.0133341, 0.0170484, -0.0312052),
                    (0.000691326, 0.00126856, 0.00106487, -2.24344e-05, 2.50508e-06, 0.000137862)),
    'l_uleg': Link(7.34, (0, 0, -0.21), (0.09, 0.09, 0.02, 0, 0, 0)),
    'l_lleg': Link(4.367, (0.001, 0, -0.187), (0.077, 0.076, 0.01, 0, -0.003, 0)),
    'l_talus': Link(0.1, (0, 0, 0), (1.01674e-05, 8.42775e-06, 1.30101e-05, 0, 0, 0)),
    'l_foot': Link(1.634, (0.027, 0, -0.067), (0.002, 0.007, 0.008, 0, 0, 0)),
    'r_uglut': Link(0.5166, (0.00529262, 0.00344732, 0.00313046),
                    (0.00074276, 0.000688179, 0.00041242, 3.79607e-08, -2.79549e-05, 3.2735e-08)),
    'r_lglut': Link(0.69, (0.0133341, -0.0170484, -0.0312052),
                    (0.000691326, 0.00126856, 0.00106487, 2.24344e-05, 2.50508e-06, -0.000137862)),
    'r_uleg': Link(7.34, (0, 0, -0.21), (0.09, 0.09, 0.02, 0, 0, 0)),
    'r_lleg': Link(4.367, (0.001, 0, -0.187), (0.077, 0.076, 0.01, 0, 0.003, 0)),
    'r_talus': Link(0.1, (0, 0, 0), (1.01674e-05, 8.42775e-06, 1.30101e-05, 0, 0, 0)),
    'r_foot': Link(1.634, (0.027, 0, -0.067), (0.002, 0.007, 0.008, 0, 0, 0)),
    'l_clav': Link(2.369, (0.014, 0.058, 0.029), (0.004, 0.006, 0.007, 0.001, 0, 0)),
    'l_scap': Link(2.707, (-0.002, 0.108, 0), (0.01, 0.005, 0.013, 0, 0, 0)),
    'l_uarm': Link(1.881, (0.007, 0.114, 0.008), (0.002, 0.003, 0.003, 0, 0, 0)),
    'l_larm': Link(2.148, (-0.003, 0.099, -0.014), (0.005, 0.003, 0.006, 0, 0, 0)),
    'l_farm': Link(0.981, (0, 0.041, 0), (0.003, 0.001, 0.003, 0, 0, 0)),
    'l_hand': Link(2.263, (0, 0.093, 0), (0.01, 0.002, 0.01, 0, 0, 0)),
    'r_clav': Link(2.369, (0.014, -0.058, 0.029), (0.004, 0.006, 0.007, -0.001, 0, 0)),
    'r_scap': Link(2.707, (-0.002, -0.108, 0), (0.01, 0.005, 0.013, 0, 0, 0)),
    'r_uarm': Link(1.881, (0.007, -0.114, 0.008), (0.002, 0.003, 0.003, 0, 0, 0)),
    'r_larm': Link(2.148, (-0.003, -0.099, -0.014), (0.005, 0.003, 0.006, 0, 0, 0)),
    'r_farm': Link(0.981, (0, -0.041, 0), (0.003, 0.001, 0.003, 0, 0, 0)),
    'r_hand': Link(2.263, (0, -0.093, 0), (0.01, 0.002, 0.01, 0, 0, 0)),
}

#: Sum of the reference masses (atlas.urdf's 28 links + multisense head), kg.
REFERENCE_TOTAL_MASS_KG = 90.61994

V_MAX = 12.0  # rad/s, the same velocity limit on every joint in atlas.urdf

JOINTS: dict[str, Joint] = {
    'back_lbz': Joint('pelvis', 'ltorso', (-0.0125, 0, 0), (0, 0, 1), -0.610865, 0.610865,
                      124.016, V_MAX),
    'back_mby': Joint('ltorso', 'mtorso', (0, 0, 0.09), (0, 1, 0), -1.2, 1.28, 206.843, V_MAX),
    'back_ubx': Joint('mtorso', 'utorso', (0, 0, 0.05), (1, 0, 0), -0.790809, 0.790809,
                      94.91, V_MAX),
    'neck_ay': Joint('utorso', 'head', (0.16555, 0, 0.50823), (0, 1, 0), -0.610865238, 1.13446401,
                     5, V_MAX),
    'l_leg_uhz': Joint('pelvis', 'l_uglut', (0, 0.089, 0), (0, 0, 1), -0.32, 1.14, 110, V_MAX),
    'l_leg_mhx': Joint('l_uglut', 'l_lglut', (0, 0, 0), (1, 0, 0), -0.47, 0.495, 180, V_MAX),
    'l_leg_lhy': Joint('l_lglut', 'l_uleg', (0.05, 0, -0.05), (0, 1, 0), -1.75, 0.524, 260, V_MAX),
    'l_leg_kny': Joint('l_uleg', 'l_lleg', (-0.05, 0, -0.374), (0, 1, 0), 0, 2.45, 220, V_MAX),
    'l_leg_uay': Joint('l_lleg', 'l_talus', (0, 0, -0.422), (0, 1, 0), -0.698, 0.698, 220, V_MAX),
    'l_leg_lax': Joint('l_talus', 'l_foot', (0, 0, 0), (1, 0, 0), -0.436, 0.436, 90, V_MAX),
    'r_leg_uhz': Joint('pelvis', 'r_uglut', (0, -0.089, 0), (0, 0, 1), -1.14, 0.32, 110, V_MAX),
    'r_leg_mhx': Joint('r_uglut', 'r_lglut', (0, 0, 0), (1, 0, 0), -0.495, 0.47, 180, V_MAX),
    # atlas.urdf really has -1.745 here but -1.75 on the left hip.
    'r_leg_lhy': Joint('r_lglut', 'r_uleg', (0.05, 0, -0.05), (0, 1, 0), -1.745, 0.524, 260, V_MAX),
    'r_leg_kny': Joint('r_uleg', 'r_lleg', (-0.05, 0, -0.374), (0, 1, 0), 0, 2.45, 220, V_MAX),
    'r_leg_uay': Joint('r_lleg', 'r_talus', (0, 0, -0.422), (0, 1, 0), -0.698, 0.698, 220, V_MAX),
    'r_leg_lax': Joint('r_talus', 'r_foot', (0, 0, 0), (1, 0, 0), -0.436, 0.436, 90, V_MAX),
    'l_arm_usy': Joint('utorso', 'l_clav', (0.024, 0.221, 0.289), (0, 0.5, 0.866025),
                       -1.9635, 1.9635, 212, V_MAX),
    'l_arm_shx': Joint('l_clav', 'l_scap', (0, 0.075, 0.036), (1, 0, 0), -1.39626, 1.74533,
                       170, V_MAX),
    'l_arm_ely': Joint('l_scap', 'l_uarm', (0, 0.185, 0), (0, 1, 0), 0, 3.14159, 114, V_MAX),
    'l_arm_elx': Joint('l_uarm', 'l_larm', (0, 0.121, 0.013), (1, 0, 0), 0, 2.35619, 114, V_MAX),
    'l_arm_uwy': Joint('l_larm', 'l_farm', (0, 0.188, -0.013), (0, 1, 0), -1.571, 1.571,
                       114, V_MAX),
    'l_arm_mwx': Joint('l_farm', 'l_hand', (0, 0.058, 0), (1, 0, 0), -0.436, 1.571, 60, V_MAX),
    'r_arm_usy': Joint('utorso', 'r_clav', (0.024, -0.221, 0.289), (0, 0.5, -0.866025),
                       -1.9635, 1.9635, 212, V_MAX),
    'r_arm_shx': Joint('r_clav', 'r_scap', (0, -0.075, 0.036), (1, 0, 0), -1.74533, 1.39626,
                       170, V_MAX),
    'r_arm_ely': Joint('r_scap', 'r_uarm', (0, -0.185, 0), (0, 1, 0), 0, 3.14159, 114, V_MAX),
    'r_arm_elx': Joint('r_uarm', 'r_larm', (0, -0.121, 0.013), (1, 0, 0), -2.35619, 0, 114, V_MAX),
    'r_arm_uwy': Joint('r_larm', 'r_farm', (0, -0.188, -0.013), (0, 1, 0), -1.571, 1.571,
                       114, V_MAX),
    'r_arm_mwx': Joint('r_farm', 'r_hand', (0, -0.058, 0), (1, 0, 0), -1.571, 0.436, 60, V_MAX),
}

# ---------------------------------------------------------------------------
# Collision shapes (simple-shapes URDF; cylinders along their local z).
# ('box', (sx, sy, sz) full sizes) or ('cylinder', (radius, length));
# then origin xyz and URDF rpy (fixed-axis roll, pitch, yaw).
# ---------------------------------------------------------------------------
HALF_PI = 1.5707963267949


def _mirror(shapes: list[tuple]) -> list[tuple]:
    """Right-side copy of left-side shapes: y -> -y, roll -> -roll."""
    out = []
    for kind, size, (x, y, z), (r, p, yaw) in shapes:
        out.append((kind, size, (x, -y, z), (-r, p, -yaw)))
    return out


#: Foot sole: 0.26 x 0.124887 x 0.01 m box, centre 0.048 0 -0.076119 in the foot frame.
SOLE_SIZE_M = (0.26, 0.124887, 0.01)
SOLE_POS_M = (0.048, 0.0, -0.076119)
#: A sphere inside each corner of a sole's bottom face, flush with it, touching heightfields
#: only (a heightfield geom's contype holds HEIGHTFIELD_CONTACT_BIT; the spheres' conaffinity
#: is that bit alone, their contype 0). MuJoCo collides a box with a heightfield prism by
#: prism, one contact each where its penetration search ends: on the VRC course's flat
#: ground a sole bore on 2-4 points near its middle and tipped about them onto its toes.
SOLE_CORNER_RADIUS_M = 0.005
HEIGHTFIELD_CONTACT_BIT = 4

_LEFT_SHAPES: dict[str, list[tuple]] = {
    'l_uglut': [('cylinder', (0.019096, 0.078396), (0, 0, 0), (0, HALF_PI, 0)),
                ('cylinder', (0.019841, 0.080842), (0, 0, 0), (0, 0, 0))],
    'l_lglut': [('cylinder', (0.02009687, 0.060306), (0.049968, 0.022488, -0.0501165),
                 (HALF_PI, 0, 0)),
                ('cylinder', (0.02, 0.12), (0, 0, 0), (0, HALF_PI, 0))],
    'l_uleg': [('cylinder', (0.1, 0.10), (-0.0179, 0.02085, -0.13), (0, 0, 0)),
               ('cylinder', (0.07, 0.15), (-0.03, 0.01, -0.23), (0, -0.3, 0)),
               ('cylinder', (0.07, 0.15), (-0.005, 0.01, -0.23), (0, 0.3, 0)),
               ('cylinder', (0.07, 0.15), (-0.02, 0.03, -0.23), (-0.25, 0, 0))],
    'l_lleg': [('cylinder', (0.06, 0.22), (-0.01, 0.00295, -0.260), (0, -0.06, 0)),
               ('cylinder', (0.06, 0.20), (0.01, 0.00295, -0.07), (0, 0.18, 0))],
    'l_talus': [('cylinder', (0.010181, 0.029542), (0, 0, 0), (0, HALF_PI, 0)),
                ('cylinder', (0.010348, 0.010059), (0, 0, 0), (HALF_PI, 0, 0))],
    'l_foot': [('box', SOLE_SIZE_M, SOLE_POS_M, (0, 0, 0))],
    'l_clav': [('cylinder', (0.045, 0.1525), (0, 0.0744, 0.03657), (0, HALF_PI, 0)),
               ('cylinder', (0.04, 0.027), (0, 0.012, 0.012), (-0.5236, 0, 0))],
    'l_scap': [('cylinder', (0.0418405, 0.137492), (0, 0.118521, 0), (HALF_PI, 0, 0)),
               ('cylinder', (0.048709, 0.013937), (-0.0884125, 0, 0), (0, HALF_PI, 0)),
               ('cylinder', (0.048709, 0.013737), (0.0847565, 0, 0), (0, HALF_PI, 0))],
    'l_uarm': [('cylinder', (0.0449, 0.116677), (0, 0.0583385, 0), (HALF_PI, 0, 0)),
               ('cylinder', (0.04504847, 0.088934), (0, 0.1205235, 0.00912975), (0, HALF_PI, 0))],
    'l_larm': [('cylinder', (0.045, 0.0161), (0.056065, 0, 0), (0, HALF_PI, 0)),
               ('cylinder', (0.045, 0.0161), (-0.0556155, 0, 0), (0, HALF_PI, 0)),
               ('cylinder', (0.044, 0.188105), (0, 0.0940525, -0.01), (HALF_PI, 0, 0))],
    'l_farm': [('cylinder', (0.0458825, 0.035181), (0, 0.0174215, 0), (HALF_PI, 0, 0)),
               ('cylinder', (0.0279, 0.050472), (0.000226, 0.06028, 0.0), (0, HALF_PI, 0))],
    'l_hand': [('cylinder', (0.035939, 0.055117), (0, 0.0526955, 0.0), (HALF_PI, 0, 0)),
               ('cylinder', (0.035939, 0.019), (0.034375, 0.002643, 0), (0, HALF_PI, 0)),
               ('cylinder', (0.035939, 0.019), (-0.0365945, 0.002643, 0), (0, HALF_PI, 0))],
}

COLLISION_SHAPES: dict[str, list[tuple]] = {
    'pelvis': [('cylinder', (0.092, 0.03), (0.046, 0.0, -0.02), (HALF_PI, 0, 0)),
               ('cylinder', (0.092, 0.03), (-0.03, 0.0, -0.02), (HALF_PI, 0, 0)),
               ('cylinder', (0.130, 0.022), (0, 0.042, 0.06), (0, 0, 0)),
               ('cylinder', (0.130, 0.022), (0, -0.042, 0.06), (0, 0, 0))],
    # ltorso's shapes are commented out in the simple-shapes URDF ("completely internal").
    'mtorso': [('cylinder', (0.017, 0.03), (0, 0, 0), (HALF_PI, 0, 0)),
               ('cylinder', (0.015, 0.02), (0.0285, 0, 0.05), (0, HALF_PI, 0)),
               ('cylinder', (0.015, 0.02), (-0.0285, 0, 0.05), (0, HALF_PI, 0))],
    'utorso': [('box', (0.3188, 0.24, 0.3162), (0.0446, 0, 0.1869), (0, 0, 0)),
               ('cylinder', (0.0363, 0.22375), (0.024, 0.16, 0.18), (-0.5236, 0, 0)),
               ('cylinder', (0.0363, 0.22375), (0.024, -0.16, 0.18), (0.5236, 0, 0))],
    'head': [('box', (0.1311, 0.12, 0.0591), (-0.0503, 0, -0.00195), (0, 0, 0)),
             ('box', (0.0468, 0.12, 0.1184), (-0.093, 0, 0.0868), (0, 0, 0))],
}
COLLISION_SHAPES.update(_LEFT_SHAPES)
COLLISION_SHAPES.update({'r' + name[1:]: _mirror(shapes) for name, shapes in _LEFT_SHAPES.items()})

# ---------------------------------------------------------------------------
# Simulation tunables (see the comments written into the XML).
# ---------------------------------------------------------------------------
TIMESTEP_S = 0.001
ARMATURE_KGM2 = 0.0
FOOT_FRICTION = (1.0, 0.02, 0.0001)  # sliding, torsional (m), rolling (m)
FOOT_CONDIM = 6
FLOOR_FRICTION = (1.0, 0.02, 0.0001)
CONTACT_SOLREF = (0.005, 1.0)  # time constant (s), damping ratio
CONTACT_SOLIMP = (0.95, 0.99, 0.001, 0.5, 2)
PIN_SOLREF = (2 * TIMESTEP_S, 1.0)
PIN_SOLIMP = (0.99, 0.999, 0.0001)

#: Pelvis height at which both sole boxes touch z = 0 with every joint at 0:
#: hip pitch origin 0.05 + knee 0.374 + ankle 0.422 + sole 0.076119 + 0.005.
SPAWN_HEIGHT_M = 0.05 + 0.374 + 0.422 + 0.076119 + SOLE_SIZE_M[2] / 2

#: Two reference inertias are physically impossible (principal moments break
#: A + B >= C): utorso (atlas.urdf) and head (multisense_sl.urdf). ODE took
#: them; MuJoCo refuses. The fix lowers the largest principal moment to
#: (A + B) / (1 + TRIANGLE_SLACK), keeping the principal axes and the other
#: two moments: the smallest change that makes the body physical.
TRIANGLE_SLACK = 1e-4


def inertia_matrix(inertia: tuple[float, ...]) -> np.ndarray:
    """3x3 matrix from URDF-ordered (ixx, iyy, izz, ixy, ixz, iyz)."""
    ixx, iyy, izz, ixy, ixz, iyz = inertia
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])


def corrected_inertia(inertia: tuple[float, ...]) -> tuple[tuple[float, ...], bool]:
    """Return (inertia, changed), made to satisfy the triangle inequality."""
    eig, axes = np.linalg.eigh(inertia_matrix(inertia))  # ascending
    if eig[0] + eig[1] >= eig[2]:
        return tuple(inertia), False
    eig = eig.copy()
    eig[2] = (eig[0] + eig[1]) / (1 + TRIANGLE_SLACK)
    mat = axes @ np.diag(eig) @ axes.T
    fixed = (mat[0, 0], mat[1, 1], mat[2, 2], mat[0, 1], mat[0, 2], mat[1, 2])
    return tuple(float(np.round(v, 9)) for v in fixed), True


def rpy_to_quat(rpy: tuple[float, float, float]) -> np.ndarray:
    """URDF fixed-axis roll-pitch-yaw to a MuJoCo (w, x, y, z) quaternion."""
    r, p, y = (0.5 * a for a in rpy)
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array([cr * cp * cy + sr * sp * sy,
                     sr * cp * cy - cr * sp * sy,
                     cr * sp * cy + sr * cp * sy,
                     cr * cp * sy - sr * sp * cy])


def fmt(values: Iterable[float]) -> str:
    """Space-separated shortest repr of floats (repr round-trips exactly)."""
    return ' '.join(repr(float(v)) if float(v) != int(v) else str(int(v)) for v in values)


# Colours: DRCSim's Atlas was dark grey with orange accents. Name -> (rgba, specular);
# the MJCF's materials and the URDF's <material> colours both come from here.
MATERIALS: dict[str, tuple[tuple[float, float, float, float], float]] = {
    'grey': ((0.45, 0.46, 0.48, 1), 0.3),
    'dark': ((0.18, 0.18, 0.2, 1), 0.2),
    'blue': ((0.2, 0.3, 0.55, 1), 0.3),
    'orange': ((0.91, 0.44, 0.03, 1), 0.3),
}
LINK_MATERIAL = {
    'pelvis': 'grey', 'ltorso': 'dark', 'mtorso': 'dark', 'utorso': 'grey', 'head': 'orange',
}
for _side in 'lr':
    LINK_MATERIAL.update({f'{_side}_{n}': 'grey'
                          for n in ('uglut', 'lglut', 'clav', 'scap', 'farm')})
    LINK_MATERIAL.update({f'{_side}_{n}': 'blue' for n in ('uleg', 'lleg', 'uarm', 'larm')})
    LINK_MATERIAL.update({f'{_side}_{n}': 'dark' for n in ('talus', 'foot', 'hand')})


def children_of(link: str) -> list[tuple[str, Joint]]:
    """Joints whose parent is `link`, in the tutorial order."""
    return [(name, JOINTS[name]) for name in JOINT_NAMES if JOINTS[name].parent == link]


@dataclass(frozen=True)
class VisualShape:
    """A visual-only shape in MJCF terms (box half sizes; capsule radius and fromto).

    The figures are kept as the MJCF text they are written as; the URDF writer parses them.
    """

    kind: str        # 'box' or 'capsule'
    material: str
    size: str
    pos: str = ''
    fromto: str = ''

    def mjcf_attributes(self) -> str:
        place = f'pos="{self.pos}"' if self.pos else f'fromto="{self.fromto}"'
        return f'type="{self.kind}" size="{self.size}" {place}'


def visual_shapes(link: str) -> list[VisualShape]:
    """Extra visual-only shapes so the primitive robot reads as a humanoid."""
    sign = 1.0 if link[0] == 'l' else -1.0
    mat = LINK_MATERIAL[link]
    if link == 'pelvis':
        return [VisualShape('box', mat, '0.09 0.13 0.06', pos='0.0 0 0.02')]
    if link == 'utorso':
        return [VisualShape('box', mat, '0.13 0.17 0.14', pos='0.02 0 0.22'),
                VisualShape('capsule', mat, '0.05', fromto='0.02 -0.12 0.32 0.02 0.12 0.32'),
                VisualShape('capsule', mat, '0.035', fromto='0.07 0 0.34 0.15 0 0.49')]  # neck
    if link == 'ltorso':
        return [VisualShape('capsule', mat, '0.06', fromto='0 0 0.04 0 0 0.14')]  # waist
    if link == 'head':
        return [VisualShape('box', 'dark', '0.02 0.055 0.035', pos='0.01 0 0.0')]
    if link.endswith('uleg'):
        return [VisualShape('capsule', mat, '0.065', fromto='0 0 -0.06 -0.05 0 -0.374')]
    if link.endswith('lleg'):
        return [VisualShape('capsule', mat, '0.05', fromto='0 0 0 0 0 -0.40')]
    if link.endswith('uarm'):
        return [VisualShape('capsule', mat, '0.042', fromto=f'0 0 0 0 {sign * 0.121:.3f} 0.013')]
    if link.endswith('hand'):
        return [VisualShape('box', mat, '0.035 0.05 0.015', pos=f'0 {sign * 0.12:.3f} 0')]
    if link.endswith('foot'):
        return [VisualShape('box', mat, '0.1 0.05 0.03', pos='0.04 0 -0.045')]
    return []


def visual_geoms(link: str, indent: str) -> list[str]:
    """MJCF <geom> lines of the link's visual shapes."""
    return [f'{indent}<geom class="visual" material="{shape.material}" {shape.mjcf_attributes()}/>'
            for shape in visual_shapes(link)]


def body_xml(name: str, joint_name: str | None, depth: int) -> list[str]:
    """Nested <body> elements for `name` and its subtree."""
    ind = '  ' * depth
    inner = ind + '  '
    link = LINKS[name]
    lines: list[str] = []
    if joint_name is None:
        lines.append(f'{ind}<body name="{name}" pos="0 0 {SPAWN_HEIGHT_M!r}" childclass="atlas">')
        lines.append(f'{inner}<freejoint name="pelvis_free"/>')
    else:
        joint = JOINTS[joint_name]
        lines.append(f'{ind}<body name="{name}" pos="{fmt(joint.origin_m)}">')
        lines.append(f'{inner}<joint name="{joint_name}" axis="{fmt(joint.axis)}" '
                     f'range="{fmt((joint.lower_rad, joint.upper_rad))}" '
                     f'user="{fmt((joint.effort_nm, joint.velocity_rad_s))}"/>')
    inertia, changed = corrected_inertia(link.inertia)
    if changed:
        lines.append(f'{inner}<!-- reference inertia {fmt(link.inertia)} is not physical '
                     '(A + B < C); largest principal moment lowered to A + B, '
                     'see tools/make_atlas_mjcf.py -->')
    ixx, iyy, izz, ixy, ixz, iyz = inertia
    lines.append(f'{inner}<inertial pos="{fmt(link.com_m)}" mass="{link.mass_kg!r}" '
                 f'fullinertia="{fmt((ixx, iyy, izz, ixy, ixz, iyz))}"/>')
    if name == 'pelvis':
        lines.append(f'{inner}<site name="imu" size="0.01"/>')
        lines.append(f'{inner}<!-- follows the robot\'s centre of mass from its front-right -->')
        lines.append(f'{inner}<camera name="track" mode="trackcom" '
                     f'pos="{fmt(TRACK_CAMERA_OFFSET_M)}" '
                     f'xyaxes="{camera_xyaxes(TRACK_CAMERA_OFFSET_M, np.zeros(3))}" fovy="45"/>')
    if name.endswith('_foot'):
        lines.append(f'{inner}<site name="{name}_ft" size="0.01"/>')
    for index, (kind, size, pos, rpy) in enumerate(COLLISION_SHAPES.get(name, [])):
        extra = ' class="sole"' if name.endswith('_foot') else ''
        geom_name = f'{name}_sole' if name.endswith('_foot') else f'{name}_c{index}'
        size_text = (fmt(s / 2 for s in size) if kind == 'box'
                     else fmt((size[0], size[1] / 2)))
        quat = '' if not any(rpy) else f' quat="{fmt(np.round(rpy_to_quat(rpy), 9))}"'
        lines.append(f'{inner}<geom name="{geom_name}"{extra} type="{kind}" size="{size_text}" '
                     f'pos="{fmt(pos)}"{quat} material="{LINK_MATERIAL[name]}"/>')
    if name.endswith('_foot'):
        lines.extend(sole_corner_geoms(name, inner))
    lines.extend(visual_geoms(name, inner))
    for child_joint, joint in children_of(name):
        lines.extend(body_xml(joint.child, child_joint, depth + 1))
    lines.append(f'{ind}</body>')
    return lines


def sole_corner_geoms(foot: str, indent: str) -> list[str]:
    """The sole's four corner spheres (SOLE_CORNER_RADIUS_M), each inside its corner of the
    box and flush with its bottom face: front left, front right, back left, back right."""
    half_x, half_y, half_z = (size / 2 for size in SOLE_SIZE_M)
    radius = SOLE_CORNER_RADIUS_M
    z = SOLE_POS_M[2] - half_z + radius
    lines = []
    for index, (along, across) in enumerate(((1, 1), (1, -1), (-1, 1), (-1, -1))):
        pos = (round(SOLE_POS_M[0] + along * (half_x - radius), 9),
               round(SOLE_POS_M[1] + across * (half_y - radius), 9), round(z, 9))
        lines.append(f'{indent}<geom name="{foot}_sole_corner{index}" class="sole_corner" '
                     f'type="sphere" size="{fmt((radius,))}" pos="{fmt(pos)}"/>')
    return lines


def camera_xyaxes(position: np.ndarray, target: np.ndarray) -> str:
    """xyaxes of a camera at `position` looking at `target`, z up."""
    forward = (target - position) / np.linalg.norm(target - position)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    return fmt(np.round(np.concatenate([right, up]), 6))


#: m from the pelvis: in front, to the robot's right.
TRACK_CAMERA_OFFSET_M = np.array([2.4, -2.4, 0.35])


def build() -> str:
    """Return the complete MJCF text."""
    body_lines = body_xml(ROOT_LINK, None, 2)
    actuator_lines = [f'    <motor name="{n}" joint="{n}" gear="1"/>' for n in JOINT_NAMES]
    material_lines = [f'    <material name="{name}" rgba="{fmt(rgba)}" specular="{specular}"/>'
                      for name, (rgba, specular) in MATERIALS.items()]
    floor_contact = (f'friction="{fmt(FLOOR_FRICTION)}" solref="{fmt(CONTACT_SOLREF)}" '
                     f'solimp="{fmt(CONTACT_SOLIMP)}"')
    pin_contact = f'solref="{fmt(PIN_SOLREF)}" solimp="{fmt(PIN_SOLIMP)}"'
    return f'''<!--
  Atlas v1 (DRCSim 2.5.2) for MuJoCo. GENERATED by tools/make_atlas_mjcf.py from
  its table of figures; edit the table, then run:  python3 tools/make_atlas_mjcf.py

  Figures: joints, masses, inertias, limits and damping from DRCSim's atlas.urdf;
  collision primitives from its simple-shapes URDF; the `head` link moved by
  neck_ay from multisense_sl.urdf (first `head` entry). Left out: the MultiSense
  hokuyo_link (0.058 kg spinning lidar on a joint the tutorial never commands)
  and the massless camera frames. Total mass {REFERENCE_TOTAL_MASS_KG} kg.
  Deviation: utorso's and head's inertias are not physical in the reference;
  their largest principal moment is lowered (comments at those bodies).

  Conventions:
  * Body frames coincide with the URDF joint frames (all joint rpy are 0).
  * Effort limits are enforced in ONE place: the controller law
    (tutorial_atlas_control.controller.compute_torque) clamps each torque to
    the joint's effort limit, so the motors below have no ctrlrange.
  * Each joint's user="effort velocity" holds its effort limit (N m) and
    velocity limit (rad/s). The velocity limits are data only, exposed by
    tutorial_atlas_control.model; like DRCSim v1's AtlasPlugin, nothing
    enforces them.
  * Actuators are declared in the tutorial's joint order: data.ctrl[i] is the
    torque (N m) of joints.JOINT_NAMES[i].
  * No self-collisions (robot geoms: contype 1, conaffinity 0), as Gazebo's
    default self_collide=false for the DRCSim Atlas model.
-->
<mujoco model="atlas_v1">
  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>

  <!-- 1 kHz like DRCSim. implicitfast integrates the joint damping implicitly
       (unconditionally stable damping, no armature needed); the controller
       law's PD torque is explicit, as in DRCSim. Elliptic friction cones:
       half the foot slide of pyramidal ones in the 30 s standing test. -->
  <option timestep="{TIMESTEP_S}" integrator="implicitfast" cone="elliptic"/>

  <!-- joint user data: [effort limit (N m), velocity limit (rad/s)] from atlas.urdf -->
  <size memory="16M" nuser_jnt="2"/>

  <visual>
    <global offwidth="1920" offheight="1080" azimuth="135" elevation="-15"/>
    <quality shadowsize="4096"/>
    <headlight ambient="0.35 0.35 0.35" diffuse="0.5 0.5 0.5" specular="0.1 0.1 0.1"/>
  </visual>

  <asset>
    <texture name="sky" type="skybox" builtin="gradient" rgb1="0.55 0.7 0.9" rgb2="0.1 0.15 0.25"
             width="512" height="512"/>
    <texture name="checker" type="2d" builtin="checker" rgb1="0.32 0.34 0.36" rgb2="0.22 0.24 0.26"
             width="512" height="512" mark="edge" markrgb="0.5 0.5 0.5"/>
    <material name="floor" texture="checker" texrepeat="1 1" texuniform="true" reflectance="0.1"/>
{chr(10).join(material_lines)}
  </asset>

  <default>
    <default class="atlas">
      <!-- damping from atlas.urdf; armature {ARMATURE_KGM2} kg m^2: none needed,
           the robot stands 30 s under DRCSim's gains without it. -->
      <joint type="hinge" damping="0.1" armature="{ARMATURE_KGM2}" limited="true"/>
      <!-- collision geoms: touch the world, never each other. Contacts: 5 ms
           time constant, critically damped, impedance 0.95-0.99 over 1 mm:
           standing, the 90.6 kg robot sinks 0.4 mm (pelvis -0.6 mm, feet slide
           0.15 mm in 30 s); MuJoCo's default 20 ms/0.9-0.95 sinks 1.2 mm
           (pelvis -1.4 mm, slide 0.24 mm). -->
      <geom contype="1" conaffinity="0" group="0" friction="1 0.005 0.0001"
            solref="{fmt(CONTACT_SOLREF)}" solimp="{fmt(CONTACT_SOLIMP)}"/>
      <default class="sole">
        <!-- Flat Atlas sole (4 box-plane contacts per foot). condim 6 adds
             torsional/rolling friction, so a foot pivoting on an edge cannot
             spin freely about the weakly held hip yaw (p = 5). Standing drift
             is the same with condim 3; pyramidal cones doubled the slide. -->
        <geom condim="{FOOT_CONDIM}" friction="{fmt(FOOT_FRICTION)}" priority="1"/>
      </default>
      <default class="sole_corner">
        <!-- A sphere in each corner of a sole, flush with its bottom face, touching
             heightfields only (their contype holds bit {HEIGHTFIELD_CONTACT_BIT}): MuJoCo
             collides a box with a heightfield one contact a prism, wherever its
             penetration search ends, and a flat sole on the VRC course bore on a few
             points near its middle. Massless, in a group nothing draws and no ray
             sees (inside the box); on planes and boxes the box alone touches. -->
        <geom contype="0" conaffinity="{HEIGHTFIELD_CONTACT_BIT}" condim="{FOOT_CONDIM}"
              friction="{fmt(FOOT_FRICTION)}" priority="1" mass="0" group="4"/>
      </default>
      <default class="visual">
        <geom contype="0" conaffinity="0" group="1" mass="0"/>
      </default>
      <site group="4" rgba="1 0 0 1"/>
    </default>
  </default>

  <worldbody>
    <light name="sun" directional="true" pos="0 0 5" dir="-0.3 0.4 -1" diffuse="0.7 0.7 0.7"
           castshadow="true"/>
    <geom name="floor" type="plane" size="0 0 0.05" material="floor" condim="3"
          {floor_contact}/>
{chr(10).join(body_lines)}
  </worldbody>

  <equality>
    <!-- DRCSim pinned the pelvis to the world for time_to_unpin seconds.
         Inactive here; model.set_pelvis_pinned() switches data.eq_active.
         No relpose: MuJoCo takes it from qpos0, i.e. the spawn pose above,
         so activating it at the initial state applies no jump.
         Stiff (time constant 2 timesteps, the shortest MuJoCo allows,
         impedance 0.99-0.999) like DRCSim's rigid pin: a limp robot hanging
         from it moves the pelvis < 0.2 mm; the default soft weld let it
         drift 19 cm. -->
    <weld name="pelvis_pin" body1="pelvis" active="false" {pin_contact}/>
  </equality>

  <actuator>
    <!-- tutorial order, gear 1: ctrl is joint torque in N m; no ctrlrange
         because the controller law is the one place that clamps effort. -->
{chr(10).join(actuator_lines)}
  </actuator>

  <sensor>
    <framequat name="imu_orientation" objtype="site" objname="imu"/>
    <gyro name="imu_angular_velocity" site="imu"/>
    <accelerometer name="imu_linear_acceleration" site="imu"/>
    <!-- ankle force/torque: at the l_leg_lax / r_leg_lax joint origin, in the foot frame -->
    <force name="l_foot_force" site="l_foot_ft"/>
    <torque name="l_foot_torque" site="l_foot_ft"/>
    <force name="r_foot_force" site="r_foot_ft"/>
    <torque name="r_foot_torque" site="r_foot_ft"/>
  </sensor>
</mujoco>
'''


# ---------------------------------------------------------------------------
# URDF: the same links, joints, inertias and shapes, for robot_state_publisher and rviz.
# ---------------------------------------------------------------------------


def _floats(text: str) -> np.ndarray:
    return np.array([float(v) for v in text.split()])


def _z_to_direction_rpy(direction: np.ndarray) -> tuple[float, float, float]:
    """URDF rpy turning a shape's local z axis (cylinders) onto `direction`."""
    dx, dy, dz = direction / np.linalg.norm(direction)
    return 0.0, float(np.arctan2(np.hypot(dx, dy), dz)), float(np.arctan2(dy, dx))


def _urdf_visual(geometry: str, xyz: Iterable[float], rpy: Iterable[float],
                 material: str) -> list[str]:
    return ['    <visual>',
            f'      <origin xyz="{fmt(xyz)}" rpy="{fmt(rpy)}"/>',
            f'      <geometry>{geometry}</geometry>',
            f'      <material name="{material}"/>',
            '    </visual>']


def _urdf_shape_visuals(shape: VisualShape) -> list[str]:
    """A visual shape as URDF visuals; a capsule (no URDF primitive): a cylinder, two spheres."""
    if shape.kind == 'box':
        size = fmt(2 * _floats(shape.size))
        return _urdf_visual(f'<box size="{size}"/>', _floats(shape.pos), (0, 0, 0), shape.material)
    radius = float(shape.size)
    ends = _floats(shape.fromto).reshape(2, 3)
    axis = ends[1] - ends[0]
    length = np.round(np.linalg.norm(axis), 9)
    lines = _urdf_visual(f'<cylinder radius="{fmt([radius])}" length="{fmt([length])}"/>',
                         np.round(ends.mean(axis=0), 9), np.round(_z_to_direction_rpy(axis), 9),
                         shape.material)
    for end in ends:
        lines += _urdf_visual(f'<sphere radius="{fmt([radius])}"/>', end, (0, 0, 0), shape.material)
    return lines


def _urdf_collision_geometry(kind: str, size: tuple) -> str:
    if kind == 'box':
        return f'<box size="{fmt(size)}"/>'
    return f'<cylinder radius="{fmt(size[:1])}" length="{fmt(size[1:])}"/>'


def link_urdf(name: str) -> list[str]:
    """One <link>: inertial (as the MJCF's, corrected where the reference is not physical),
    the collision shapes drawn and colliding, and the visual-only shapes drawn."""
    link = LINKS[name]
    inertia, changed = corrected_inertia(link.inertia)
    ixx, iyy, izz, ixy, ixz, iyz = inertia
    lines = [f'  <link name="{name}">', '    <inertial>']
    if changed:
        lines.append(f'      <!-- reference inertia {fmt(link.inertia)} is not physical '
                     '(A + B < C); largest principal moment lowered to A + B, as in the MJCF -->')
    lines += [f'      <origin xyz="{fmt(link.com_m)}" rpy="0 0 0"/>',
              f'      <mass value="{link.mass_kg!r}"/>',
              f'      <inertia ixx="{ixx!r}" ixy="{ixy!r}" ixz="{ixz!r}" '
              f'iyy="{iyy!r}" iyz="{iyz!r}" '
              f'izz="{izz!r}"/>',
              '    </inertial>']
    for kind, size, pos, rpy in COLLISION_SHAPES.get(name, []):
        lines += _urdf_visual(_urdf_collision_geometry(kind, size), pos, rpy, LINK_MATERIAL[name])
    for shape in visual_shapes(name):
        lines += _urdf_shape_visuals(shape)
    for kind, size, pos, rpy in COLLISION_SHAPES.get(name, []):
        lines += ['    <collision>',
                  f'      <origin xyz="{fmt(pos)}" rpy="{fmt(rpy)}"/>',
                  f'      <geometry>{_urdf_collision_geometry(kind, size)}</geometry>',
                  '    </collision>']
    lines.append('  </link>')
    return lines


def joint_urdf(name: str) -> list[str]:
    joint = JOINTS[name]
    return [f'  <joint name="{name}" type="revolute">',
            f'    <parent link="{joint.parent}"/>',
            f'    <child link="{joint.child}"/>',
            f'    <origin xyz="{fmt(joint.origin_m)}" rpy="0 0 0"/>',
            f'    <axis xyz="{fmt(joint.axis)}"/>',
            f'    <limit lower="{joint.lower_rad!r}" upper="{joint.upper_rad!r}" '
            f'effort="{joint.effort_nm!r}" velocity="{joint.velocity_rad_s!r}"/>',
            f'    <dynamics damping="{joint.damping_nms!r}"/>',
            '  </joint>']


def _tree_order(link: str) -> list[tuple[str, str | None]]:
    """(link, joint into it) depth first, the order of the MJCF's nested bodies."""
    order: list[tuple[str, str | None]] = [(link, None)] if link == ROOT_LINK else []
    for joint_name, joint in children_of(link):
        order.append((joint.child, joint_name))
        order.extend(_tree_order(joint.child))
    return order


def sensor_frames_urdf() -> list[str]:
    """The head's sensor frames (sensors/frames.py, multisense_sl.urdf's numbers): the laser's
    spindle (continuous hokuyo_joint) and the fixed frames the scan, the cameras and the IMU
    are stamped in. Frames only, no bodies: the model turns the spindle without a body, so
    these links have no inertia and the simulator publishes them from the URDF (/tf_static)
    and from /multisense_sl/joint_states."""
    lines = [f'  <joint name="{HOKUYO_JOINT.joint}" type="continuous">',
             f'    <parent link="{HOKUYO_JOINT.parent}"/>',
             f'    <child link="{HOKUYO_JOINT.child}"/>',
             f'    <origin xyz="{fmt(HOKUYO_JOINT.xyz_m)}" rpy="{fmt(HOKUYO_JOINT.rpy_rad)}"/>',
             f'    <axis xyz="{fmt(HOKUYO_AXIS)}"/>',
             '  </joint>',
             f'  <link name="{HOKUYO_JOINT.child}"/>']
    for frame in HEAD_FRAMES:
        lines += [f'  <joint name="{frame.joint}" type="fixed">',
                  f'    <parent link="{frame.parent}"/>',
                  f'    <child link="{frame.child}"/>',
                  f'    <origin xyz="{fmt(frame.xyz_m)}" rpy="{fmt(frame.rpy_rad)}"/>',
                  '  </joint>',
                  f'  <link name="{frame.child}"/>']
    return lines


def build_urdf() -> str:
    """Return the URDF text: the MJCF's robot, for robot_state_publisher and rviz."""
    lines = ['<?xml version="1.0"?>',
             '<!--',
             '  Atlas v1 (DRCSim 2.5.2) as URDF. '
             'GENERATED by tools/make_atlas_mjcf.py from the same',
             '  table as sim/atlas_v1.xml '
             '(links, joints, limits, masses, inertias, shapes, colours);',
             '  edit the table, then run:  python3 tools/make_atlas_mjcf.py',
             '  The root link is pelvis; the simulator broadcasts world -> pelvis on /tf.',
             '  Capsules (no URDF primitive) are drawn as a cylinder with a sphere at each end.',
             '  Below `head`, the MultiSense SL head\'s sensor frames (sensors/frames.py): frames',
             '  only, not bodies of the model.',
             '-->',
             '<robot name="atlas">']
    for name, (rgba, _specular) in MATERIALS.items():
        lines.append(f'  <material name="{name}"><color rgba="{fmt(rgba)}"/></material>')
    for link, joint_name in _tree_order(ROOT_LINK):
        if joint_name is not None:
            lines += joint_urdf(joint_name)
        lines += link_urdf(link)
    lines += sensor_frames_urdf()
    lines.append('</robot>')
    return '\n'.join(lines) + '\n'


def main() -> int:
    """Write the MJCF file and the URDF beside it; argv[1] overrides the MJCF path
    (the URDF gets the same name with the suffix .urdf)."""
    output = Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT_OUTPUT
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(build())
    print(f'wrote {output}')
    urdf_output = output.with_suffix('.urdf')
    urdf_output.write_text(build_urdf())
    print(f'wrote {urdf_output}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
