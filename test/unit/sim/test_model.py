"""sim/atlas_v1.xml against the Atlas v1 figures, and physics checks (standing, falling)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable
from pathlib import Path

import mujoco
import numpy as np
import pytest

from support.model_table import load_table
from tutorial_atlas_control.command import arrays as commands
from tutorial_atlas_control.joints import JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.sim import controller, model

REPO = Path(__file__).resolve().parents[3]
REFERENCE = REPO.parent / 'shared' / 'reference'
GAINS_YAML = REPO / 'config' / 'atlas_controller.yaml'


TABLE = load_table()


@pytest.fixture(scope='module')
def atlas() -> model.AtlasModel:
    return model.load_model()


def body_name(m: mujoco.MjModel, body_id: int) -> str:
    return mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, body_id)


def full_inertia(m: mujoco.MjModel, body_id: int) -> np.ndarray:
    """Body inertia about its COM in the body frame, from MuJoCo's principal form."""
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, m.body_iquat[body_id])
    rot = rot.reshape(3, 3)
    return rot @ np.diag(m.body_inertia[body_id]) @ rot.T


# --- the model file --------------------------------------------------------------------------

def test_model_file_is_what_the_generator_writes() -> None:
    assert model.MODEL_PATH.read_text() == TABLE.build(), \
        'sim/atlas_v1.xml is stale: run `python3 tools/make_atlas_mjcf.py`'


def test_every_joint_matches_the_table(atlas: model.AtlasModel) -> None:
    m = atlas.model
    assert m.njnt == NUM_JOINTS + 1  # + the pelvis free joint
    for index, name in enumerate(JOINT_NAMES):
        figures = TABLE.JOINTS[name]
        joint = m.joint(name)
        assert joint.type[0] == mujoco.mjtJoint.mjJNT_HINGE, name
        child = int(joint.bodyid[0])
        assert body_name(m, child) == figures.child, name
        assert body_name(m, int(m.body_parentid[child])) == figures.parent, name
        np.testing.assert_allclose(m.body_pos[child], figures.origin_m, atol=1e-12, err_msg=name)
        np.testing.assert_allclose(m.body_quat[child], [1, 0, 0, 0], atol=1e-12, err_msg=name)
        axis = np.asarray(figures.axis) / np.linalg.norm(figures.axis)
        np.testing.assert_allclose(joint.axis, axis, atol=1e-9, err_msg=name)
        assert joint.limited[0] == 1, name
        np.testing.assert_allclose(joint.range, [figures.lower_rad, figures.upper_rad], atol=1e-12)
        assert atlas.lower_rad[index] == figures.lower_rad
        assert atlas.upper_rad[index] == figures.upper_rad
        assert atlas.effort_limit_nm[index] == figures.effort_nm
        assert atlas.velocity_limit_rad_s[index] == figures.velocity_rad_s
        assert m.dof_damping[joint.dofadr[0]] == pytest.approx(figures.damping_nms)
        assert atlas.qpos_adr[index] == joint.qposadr[0]
        assert atlas.dof_adr[index] == joint.dofadr[0]


def test_every_link_matches_the_table(atlas: model.AtlasModel) -> None:
    m = atlas.model
    assert set(TABLE.LINKS) == {body_name(m, b) for b in range(1, m.nbody)}
    for name, link in TABLE.LINKS.items():
        body = m.body(name)
        assert body.mass[0] == pytest.approx(link.mass_kg, rel=1e-12), name
        np.testing.assert_allclose(body.ipos, link.com_m, atol=1e-12, err_msg=name)
        expected, changed = TABLE.corrected_inertia(link.inertia)
        assert changed == (name in ('utorso', 'head')), name
        np.testing.assert_allclose(full_inertia(m, body.id), TABLE.inertia_matrix(expected),
                                   atol=1e-8, err_msg=name)


def test_corrected_inertias_change_only_the_largest_principal_moment() -> None:
    for name in ('utorso', 'head'):
        original = np.linalg.eigvalsh(TABLE.inertia_matrix(TABLE.LINKS[name].inertia))
        fixed = np.linalg.eigvalsh(
            TABLE.inertia_matrix(TABLE.corrected_inertia(TABLE.LINKS[name].inertia)[0]))
        np.testing.assert_allclose(fixed[:2], original[:2], rtol=1e-5)
        assert fixed[2] < original[2]
        assert fixed[0] + fixed[1] >= fixed[2]


def test_total_mass_matches_the_reference(atlas: model.AtlasModel) -> None:
    total = atlas.model.body_subtreemass[atlas.pelvis_body_id]
    assert total == pytest.approx(TABLE.REFERENCE_TOTAL_MASS_KG, rel=1e-3)
    assert total == pytest.approx(sum(link.mass_kg for link in TABLE.LINKS.values()), rel=1e-12)


def test_actuators_are_torque_motors_in_tutorial_order(atlas: model.AtlasModel) -> None:
    m = atlas.model
    assert m.nu == NUM_JOINTS
    for index, name in enumerate(JOINT_NAMES):
        assert m.actuator(index).name == name
        assert m.actuator_trnid[index, 0] == m.joint(name).id
        assert m.actuator_gear[index, 0] == 1.0
        assert m.actuator_ctrllimited[index] == 0  # the controller law clamps effort


def test_simulation_options(atlas: model.AtlasModel) -> None:
    m = atlas.model
    assert m.opt.timestep == 0.001
    assert m.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    assert m.vis.global_.offwidth >= 1280 and m.vis.global_.offheight >= 720
    camera = m.camera('track')
    assert int(camera.mode[0]) in (int(mujoco.mjtCamLight.mjCAMLIGHT_TRACKCOM),
                                   int(mujoco.mjtCamLight.mjCAMLIGHT_TRACK))
    assert body_name(m, int(camera.bodyid[0])) == 'pelvis'
    assert m.nlight >= 1


def test_sensors(atlas: model.AtlasModel) -> None:
    dims = {name: s.stop - s.start for name, s in atlas.sensor_slices.items()}
    assert dims == {'imu_orientation': 4, 'imu_angular_velocity': 3, 'imu_linear_acceleration': 3,
                    'l_foot_force': 3, 'l_foot_torque': 3, 'r_foot_force': 3, 'r_foot_torque': 3}
    m = atlas.model
    for side in 'lr':
        site = m.site(f'{side}_foot_ft')
        assert body_name(m, int(site.bodyid[0])) == f'{side}_foot'
        np.testing.assert_allclose(site.pos, 0.0)  # the l/r_leg_lax joint origin
    with pytest.raises(model.ModelError, match='Unknown sensor'):
        model.sensor(atlas, mujoco.MjData(m), 'nose')


def test_load_model_errors(tmp_path: Path) -> None:
    with pytest.raises(model.ModelError, match='does not exist.*make_atlas_mjcf'):
        model.load_model(tmp_path / 'missing.xml')
    broken = tmp_path / 'broken.xml'
    broken.write_text('<mujoco><worldbody><body></mujoco>')
    with pytest.raises(model.ModelError, match='Could not compile'):
        model.load_model(broken)
    other = tmp_path / 'other.xml'
    other.write_text('<mujoco><worldbody><body><joint name="back_lbz"/><geom size="0.1"/>'
                     '</body></worldbody></mujoco>')
    with pytest.raises(model.ModelError, match="no joint named 'back_mby'"):
        model.load_model(other)


# --- initial state -----------------------------------------------------------------------------

def test_spawn_puts_the_soles_on_the_floor(atlas: model.AtlasModel) -> None:
    # SIM300 below: pytest.approx goes on the right (the rule takes SPAWN_HEIGHT_M for a literal)
    assert model.SPAWN_HEIGHT_M == pytest.approx(TABLE.SPAWN_HEIGHT_M, abs=1e-12)  # noqa: SIM300
    data = mujoco.MjData(atlas.model)
    data.qpos[:] = 1.0
    model.reset_to_initial(atlas, data)
    np.testing.assert_array_equal(model.joint_positions(atlas, data), 0.0)
    position, quaternion = model.pelvis_pose(atlas, data)
    np.testing.assert_allclose(position, [0, 0, model.SPAWN_HEIGHT_M])
    np.testing.assert_allclose(quaternion, [1, 0, 0, 0])
    for side in 'lr':
        sole = atlas.model.geom(f'{side}_foot_sole')
        bottom = data.geom(sole.id).xpos[2] - sole.size[2]
        assert bottom == pytest.approx(0.0, abs=1e-9)
    # DRCSim spawned the pelvis at 0.93 m, 2.9 mm higher.
    assert 0.93 - model.SPAWN_HEIGHT_M == pytest.approx(0.002881, abs=1e-6)  # noqa: SIM300


def test_body_position_in_pose_is_the_simulated_pose(atlas: model.AtlasModel) -> None:
    """Forward kinematics of a recorded pose gives where the simulator had the foot."""
    data = mujoco.MjData(atlas.model)
    model.reset_to_initial(atlas, data)
    data.qpos[atlas.qpos_adr] = np.linspace(-0.3, 0.3, NUM_JOINTS)
    adr = atlas.free_qpos_adr
    data.qpos[adr:adr + 7] = (0.4, -0.2, 0.8, np.cos(0.3), 0.0, 0.0, np.sin(0.3))
    mujoco.mj_forward(atlas.model, data)
    foot = atlas.model.body('r_foot').id
    position, quaternion = model.pelvis_pose(atlas, data)
    scratch = mujoco.MjData(atlas.model)
    found = model.body_position_in_pose(atlas, scratch, foot, position, quaternion,
                                        model.joint_positions(atlas, data))
    np.testing.assert_allclose(found, data.xpos[foot], atol=1e-12)
    # Each input counts: the pelvis 0.1 m higher lifts the foot 0.1 m; a bent knee lifts it.
    higher = model.body_position_in_pose(atlas, scratch, foot, position + [0, 0, 0.1],
                                         quaternion, model.joint_positions(atlas, data))
    np.testing.assert_allclose(higher - found, [0, 0, 0.1], atol=1e-12)
    standing = model.body_position_in_pose(atlas, scratch, foot, position, [1, 0, 0, 0],
                                           np.zeros(NUM_JOINTS))
    bent = np.zeros(NUM_JOINTS)
    bent[JOINT_NAMES.index('r_leg_kny')] = 1.0
    kneeling = model.body_position_in_pose(atlas, scratch, foot, position, [1, 0, 0, 0], bent)
    assert kneeling[2] - standing[2] > 0.1


def test_pin_holds_the_spawn_pose_without_a_jump(atlas: model.AtlasModel) -> None:
    data = mujoco.MjData(atlas.model)
    model.reset_to_initial(atlas, data)
    assert data.eq_active[atlas.pin_eq_id] == 0
    model.set_pelvis_pinned(atlas, data, True)
    mujoco.mj_forward(atlas.model, data)
    equality_rows = data.efc_type[:data.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY
    assert equality_rows.sum() == 6
    np.testing.assert_allclose(data.efc_pos[:data.nefc][equality_rows], 0.0, atol=1e-12)
    for _ in range(500):  # limp robot hanging from the pin
        mujoco.mj_step(atlas.model, data)
    position, _ = model.pelvis_pose(atlas, data)
    np.testing.assert_allclose(position, [0, 0, model.SPAWN_HEIGHT_M], atol=1e-3)
    model.set_pelvis_pinned(atlas, data, False)
    assert data.eq_active[atlas.pin_eq_id] == 0


# --- physics -----------------------------------------------------------------------------------

def simulate(atlas: model.AtlasModel, command: commands.JointCommandArrays, seconds: float,
             pin_seconds: float) -> dict[str, float]:
    """Run the controller law at 1 kHz; return drift figures and the first time z < 0.5 m."""
    m = atlas.model
    data = mujoco.MjData(m)
    model.reset_to_initial(atlas, data)
    model.set_pelvis_pinned(atlas, data, pin_seconds > 0)
    state = controller.PidState()
    torque = np.zeros(NUM_JOINTS)
    dt_s = m.opt.timestep
    feet = [m.body(f'{side}_foot').id for side in 'lr']
    feet_start = data.xpos[feet, :2].copy()
    z_start = data.qpos[atlas.free_qpos_adr + 2]
    steps, unpin_step = round(seconds / dt_s), round(pin_seconds / dt_s)
    worst_dz = worst_slide = 0.0
    fall_time = float('inf')
    for step in range(steps):
        if step == unpin_step:
            model.set_pelvis_pinned(atlas, data, False)
        controller.compute_torque(command, model.joint_positions(atlas, data),
                                  model.joint_velocities(atlas, data), state, dt_s,
                                  atlas.lower_rad, atlas.upper_rad, atlas.effort_limit_nm,
                                  out=torque)
        data.ctrl[:] = torque
        mujoco.mj_step(m, data)
        z = data.qpos[atlas.free_qpos_adr + 2]
        worst_dz = max(worst_dz, abs(z - z_start))
        worst_slide = max(worst_slide,
                          float(np.linalg.norm(data.xpos[feet, :2] - feet_start, axis=1).max()))
        if z < 0.5:
            fall_time = data.time
            break
    assert np.all(np.isfinite(data.qpos))
    return {'dz': worst_dz, 'slide': worst_slide, 'fall_time': fall_time}


@pytest.mark.parametrize('pin_seconds', [1.0, 0.0], ids=['pinned_1s', 'never_pinned'])
def test_stands_30s_on_the_pd_law_alone(atlas: model.AtlasModel, pin_seconds: float) -> None:
    gains = controller.load_gains_yaml(GAINS_YAML)
    result = simulate(atlas, controller.hold_command(gains, np.zeros(NUM_JOINTS)), 30.0,
                      pin_seconds)
    assert result['fall_time'] == float('inf')
    assert result['dz'] < 0.02   # m, pelvis height
    assert result['slide'] < 0.01  # m, each foot, horizontally


def test_falls_without_gains(atlas: model.AtlasModel) -> None:
    result = simulate(atlas, commands.JointCommandArrays.zeros(), 3.0, 0.0)
    assert result['fall_time'] < 3.0


def test_simulation_is_deterministic(atlas: model.AtlasModel) -> None:
    gains = controller.load_gains_yaml(GAINS_YAML)
    target = np.zeros(NUM_JOINTS)
    target[JOINT_NAMES.index('l_leg_kny')] = 0.6  # something that moves
    command = controller.hold_command(gains, target)

    def run() -> np.ndarray:
        data = mujoco.MjData(atlas.model)
        model.reset_to_initial(atlas, data)
        state = controller.PidState()
        for _ in range(1500):
            data.ctrl[:] = controller.compute_torque(
                command, model.joint_positions(atlas, data), model.joint_velocities(atlas, data),
                state, atlas.model.opt.timestep, atlas.lower_rad, atlas.upper_rad,
                atlas.effort_limit_nm)
            mujoco.mj_step(atlas.model, data)
        return data.qpos.copy()

    assert run().tobytes() == run().tobytes()


# --- DRCSim's figures typed here: checked in every clone, without the reference files ---------

#: A subset of DRCSim 2.x's atlas.urdf (Atlas v1), typed from it by hand: joint -> (axis,
#: lower, upper (rad), effort (N m), velocity (rad/s)). Chosen where a slip would not show
#: elsewhere: the tilted shoulder axes, the mirrored limits of the two sides (not always exact
#: mirrors: l_leg_lhy -1.75, r_leg_lhy -1.745), the neck from multisense_sl.urdf.
DRCSIM_JOINTS = {
    'back_lbz': ((0, 0, 1), -0.610865, 0.610865, 124.016, 12),
    'back_mby': ((0, 1, 0), -1.2, 1.28, 206.843, 12),
    'back_ubx': ((1, 0, 0), -0.790809, 0.790809, 94.91, 12),
    'neck_ay': ((0, 1, 0), -0.610865238, 1.13446401, 5, 12),
    'l_arm_usy': ((0, 0.5, 0.866025), -1.9635, 1.9635, 212, 12),
    'r_arm_usy': ((0, 0.5, -0.866025), -1.9635, 1.9635, 212, 12),
    'l_arm_shx': ((1, 0, 0), -1.39626, 1.74533, 170, 12),
    'r_arm_shx': ((1, 0, 0), -1.74533, 1.39626, 170, 12),
    'l_arm_elx': ((1, 0, 0), 0, 2.35619, 114, 12),
    'r_arm_elx': ((1, 0, 0), -2.35619, 0, 114, 12),
    'l_arm_mwx': ((1, 0, 0), -0.436, 1.571, 60, 12),
    'r_arm_mwx': ((1, 0, 0), -1.571, 0.436, 60, 12),
    'l_leg_uhz': ((0, 0, 1), -0.32, 1.14, 110, 12),
    'r_leg_uhz': ((0, 0, 1), -1.14, 0.32, 110, 12),
    'l_leg_mhx': ((1, 0, 0), -0.47, 0.495, 180, 12),
    'r_leg_mhx': ((1, 0, 0), -0.495, 0.47, 180, 12),
    'l_leg_lhy': ((0, 1, 0), -1.75, 0.524, 260, 12),
    'r_leg_lhy': ((0, 1, 0), -1.745, 0.524, 260, 12),
    'l_leg_kny': ((0, 1, 0), 0, 2.45, 220, 12),
    'l_leg_uay': ((0, 1, 0), -0.698, 0.698, 220, 12),
    'l_leg_lax': ((1, 0, 0), -0.436, 0.436, 90, 12),
}
#: Every link's mass (kg) in atlas.urdf (the same on both sides), and the MultiSense head's
#: (multisense_sl.urdf's first `head` link).
DRCSIM_MASSES_KG = {
    'pelvis': 14.2529, 'ltorso': 1.92, 'mtorso': 0.55, 'utorso': 18.484, 'head': 1.41984,
    'uglut': 0.5166, 'lglut': 0.69, 'uleg': 7.34, 'lleg': 4.367, 'talus': 0.1, 'foot': 1.634,
    'clav': 2.369, 'scap': 2.707, 'uarm': 1.881, 'larm': 2.148, 'farm': 0.981, 'hand': 2.263,
}
CENTRE_LINKS = ('pelvis', 'ltorso', 'mtorso', 'utorso', 'head')


def test_drcsim_figures_typed_here(atlas: model.AtlasModel) -> None:
    """The simulated model carries DRCSim's axes, limits and masses (the gains are checked
    against DRCSim's the same way in test_controller.py, DRCSIM_PD)."""
    m = atlas.model
    index = {name: i for i, name in enumerate(JOINT_NAMES)}
    for name, (axis, lower, upper, effort, velocity) in DRCSIM_JOINTS.items():
        joint_id = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)
        # MuJoCo normalizes the axis: DRCSim's (0, 0.5, 0.866025) is 2e-7 short of unit length.
        np.testing.assert_allclose(m.jnt_axis[joint_id], np.asarray(axis) / np.linalg.norm(axis),
                                   atol=1e-9, err_msg=name)
        i = index[name]
        assert (atlas.lower_rad[i], atlas.upper_rad[i]) == (lower, upper), name
        assert atlas.effort_limit_nm[i] == effort, name
        assert atlas.velocity_limit_rad_s[i] == velocity, name
    links = [*CENTRE_LINKS, *(f'{side}_{link}' for side in 'lr'
                              for link in DRCSIM_MASSES_KG if link not in CENTRE_LINKS)]
    for link in links:
        body_id = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, link)
        assert body_id >= 0, f'no body {link}'
        assert m.body_mass[body_id] == DRCSIM_MASSES_KG[link.removeprefix('l_').removeprefix(
            'r_')], link
    # 90.61994 kg in all: 889 N of weight.
    expected_total = sum(DRCSIM_MASSES_KG[name.removeprefix('l_').removeprefix('r_')]
                         for name in links)
    assert expected_total == pytest.approx(90.61994, abs=1e-9)
    assert m.body_subtreemass[atlas.pelvis_body_id] == pytest.approx(expected_total, abs=1e-9)


# --- cross-check against the reference files, when they are beside the repository -------------

_reference_absent = pytest.mark.skipif(
    not (REFERENCE / 'atlas_v1.urdf').is_file(),
    reason=f'{REFERENCE} not present (test_drcsim_figures_typed_here checks a subset)')


def needs_reference(test: Callable[[], None]) -> Callable[[], None]:
    """Skips without the reference files, even under TAC_REQUIRE_ALL (test/conftest.py)."""
    return pytest.mark.optional('DRCSim reference files')(_reference_absent(test))


def _floats(text: str) -> list[float]:
    return [float(v) for v in text.split()]


@needs_reference
def test_table_matches_atlas_urdf() -> None:
    root = ET.parse(REFERENCE / 'atlas_v1.urdf').getroot()
    joints = {j.get('name'): j for j in root.findall('joint')}
    assert set(joints) == set(JOINT_NAMES)
    for name, joint in joints.items():
        figures = TABLE.JOINTS[name]
        limit = joint.find('limit')
        assert joint.get('type') == 'revolute'
        assert joint.find('parent').get('link') == figures.parent
        assert joint.find('child').get('link') == figures.child
        assert _floats(joint.find('origin').get('xyz')) == list(figures.origin_m), name
        assert _floats(joint.find('origin').get('rpy')) == [0, 0, 0], name
        assert _floats(joint.find('axis').get('xyz')) == list(figures.axis), name
        assert float(limit.get('lower')) == figures.lower_rad, name
        assert float(limit.get('upper')) == figures.upper_rad, name
        assert float(limit.get('effort')) == figures.effort_nm, name
        assert float(limit.get('velocity')) == figures.velocity_rad_s, name
        assert float(joint.find('dynamics').get('damping')) == figures.damping_nms, name
    links = {link.get('name'): link for link in root.findall('link')}
    assert set(links) | {'head'} == set(TABLE.LINKS)
    total = 0.0
    for name, link in links.items():
        inertial = link.find('inertial')
        mass = float(inertial.find('mass').get('value'))
        total += mass
        assert mass == TABLE.LINKS[name].mass_kg, name
        assert _floats(inertial.find('origin').get('xyz')) == list(TABLE.LINKS[name].com_m), name
        inertia = inertial.find('inertia')
        assert tuple(float(inertia.get(k)) for k in ('ixx', 'iyy', 'izz', 'ixy', 'ixz', 'iyz')) \
            == TABLE.LINKS[name].inertia, name
    head = ET.parse(REFERENCE / 'multisense_sl_head.urdf').getroot().find("link[@name='head']")
    head_mass = float(head.find('inertial/mass').get('value'))
    assert head_mass == TABLE.LINKS['head'].mass_kg
    inertia = head.find('inertial/inertia')
    assert tuple(float(inertia.get(k)) for k in ('ixx', 'iyy', 'izz', 'ixy', 'ixz', 'iyz')) \
        == TABLE.LINKS['head'].inertia
    assert total + head_mass == pytest.approx(TABLE.REFERENCE_TOTAL_MASS_KG, rel=1e-12)
    assert model.load_model().model.body_subtreemass[1] == \
        pytest.approx(total + head_mass, rel=1e-3)


@needs_reference
def test_foot_sole_matches_simple_shapes_urdf() -> None:
    root = ET.parse(REFERENCE / 'atlas_v1_simple_shapes.urdf').getroot()
    for side in 'lr':
        collision = root.find(f"link[@name='{side}_foot']/collision")
        assert _floats(collision.find('geometry/box').get('size')) == list(TABLE.SOLE_SIZE_M)
        assert _floats(collision.find('origin').get('xyz')) == list(TABLE.SOLE_POS_M)


@needs_reference
def test_gains_config_matches_drcsim() -> None:
    yaml = pytest.importorskip('yaml')
    reference = yaml.safe_load((REFERENCE / 'atlas_controller_gains.yaml').read_text())
    expected = controller.gains_from_params(reference['atlas_controller']['gains'])
    ours = controller.load_gains_yaml(GAINS_YAML)
    for key in ('p', 'i', 'd', 'i_clamp'):
        np.testing.assert_array_equal(getattr(ours, key), getattr(expected, key), err_msg=key)
