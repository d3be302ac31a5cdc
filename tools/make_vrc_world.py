#!/usr/bin/env python3
"""Generate sim/vrc_task_2.xml: DRCSim's VRC Task 2 course with the VRC's Atlas in it.

The robot is sim/atlas_v1.xml's (tools/make_atlas_mjcf.py's table, its joints, actuators,
sensors and `pelvis_pin` weld unchanged) dressed as DRCSim's `atlas_sandia_hands`: a rigid
Sandia hand on each wrist and the multisense_sl head's Hokuyo link held fixed. The course
comes from the project's description of it (tutorial_atlas_control/course/vrc_task_2.py):
the terrain heightfield, the start pen, the five gates, the mud box and the pit's floor,
the 30 loose cinder blocks. docs/vrc.md says what is modelled and what is left out.

The terrain's elevation is sim/vrc_task_2_terrain.png, derived once from DRCSim's
heightmap PNG (`--heightmap PATH`): an 8-bit grey image of the same grey levels, which
MuJoCo loads directly and normalises between its darkest (0) and brightest (250) pixels,
as Gazebo scaled (docs/vrc.md).

Usage: python3 tools/make_vrc_world.py [--heightmap DRCSIM_PNG] [OUTPUT]
       (default OUTPUT sim/vrc_task_2.xml; the terrain image is written beside it when
       --heightmap is given, else read from there)
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import sys
import xml.etree.ElementTree as ET
from pathlib import Path
from types import ModuleType

import numpy as np
from PIL import Image

REPO_ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO_ROOT / 'src'))
from tutorial_atlas_control.course import starts as course_starts  # noqa: E402
from tutorial_atlas_control.course import vrc_task_2 as course  # noqa: E402
from tutorial_atlas_control.sensors.frames import HOKUYO_JOINT, HOKUYO_LINK  # noqa: E402


def _atlas_table() -> ModuleType:
    """tools/make_atlas_mjcf.py as a module: the robot's MJCF and its helpers."""
    if 'make_atlas_mjcf' in sys.modules:  # the tests' copy (test/support/model_table.py)
        return sys.modules['make_atlas_mjcf']
    spec = importlib.util.spec_from_file_location('make_atlas_mjcf',
                                                  REPO_ROOT / 'tools' / 'make_atlas_mjcf.py')
    module = importlib.util.module_from_spec(spec)
    assert spec.loader is not None
    sys.modules['make_atlas_mjcf'] = module  # its dataclasses look it up
    spec.loader.exec_module(module)
    return module


ATLAS = _atlas_table()
fmt = ATLAS.fmt

DEFAULT_OUTPUT = REPO_ROOT / 'sim' / 'vrc_task_2.xml'
TERRAIN_FILE = course_starts.TERRAIN_FILE
#: The heightfield's solid base below its lowest point (m): deeper than a foot can press.
TERRAIN_BASE_M = 0.2
#: The course's contact priority: above the soles' 1, so that the course's geoms' friction,
#: condim and contact softness are the contact's (see docs/vrc.md, friction).
COURSE_PRIORITY = 2
#: The soles' torsional and rolling friction (m), kept on every course contact.
SOLE_SPIN_ROLL = ATLAS.FOOT_FRICTION[1:]
#: A block starts this far (m) above the highest ground under it, and falls into place.
BLOCK_CLEARANCE_M = 0.002

# ---------------------------------------------------------------------------
# The VRC robot's additions (DRCSim's sandia_hand.urdf.xacro and multisense_sl.urdf).
# ---------------------------------------------------------------------------
#: The palm, 0.1 m out along the hand link's axis (+y left, -y right), its x axis outwards.
HAND_MOUNT_M = 0.1
PALM_MASS_KG = 1.303
PALM_INERTIA = 0.001303  # a solid 5 cm sphere's, each axis (kg m²)
#: One finger's links straight (joint angles 0), in its base frame: (mass kg, x m, inertia
#: diag kg m²); base 0.25 kg, three phalanges and three 10 g accelerometer links.
FINGER_LINKS: tuple[tuple[float, float, tuple[float, float, float]], ...] = (
    (0.25, 0.0, (1e-5, 1e-5, 1e-5)),                          # f<i>_base
    (0.01, -0.05, (1e-6, 1e-6, 1e-6)),                        # f<i>_fixed_accel
    (0.106, 0.0, (1.1925e-5, 1.1505e-4, 1.1505e-4)),          # f<i>_0
    (0.033, 0.028, (1.65e-6, 1.316975e-5, 1.316975e-5)),      # f<i>_1 (turned about x)
    (0.01, 0.058, (1e-6, 1e-6, 1e-6)),                        # f<i>_1_accel
    (0.033, 0.078, (1.3365e-6, 9.603e-6, 9.603e-6)),          # f<i>_2
    (0.01, 0.118, (1e-6, 1e-6, 1e-6)),                        # f<i>_2_accel
)
#: Where the fingers' bases sit on the palm: (x, y, z, pitch, yaw) for the left hand
#: (reflect 1; the right hand mirrors y and yaw). Finger 3 is the thumb.
FINGER_MOUNTS: tuple[tuple[float, float, float, float, float], ...] = (
    (0.14, 0.0, 0.0, 0.0, -0.3),
    (0.115, -0.03122, 0.0, 0.0, -0.3),
    (0.09, -0.06245, 0.0, 0.0, -0.3),
    (0.03995, 0.04383, 0.014, -math.pi / 2, -2.3562),
)
#: multisense_sl's hokuyo_link on `head` (hokuyo_joint held at 0): origin, mass, centre of
#: mass and inertia (the first entry of the URDF, as for `head`).
HOKUYO_ORIGIN_M = HOKUYO_JOINT.xyz_m
HOKUYO_MASS_KG = 0.057654
HOKUYO_COM_M = (0.012428, 0.0004084, -0.0041835)
HOKUYO_INERTIA = (0.0004005974, 0.002080106, 0.001782985, 4.9927e-08, 1.1015e-05, -9.8165e-09)


def finger_inertial() -> tuple[float, np.ndarray, np.ndarray]:
    """One straight finger as one rigid body: mass, centre of mass (3,) and inertia (3, 3)
    about it, in the finger's base frame."""
    masses = np.array([link[0] for link in FINGER_LINKS])
    xs = np.array([link[1] for link in FINGER_LINKS])
    mass = float(masses.sum())
    com_x = float(masses @ xs / mass)
    inertia = np.zeros((3, 3))
    for link_mass, x, diag in FINGER_LINKS:
        d = x - com_x  # along x: adds to the y and z moments
        inertia += np.diag(diag) + link_mass * d * d * np.diag([0.0, 1.0, 1.0])
    return mass, np.array([com_x, 0.0, 0.0]), inertia


def hand_mass_kg() -> float:
    """One Sandia hand's mass (kg): the palm and four fingers."""
    return PALM_MASS_KG + 4 * finger_inertial()[0]


def vrc_robot_mass_kg() -> float:
    """The VRC robot's mass (kg): atlas_v1's, two hands and the Hokuyo link."""
    return ATLAS.REFERENCE_TOTAL_MASS_KG + 2 * hand_mass_kg() + HOKUYO_MASS_KG


def _rpy_quat(roll: float, pitch: float, yaw: float) -> str:
    return fmt(np.round(ATLAS.rpy_to_quat((roll, pitch, yaw)), 9))


def _sub(parent: ET.Element, tag: str, **attributes: str) -> ET.Element:
    element = ET.SubElement(parent, tag)
    for key, value in attributes.items():
        element.set(key.rstrip('_'), value)
    return element


def _full(inertia: np.ndarray) -> str:
    return fmt(np.round([inertia[0, 0], inertia[1, 1], inertia[2, 2],
                         inertia[0, 1], inertia[0, 2], inertia[1, 2]], 12))


def fixed_links() -> list[tuple[str, str, tuple[float, ...], tuple[float, float, float]]]:
    """The VRC robot's welded additions, parents first: (parent, link, xyz m, rpy rad), the
    one list the MJCF's bodies and the URDF's fixed joints are written from."""
    links: list[tuple[str, str, tuple[float, ...], tuple[float, float, float]]] = []
    for side in ('l', 'r'):
        reflect = 1.0 if side == 'l' else -1.0
        links.append((f'{side}_hand', f'{side}_palm', (0.0, reflect * HAND_MOUNT_M, 0.0),
                      (0.0, 0.0, reflect * math.pi / 2)))
        for index, (x, y, z, pitch, yaw) in enumerate(FINGER_MOUNTS):
            links.append((f'{side}_palm', f'{side}_f{index}', (x, reflect * y, z),
                          (0.0, pitch, reflect * yaw)))
    links.append(('head', HOKUYO_LINK, HOKUYO_ORIGIN_M, (0.0, 0.0, 0.0)))
    return links


def _placement(link: str) -> dict[str, str]:
    """The MJCF pos and quat of one of fixed_links()'s bodies."""
    _parent, _name, xyz, rpy = next(entry for entry in fixed_links() if entry[1] == link)
    placement = {'pos': fmt(xyz)}
    if any(rpy):
        placement['quat'] = _rpy_quat(*rpy)
    return placement


def add_hand(hand: ET.Element, side: str) -> None:
    """A rigid Sandia hand under the `l_hand`/`r_hand` body: the palm and four fingers,
    welded (no joints), colliding as the robot's other geoms do."""
    palm = _sub(hand, 'body', name=f'{side}_palm', **_placement(f'{side}_palm'))
    _sub(palm, 'inertial', pos='0 0 0', mass=repr(PALM_MASS_KG),
         diaginertia=fmt((PALM_INERTIA,) * 3))
    _sub(palm, 'geom', name=f'{side}_palm_c0', type_='box', size='0.05 0.045 0.02',
         pos='0.05 0 0', material='dark')
    mass, com, inertia = finger_inertial()
    for index in range(len(FINGER_MOUNTS)):
        finger = _sub(palm, 'body', name=f'{side}_f{index}', **_placement(f'{side}_f{index}'))
        _sub(finger, 'inertial', pos=fmt(np.round(com, 9)), mass=repr(round(mass, 9)),
             fullinertia=_full(inertia))
        _sub(finger, 'geom', name=f'{side}_f{index}_c0', type_='capsule', size='0.012',
             fromto='0 0 0 0.118 0 0', material='grey')


def add_hokuyo(head: ET.Element) -> None:
    """multisense_sl's Hokuyo link on `head`, its spinning joint held (a welded body)."""
    hokuyo = _sub(head, 'body', name='hokuyo_link', **_placement('hokuyo_link'))
    _sub(hokuyo, 'inertial', pos=fmt(HOKUYO_COM_M), mass=repr(HOKUYO_MASS_KG),
         fullinertia=fmt(HOKUYO_INERTIA))
    _sub(hokuyo, 'geom', class_='visual', type_='cylinder', size='0.024 0.024',
         pos='0.03 0 0.0235', material='dark')


# ---------------------------------------------------------------------------
# The course.
# ---------------------------------------------------------------------------


def derive_terrain(heightmap_png: Path, output: Path) -> np.ndarray:
    """Write the terrain image from DRCSim's heightmap PNG: the same 513 × 513 grey levels,
    8-bit, no metadata; check them against the course's description first."""
    try:
        grey = np.asarray(Image.open(heightmap_png).convert('L'))
    except OSError as err:
        raise SystemExit(f'{heightmap_png}: not a readable image ({err})') from None
    check_terrain(grey, heightmap_png)
    Image.fromarray(grey, mode='L').save(output, optimize=True)
    return grey


def check_terrain(grey: np.ndarray, source: Path) -> None:
    """The image is the course's heightmap: its size, and its darkest and brightest grey
    levels 0 and HEIGHTMAP.brightest (MuJoCo normalises between them, Gazebo scaled by the
    brightest: the two agree only then)."""
    hm = course.HEIGHTMAP
    if grey.shape != (hm.pixels, hm.pixels):
        raise SystemExit(f'{source}: {grey.shape[1]} × {grey.shape[0]} pixels, the course '
                         f'takes {hm.pixels} × {hm.pixels}')
    if int(grey.min()) != 0 or int(grey.max()) != hm.brightest:
        raise SystemExit(f'{source}: grey levels {grey.min()}…{grey.max()}, the course '
                         f'takes 0…{hm.brightest}')


def load_terrain(path: Path) -> np.ndarray:
    """The terrain image's grey levels (rows from +y down, columns from -x)."""
    if not path.is_file():
        raise SystemExit(f'{path} does not exist: derive it once with '
                         '`python3 tools/make_vrc_world.py --heightmap DRCSIM_HEIGHTMAP_PNG`')
    grey = np.asarray(Image.open(path).convert('L'))
    check_terrain(grey, path)
    return grey


def highest_ground_m(grey: np.ndarray, x0: float, x1: float, y0: float, y1: float) -> float:
    """The highest heightmap vertex (m) within one cell of the rectangle x0…x1, y0…y1."""
    hm = course.HEIGHTMAP
    half = hm.size_m / 2

    def index(v: float, low: bool) -> int:
        cell = v / hm.cell_m
        return int(np.clip(math.floor(cell) - 1 if low else math.ceil(cell) + 1,
                           0, hm.pixels - 1))

    c0, c1 = index(x0 + half, True), index(x1 + half, False)
    r0, r1 = index(half - y1, True), index(half - y0, False)
    return hm.height_m(float(grey[r0:r1 + 1, c0:c1 + 1].max()))


def block_pose(block: course.Block, grey: np.ndarray) -> tuple[np.ndarray, str]:
    """The block's position and quaternion: DRCSim's pose, raised (never lowered) so that
    its lowest corner clears the highest ground under it by BLOCK_CLEARANCE_M."""
    quat = ATLAS.rpy_to_quat((block.roll_rad, block.pitch_rad, block.yaw_rad))
    w, x, y, z = quat
    rot = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                    [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                    [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    half = np.array(course.BLOCK_ENVELOPE_M) / 2
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    corners = (signs * half + (0.0, 0.0, half[2])) @ rot.T + (block.x_m, block.y_m, block.z_m)
    ground = highest_ground_m(grey, corners[:, 0].min(), corners[:, 0].max(),
                              corners[:, 1].min(), corners[:, 1].max())
    lift = max(0.0, ground + BLOCK_CLEARANCE_M - float(corners[:, 2].min()))
    position = np.round((block.x_m, block.y_m, block.z_m + lift), 6)
    return position, fmt(np.round(quat, 9))


def terrain_height_m(grey: np.ndarray, x: float, y: float) -> float:
    """The heightfield's surface (m) at world (x, y) as MuJoCo triangulates it: each cell
    split along its diagonal from (-x, -y) to (+x, +y)."""
    hm = course.HEIGHTMAP
    u, v = (x + hm.size_m / 2) / hm.cell_m, (y + hm.size_m / 2) / hm.cell_m
    col, row = min(int(u), hm.pixels - 2), min(int(v), hm.pixels - 2)
    fu, fv = u - col, v - row
    up = hm.pixels - 1 - row  # the image's row of the vertex at `row` from -y

    def z(d_col: int, d_row: int) -> float:
        return hm.height_m(float(grey[up - d_row, col + d_col]))

    if fu >= fv:
        return z(0, 0) + fu * (z(1, 0) - z(0, 0)) + fv * (z(1, 1) - z(1, 0))
    return z(0, 0) + fv * (z(0, 1) - z(0, 0)) + fu * (z(1, 1) - z(0, 1))


def sole_corners_m() -> np.ndarray:
    """The soles' eight bottom corners (8, 3) in the pelvis frame, every joint at 0."""
    corners = []
    for side in 'lr':
        chain = [ATLAS.JOINTS[f'{side}_leg_{j}'].origin_m
                 for j in ('uhz', 'mhx', 'lhy', 'kny', 'uay', 'lax')]
        foot = np.sum(chain, axis=0)
        half = np.array(ATLAS.SOLE_SIZE_M) / 2
        for sx in (-1, 1):
            for sy in (-1, 1):
                corners.append(foot + ATLAS.SOLE_POS_M + (sx * half[0], sy * half[1], -half[2]))
    return np.array(corners)


def spawn_pose(start: course.Start, grey: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The pelvis's pose for `start` with every joint at 0: at its (x, y) and yaw, the flat
    soles' lowest corner on the terrain and none in it (DRCSim's z was its own model's)."""
    c, s = math.cos(start.yaw_rad), math.sin(start.yaw_rad)
    corners = sole_corners_m()
    above = []
    for x, y, z in corners:
        ground = terrain_height_m(grey, start.x_m + c * x - s * y, start.y_m + s * x + c * y)
        above.append(ground - z)
    position = np.round((start.x_m, start.y_m, max(above)), 9)
    return position, np.round(ATLAS.rpy_to_quat((0.0, 0.0, start.yaw_rad)), 9)


def _box(parent: ET.Element, name: str, box: course.Box, **attributes: str) -> ET.Element:
    return _sub(parent, 'geom', name=name, type_='box', size=fmt(np.array(box.size_m) / 2),
                pos=fmt(box.centre_m), **attributes)


def add_course(world: ET.Element, grey: np.ndarray) -> None:
    """The course's geoms and loose bodies in the worldbody (after the robot)."""
    hm = course.HEIGHTMAP
    # The soles' corner spheres touch it (make_atlas_mjcf.py's HEIGHTFIELD_CONTACT_BIT).
    _sub(world, 'geom', name='terrain', type_='hfield', hfield='terrain', class_='course',
         contype=str(1 | ATLAS.HEIGHTFIELD_CONTACT_BIT), pos=fmt((0, 0, hm.z0_m)),
         material='terrain')
    _sub(world, 'geom', name='mud_ground_plane', type_='plane', class_='mud_floor',
         size=fmt((hm.size_m / 2, hm.size_m / 2, 0.1)), pos=fmt((0, 0, course.MUD_FLOOR_Z_M)),
         material='mud')
    _box(world, 'mud_atlas', course.MUD_BOX, contype='0', conaffinity='0', group='3',
         material='mud_volume')
    (px, py, pz), pen_yaw = course.PEN_POSE
    pen = _sub(world, 'body', name='starting_pen', pos=fmt((px, py, pz)),
               quat=_rpy_quat(0, 0, pen_yaw), childclass='course')
    for index, wall in enumerate(course.PEN_WALLS):
        _box(pen, f'pen_wall_{index}', wall, material='wall')
    _box(pen, 'pen_floor', course.PEN_FLOOR, class_='pen_floor', material='pen_floor')
    post = np.array(course.GATE_POST_M)
    for gate in course.GATES:
        body = _sub(world, 'body', name=gate.name, pos=fmt((gate.x_m, gate.y_m, 0)),
                    quat=_rpy_quat(0, 0, gate.yaw_rad), childclass='course')
        for side, y in (('right', -2.5), ('left', 2.5)):
            _box(body, f'{gate.name}_{side}', course.Box((0, y, post[2] / 2), tuple(post)),
                 material='gate')
        _box(body, f'{gate.name}_top', course.Box((0, 0, post[2] + 0.1), (0.2, 5.2, 0.2)),
             material='gate')
    for block in course.BLOCKS:
        position, quat = block_pose(block, grey)
        body = _sub(world, 'body', name=block.name, pos=fmt(position), quat=quat,
                    childclass='course')
        _sub(body, 'freejoint', name=f'{block.name}_free')
        _sub(body, 'inertial', pos=fmt((0, 0, 0.1016)), mass=repr(course.BLOCK_MASS_KG),
             diaginertia=fmt(course.BLOCK_INERTIA))
        for index, wall in enumerate(course.BLOCK_WALLS):
            _box(body, f'{block.name}_{index}', wall, material='block')


# ---------------------------------------------------------------------------
# The file.
# ---------------------------------------------------------------------------
#: ODE's friction between two surfaces, the smaller of the two (DRCSim's figures).
TERRAIN_MU = min(course.FOOT_FRICTION, course.TERRAIN_FRICTION)
PEN_FLOOR_MU = min(course.FOOT_FRICTION, course.PEN_FLOOR_FRICTION)
MUD_FLOOR_MU = min(course.FOOT_FRICTION, course.MUD_FLOOR_FRICTION)

COURSE_MATERIALS = {
    'terrain': '0.47 0.42 0.33 1', 'mud': '0.3 0.22 0.12 1', 'mud_volume': '0.35 0.25 0.1 0.4',
    'wall': '0.75 0.75 0.72 1', 'pen_floor': '0.55 0.55 0.5 1', 'gate': '0.9 0.55 0.1 1',
    'block': '0.6 0.6 0.6 1',
}

HEADER = f'''
  DRCSim's VRC Task 2 course (vrc_task_2.world, DRCSim 2.7.0) with the VRC's Atlas
  (atlas_sandia_hands) for MuJoCo. GENERATED by tools/make_vrc_world.py from
  tutorial_atlas_control/course/vrc_task_2.py and tools/make_atlas_mjcf.py's robot;
  edit those, then run:  python3 tools/make_vrc_world.py

  The robot: sim/atlas_v1.xml's (same joints, actuators, sensors, weld), plus a rigid
  Sandia hand {HAND_MOUNT_M} m out from each of l_hand/r_hand ({hand_mass_kg():.3f} kg: a
  {PALM_MASS_KG} kg palm, four fingers of a 0.25 kg base and their phalanges, welded
  straight) and multisense_sl's hokuyo_link on head (its spinning joint held fixed).
  Total {vrc_robot_mass_kg():.5f} kg.
  The course: the terrain heightfield ({TERRAIN_FILE}, Gazebo's scaling
  z = {course.HEIGHTMAP.z0_m} + {course.HEIGHTMAP.relief_m} * grey / {course.HEIGHTMAP.brightest}),
  the start pen, gates 0-4, the pit's floor plane, the mud volume `mud_atlas` (touches
  nothing: the mud's drag finds it by name), 30 loose 5 kg cinder blocks. No floor plane.
  Houses and cones are left out (off the path).
  Friction as ODE combined it (the smaller of two): the course's geoms have priority
  {COURSE_PRIORITY} over the soles' 1, so a contact takes the course geom's friction, which
  is min(feet {course.FOOT_FRICTION}, surface): terrain and blocks {TERRAIN_MU}, pen floor
  {PEN_FLOOR_MU}, pit floor {MUD_FLOOR_MU}; with the soles' torsional/rolling friction and
  condim 6. docs/vrc.md says more.
  The spawn: the pelvis body's pos/quat below (the free joint's qpos0, the pelvis_pin
  weld's target) stands Atlas, joints at 0, at the course's start; the keyframes put it
  at each of DRCSim's four starts.
'''


def _insert_defaults(default: ET.Element) -> None:
    contact = (f'solref="{fmt(ATLAS.CONTACT_SOLREF)}" solimp="{fmt(ATLAS.CONTACT_SOLIMP)}"')
    course_class = ET.fromstring(
        f'<default class="course"><geom contype="1" conaffinity="1" condim="6" '
        f'priority="{COURSE_PRIORITY}" friction="{fmt((TERRAIN_MU, *SOLE_SPIN_ROLL))}" '
        f'{contact}/>'
        f'<default class="pen_floor"><geom friction="{fmt((PEN_FLOOR_MU, *SOLE_SPIN_ROLL))}"/>'
        f'</default>'
        f'<default class="mud_floor"><geom friction="{fmt((MUD_FLOOR_MU, *SOLE_SPIN_ROLL))}"/>'
        f'</default></default>')
    default.append(course_class)


def _keyframes(root: ET.Element, grey: np.ndarray, world: ET.Element) -> None:
    """A keyframe per DRCSim start: the robot standing there, joints 0, blocks as placed."""
    blocks = []
    for body in world.findall('body'):
        if body.get('name') != 'pelvis' and body.find('freejoint') is not None:
            blocks += [body.get('pos'), body.get('quat')]
    keyframe = _sub(root, 'keyframe')
    for start in course.STARTS.values():
        position, quat = spawn_pose(start, grey)
        qpos = ' '.join([fmt(position), fmt(quat), fmt([0] * len(ATLAS.JOINT_NAMES))] + blocks)
        _sub(keyframe, 'key', name=start.name, qpos=qpos)


def build(grey: np.ndarray) -> str:
    """The complete MJCF text of the course with the VRC robot, from the terrain's grey
    levels (load_terrain)."""
    parser = ET.XMLParser(target=ET.TreeBuilder(insert_comments=True))
    root = ET.fromstring(ATLAS.build(), parser=parser)
    root.set('model', course.WORLD_NAME)
    hm = course.HEIGHTMAP
    asset = root.find('asset')
    _sub(asset, 'hfield', name='terrain', file=TERRAIN_FILE,
         size=fmt((hm.size_m / 2, hm.size_m / 2, hm.relief_m, TERRAIN_BASE_M)))
    for name, rgba in COURSE_MATERIALS.items():
        _sub(asset, 'material', name=name, rgba=rgba)
    _insert_defaults(root.find('default'))
    # Blocks at rest sleep (MuJoCo skips them until touched): 30 awake blocks on the
    # heightfield cost 370 contacts a step. The robot, actuated, never sleeps (MuJoCo's
    # automatic policy for a tree with actuators).
    _sub(root.find('option'), 'flag', sleep='enable')
    world = root.find('worldbody')
    world.remove(world.find("geom[@name='floor']"))
    pelvis = world.find("body[@name='pelvis']")
    position, quat = spawn_pose(course.STARTS[course.WORLD_NAME], grey)
    pelvis.set('pos', fmt(position))
    pelvis.set('quat', fmt(quat))
    for side in 'lr':
        add_hand(pelvis.find(f".//body[@name='{side}_hand']"), side)
    add_hokuyo(pelvis.find(".//body[@name='head']"))
    add_course(world, grey)
    _keyframes(root, grey, world)
    ET.indent(root, '  ')
    return f'<!--{HEADER}-->\n' + ET.tostring(root, encoding='unicode') + '\n'


def build_urdf() -> str:
    """The VRC robot's URDF, for /tf and rviz: atlas_v1's (tools/make_atlas_mjcf.py) with the
    hands' links on fixed joints (no inertials: the MJCF has the masses). The Hokuyo's link,
    a body welded to the head here, is atlas_v1's URDF's already: on the spun hokuyo_joint,
    as the simulator publishes it."""
    lines = ATLAS.build_urdf().replace('<robot name="atlas">',
                                       '<robot name="atlas_sandia_hands">').splitlines()
    lines[1:1] = ['<!-- The VRC robot: GENERATED by tools/make_vrc_world.py from '
                  'tools/make_atlas_mjcf.py\'s URDF and the hands\' and Hokuyo\'s mounts. -->']
    end = lines.index('</robot>')
    added = []
    for parent, link, xyz, rpy in fixed_links():
        if link == HOKUYO_LINK:
            continue
        added += [f'  <joint name="{link}_joint" type="fixed">',
                  f'    <parent link="{parent}"/>', f'    <child link="{link}"/>',
                  f'    <origin xyz="{fmt(xyz)}" rpy="{fmt(rpy)}"/>', '  </joint>',
                  f'  <link name="{link}"/>']
    lines[end:end] = added
    return '\n'.join(lines) + '\n'


def main(argv: list[str] | None = None) -> int:
    """Write the world (and, from DRCSim's heightmap, the terrain image beside it)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('output', nargs='?', type=Path, default=DEFAULT_OUTPUT)
    parser.add_argument('--heightmap', type=Path, metavar='DRCSIM_PNG',
                        help="DRCSim's vrc_heightmap_2 heightmap.png: derive the terrain "
                        'image from it (once)')
    args = parser.parse_args(argv)
    terrain = args.output.parent / TERRAIN_FILE
    if args.heightmap is not None:
        derive_terrain(args.heightmap, terrain)
        print(f'wrote {terrain}')
    args.output.write_text(build(load_terrain(terrain)))
    print(f'wrote {args.output}')
    urdf_output = args.output.with_suffix('.urdf')
    urdf_output.write_text(build_urdf())
    print(f'wrote {urdf_output}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
