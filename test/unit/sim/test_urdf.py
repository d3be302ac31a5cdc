"""sim/atlas_v1.urdf against sim/atlas_v1.xml: one robot, described twice from one table."""

from __future__ import annotations

import re
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np
import pytest

from support.model_table import load_table
from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.sensors import HEAD_FRAMES, HOKUYO_JOINT, frame_in_head
from tutorial_atlas_control.sim import model, urdf

REPO = Path(__file__).resolve().parents[3]
#: The left knee's joint origin in the URDF, and the same 1 cm lower.
KNEE_ORIGIN = '<child link="l_lleg"/>\n    <origin xyz="-0.05 0 -0.374"'
KNEE_ORIGIN_MOVED = '<child link="l_lleg"/>\n    <origin xyz="-0.05 0 -0.384"'
URDF_PATH = REPO / 'sim' / 'atlas_v1.urdf'
#: Random joint configurations whose forward kinematics are compared.
FK_SAMPLES = 50
#: Every link origin of the two models within this (m) in every sample.
FK_TOLERANCE_M = 1e-3
#: Link orientations within this (rad).
FK_TOLERANCE_RAD = 1e-6


TABLE = load_table()
#: The head's sensor frames: URDF links that are not bodies of the model.
SENSOR_LINKS = (HOKUYO_JOINT.child, *(frame.child for frame in HEAD_FRAMES))
#: The geom groups a viewer draws by default (the soles' corner spheres are in group 4).
DRAWN_GROUPS = (0, 1, 2)


@pytest.fixture(scope='module')
def mjcf() -> mujoco.MjModel:
    return model.load_model().model


def compile_urdf(text: str) -> mujoco.MjModel:
    """A URDF compiled by MuJoCo, the root link kept as a body (MuJoCo would fuse it into
    the world) and its visuals kept, so that bodies, masses and shapes can be compared. The
    head's sensor frames (no inertia) get MuJoCo's least mass, which a moving body needs."""
    return mujoco.MjModel.from_xml_string(text.replace(
        '<robot name="atlas">',
        '<robot name="atlas"><mujoco><compiler fusestatic="false" discardvisual="false" '
        'boundmass="1e-9" boundinertia="1e-12"/></mujoco>'))


@pytest.fixture(scope='module')
def urdf_model() -> mujoco.MjModel:
    return compile_urdf(URDF_PATH.read_text())


def body_names(m: mujoco.MjModel) -> list[str]:
    return [m.body(b).name for b in range(1, m.nbody)]


def urdf_links() -> list[str]:
    return [link.get('name') for link in ET.fromstring(URDF_PATH.read_text()).findall('link')]


def test_urdf_file_is_what_the_generator_writes() -> None:
    assert URDF_PATH.read_text() == TABLE.build_urdf(), \
        'sim/atlas_v1.urdf is stale: run `python3 tools/make_atlas_mjcf.py`'


def test_same_joints_in_the_same_order_with_the_same_limits(mjcf: mujoco.MjModel) -> None:
    _links, joints = urdf.read_joints(URDF_PATH.read_text())
    mjcf_hinges = [mjcf.joint(j).name for j in range(mjcf.njnt)
                   if mjcf.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]
    sensor_joints = [HOKUYO_JOINT.joint, *(frame.joint for frame in HEAD_FRAMES)]
    assert [joint.name for joint in joints] == mjcf_hinges + sensor_joints
    joints = joints[:len(mjcf_hinges)]
    assert set(mjcf_hinges) == set(JOINT_NAMES)  # bare names, no atlas:: prefix
    for joint in joints:
        assert joint.kind == 'revolute', joint.name
        np.testing.assert_array_equal([joint.lower_rad, joint.upper_rad],
                                      mjcf.joint(joint.name).range)


def test_same_links_masses_and_inertias(mjcf: mujoco.MjModel, urdf_model: mujoco.MjModel) -> None:
    assert sorted(body_names(urdf_model)) == sorted(body_names(mjcf) + list(SENSOR_LINKS))
    assert sorted(urdf_links()) == sorted(body_names(urdf_model))
    for name in body_names(mjcf):
        assert urdf_model.body(name).mass[0] == mjcf.body(name).mass[0], name
        np.testing.assert_allclose(urdf_model.body(name).ipos, mjcf.body(name).ipos, atol=1e-12)
        np.testing.assert_allclose(urdf_model.body(name).inertia, mjcf.body(name).inertia,
                                   rtol=1e-9, err_msg=name)


def test_forward_kinematics_agree_in_random_configurations(
        mjcf: mujoco.MjModel, urdf_model: mujoco.MjModel) -> None:
    """Both models with the pelvis at the origin, the same random joint angles within the
    limits: every link origin (and orientation) agrees. Prints the largest difference."""
    rng = np.random.default_rng(15)
    data_mjcf, data_urdf = mujoco.MjData(mjcf), mujoco.MjData(urdf_model)
    names = body_names(mjcf)
    worst_m = worst_rad = 0.0
    for _ in range(FK_SAMPLES):
        data_mjcf.qpos[:7] = (0, 0, 0, 1, 0, 0, 0)
        for name in JOINT_NAMES:
            angle = rng.uniform(*mjcf.joint(name).range)
            data_mjcf.qpos[mjcf.joint(name).qposadr[0]] = angle
            data_urdf.qpos[urdf_model.joint(name).qposadr[0]] = angle
        mujoco.mj_kinematics(mjcf, data_mjcf)
        mujoco.mj_kinematics(urdf_model, data_urdf)
        for name in names:
            worst_m = max(worst_m, float(np.linalg.norm(
                data_mjcf.body(name).xpos - data_urdf.body(name).xpos)))
            dot = abs(float(data_mjcf.body(name).xquat @ data_urdf.body(name).xquat))
            worst_rad = max(worst_rad, 2.0 * float(np.arccos(min(1.0, dot))))
    print(f'largest URDF-MJCF difference over {FK_SAMPLES} configurations: link origin '
          f'{worst_m:.3g} m, orientation {worst_rad:.3g} rad')
    assert worst_m <= FK_TOLERANCE_M
    assert worst_rad <= FK_TOLERANCE_RAD


def test_a_moved_joint_is_seen_by_the_comparison(mjcf: mujoco.MjModel) -> None:
    """The FK comparison can fail: a URDF with the knee 1 cm lower puts the foot 1 cm off."""
    text = URDF_PATH.read_text().replace(KNEE_ORIGIN, KNEE_ORIGIN_MOVED)
    moved = compile_urdf(text)
    data_mjcf, data_moved = mujoco.MjData(mjcf), mujoco.MjData(moved)
    data_mjcf.qpos[:7] = (0, 0, 0, 1, 0, 0, 0)
    mujoco.mj_kinematics(mjcf, data_mjcf)
    mujoco.mj_kinematics(moved, data_moved)
    offset = data_mjcf.body('l_foot').xpos - data_moved.body('l_foot').xpos
    assert np.linalg.norm(offset) == pytest.approx(0.01, abs=1e-9)


def _visual_colours(m: mujoco.MjModel, body: str) -> set[tuple[float, ...]]:
    """Colours drawn on a body: its geoms' material (MJCF) or rgba (URDF import) colours."""
    colours = set()
    for geom in range(m.ngeom):
        if m.geom_bodyid[geom] == m.body(body).id and m.geom_group[geom] in DRAWN_GROUPS:
            material = m.geom_matid[geom]
            rgba = m.mat_rgba[material] if material >= 0 else m.geom_rgba[geom]
            colours.add(tuple(round(float(v), 6) for v in rgba))
    return colours


def test_same_shapes_and_colours(mjcf: mujoco.MjModel) -> None:
    """Each link draws the MJCF's shapes in the MJCF's colours (a capsule as a cylinder
    and two spheres)."""
    root = ET.fromstring(URDF_PATH.read_text())
    for link in root.findall('link'):
        name = link.get('name')
        visuals = link.findall('visual')
        if name in SENSOR_LINKS:
            assert not visuals, name  # frames, drawn by nothing
            continue
        body = mjcf.body(name).id
        geoms = [g for g in range(mjcf.ngeom)
                 if mjcf.geom_bodyid[g] == body and mjcf.geom_group[g] in DRAWN_GROUPS]
        capsules = sum(mjcf.geom_type[g] == mujoco.mjtGeom.mjGEOM_CAPSULE for g in geoms)
        assert len(visuals) == len(geoms) + 2 * capsules, name
        colours = {tuple(float(v) for v in
                         root.find(f"material[@name='{v.find('material').get('name')}']")
                         .find('color').get('rgba').split()) for v in visuals}
        assert colours == _visual_colours(mjcf, name), name


def test_the_shipped_urdf_matches_the_shipped_model(mjcf: mujoco.MjModel) -> None:
    path, text = urdf.matching_urdf(model.MODEL_PATH, mjcf)
    assert path == URDF_PATH
    assert text == URDF_PATH.read_text()


def test_a_variant_without_urdf_has_none(tmp_path: Path, mjcf: mujoco.MjModel) -> None:
    variant = tmp_path / 'variant.xml'
    shutil.copy(model.MODEL_PATH, variant)
    with pytest.raises(urdf.UrdfError,
                       match=re.escape(f'({tmp_path / "variant.urdf"} does not exist)')):
        urdf.matching_urdf(variant, mjcf)


def test_a_urdf_of_another_robot_does_not_match(tmp_path: Path, mjcf: mujoco.MjModel) -> None:
    variant = tmp_path / 'variant.xml'
    shutil.copy(model.MODEL_PATH, variant)
    (tmp_path / 'variant.urdf').write_text(
        URDF_PATH.read_text().replace(KNEE_ORIGIN, KNEE_ORIGIN_MOVED))
    with pytest.raises(urdf.UrdfError, match="joint 'l_leg_kny' connects other links or has "
                                             'another origin or axis'):
        urdf.matching_urdf(variant, mjcf)
    (tmp_path / 'variant.urdf').write_text('<mujoco/>')
    with pytest.raises(urdf.UrdfError, match='root element is <mujoco>, not <robot>'):
        urdf.matching_urdf(variant, mjcf)
    (tmp_path / 'variant.urdf').write_text(
        URDF_PATH.read_text().replace('name="l_leg_kny"', 'name="l_knee"'))
    with pytest.raises(urdf.UrdfError, match="no revolute joint 'l_leg_kny'"):
        urdf.matching_urdf(variant, mjcf)


def test_sensor_frames_sit_where_the_sensors_take_their_readings(
        urdf_model: mujoco.MjModel) -> None:
    """Each sensor frame's pose below `head` in the URDF (what robot_state_publisher and
    rviz use) is the one the laser, cameras and IMU are computed in (sensors/frames.py),
    the spindle at rest and turned."""
    data = mujoco.MjData(urdf_model)
    spindle = urdf_model.joint(HOKUYO_JOINT.joint).qposadr[0]
    for angle in (0.0, 0.7, -2.9):
        data.qpos[spindle] = angle
        mujoco.mj_kinematics(urdf_model, data)
        head_position, head_rotation = data.body('head').xpos, data.body('head').xmat.reshape(3, 3)
        for link in SENSOR_LINKS:
            position, rotation = frame_in_head(link, angle)
            np.testing.assert_allclose(data.body(link).xpos,
                                       head_position + head_rotation @ position, atol=1e-9)
            np.testing.assert_allclose(data.body(link).xmat.reshape(3, 3),
                                       head_rotation @ rotation, atol=1e-9)


def test_a_link_the_model_lacks_is_no_frame(tmp_path: Path, mjcf: mujoco.MjModel) -> None:
    """Links beyond the model's bodies are accepted only as frames fixed or spun on a body:
    a moving (revolute) extra link or a link joined to nothing is another robot."""
    variant = tmp_path / 'variant.xml'
    shutil.copy(model.MODEL_PATH, variant)
    spun_link = '<joint name="hokuyo_joint" type="continuous">'
    (tmp_path / 'variant.urdf').write_text(
        URDF_PATH.read_text().replace(spun_link, '<joint name="hokuyo_joint" type="revolute">'))
    with pytest.raises(urdf.UrdfError, match=r'links and bodies differ \(hokuyo_link is neither'):
        urdf.matching_urdf(variant, mjcf)
    (tmp_path / 'variant.urdf').write_text(
        URDF_PATH.read_text().replace('</robot>', '<link name="loose"/></robot>'))
    with pytest.raises(urdf.UrdfError, match=r'\(loose is neither a body nor a frame'):
        urdf.matching_urdf(variant, mjcf)
    (tmp_path / 'variant.urdf').write_text(
        URDF_PATH.read_text().replace('<link name="head">', '<link name="skull">'))
    with pytest.raises(urdf.UrdfError, match=r'links and bodies differ \(head\)'):
        urdf.matching_urdf(variant, mjcf)


def test_a_link_described_twice_is_refused(tmp_path: Path, mjcf: mujoco.MjModel) -> None:
    """rviz's RobotModel draws nothing of a URDF with a link twice: refused, named."""
    variant = tmp_path / 'variant.xml'
    shutil.copy(model.MODEL_PATH, variant)
    (tmp_path / 'variant.urdf').write_text(URDF_PATH.read_text().replace(
        '</robot>', '<joint name="again" type="fixed"><parent link="head"/>'
        '<child link="hokuyo_link"/></joint><link name="hokuyo_link"/></robot>'))
    with pytest.raises(urdf.UrdfError, match="link 'hokuyo_link' is described twice"):
        urdf.matching_urdf(variant, mjcf)
