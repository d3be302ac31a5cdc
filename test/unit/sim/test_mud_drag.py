"""sim.mud: DRCSim's MudPlugin in MuJoCo — a foot dropped through the mud, and Atlas in it."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.course import MUD_DAMPING, CourseError
from tutorial_atlas_control.sim import (
    DEFAULT_GAINS_FILE,
    MODEL_PATH,
    AtlasSimulator,
    MudDrag,
    load_gains_yaml,
    load_model,
)
from tutorial_atlas_control.sim.model import ModelError
from tutorial_atlas_control.sim.vrc import WrenchInput

GRAVITY = np.array([0.0, 0.0, -9.81])
#: The mud: 0.5 m deep, its top at z = 0 (a foot falls through it and out of its bottom).
#: Euler, so that a step's velocity change is exactly dt times its acceleration (MuJoCo 4's
#: implicitfast also folds a free body's gyroscopic term into the step).
FOOT_IN_MUD_XML = """
<mujoco>
  <option timestep="0.001" integrator="Euler" gravity="0 0 -9.81"/>
  <worldbody>
    <geom name="mud_atlas" type="box" size="1 1 0.25" pos="0 0 -0.25"
          contype="0" conaffinity="0"/>
    <body name="l_foot" pos="0 0 0.1">
      <freejoint/>
      <inertial pos="0.02 0 0.01" mass="1.634" diaginertia="0.002 0.007 0.008"/>
      <geom type="box" size="0.13 0.0624 0.005" pos="0.048 0 -0.02"/>
    </body>
  </worldbody>
</mujoco>
"""


#: One step of the foot's run: touched, the drag at the point, the point, two twists.
FootStep = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def _foot_run(tmp_path: Path, steps: int) -> list[FootStep]:
    """Drop the foot, spinning, into the mud; per step: whether it touched, the drag at
    the point (6,), the point, the link's twist at the point at the step's start and the
    twist the drag alone left at the step's end (both (6,), v then w)."""
    path = tmp_path / 'foot_in_mud.xml'
    path.write_text(FOOT_IN_MUD_XML)
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    data.qvel[:] = [0.3, -0.2, -2.0, 4.0, -3.0, 5.0]
    mud = MudDrag.for_model(model, path)
    assert mud is not None
    jac = np.zeros((6, model.nv))
    out = []
    for _ in range(steps):
        mujoco.mj_step1(model, data)
        touched = mud.update(data, model.opt.timestep)
        data.xfrc_applied[:] = mud.xfrc
        before = data.qvel.copy()
        mujoco.mj_step2(model, data)
        if not touched:
            out.append((np.array(False), mud.xfrc[1].copy(), np.zeros(3), np.zeros(6),
                        np.zeros(6)))
            continue
        point = mud.points_m[0].copy()
        mujoco.mj_jac(model, data, jac[0:3], jac[3:6], point, 1)  # the step's start pose
        # The velocity without gravity's and the gyroscopic terms' share of this step.
        others = np.zeros((1, model.nv))
        mujoco.mj_solveM(model, data, others, -data.qfrc_bias[None, :].copy())
        after = data.qvel - model.opt.timestep * others[0]
        at_com = mud.xfrc[1]
        arm = point - data.xipos[1]
        at_point = np.concatenate((at_com[0:3], at_com[3:6] - np.cross(arm, at_com[0:3])))
        out.append((np.array(True), at_point, point, jac @ before, jac @ after))
    return out


def test_a_foot_in_the_mud_feels_minus_c_times_its_twist_at_the_contact_point(
        tmp_path: Path) -> None:
    run = _foot_run(tmp_path, 1500)
    touching = [row for row in run if row[0]]
    assert len(touching) > 100
    for step, (_, wrench, point, start, end) in enumerate(touching):
        # ODE's soft joint: -c times the twist the drag leaves at the step's end.
        np.testing.assert_allclose(wrench, -MUD_DAMPING * end, atol=1e-9)
        # Once the first few steps have taken the foot's spin (c dt / I = 20 about its
        # long axis), the force is -c v at the step's start within c dt |A|: about 8 % at
        # this point (1/m and the lever arm's r^2/I). The torque is not compared so: the
        # force at the point turns the foot within the step as much as w itself.
        if step >= 5:
            assert np.linalg.norm(wrench[0:3] + MUD_DAMPING * start[0:3]) \
                <= 0.1 * MUD_DAMPING * np.linalg.norm(start[0:3])
        assert -0.25 - 0.5 <= point[2] <= 0.0 + 1e-9  # within the mud's depth


def test_the_drag_starts_with_contact_and_is_gone_when_the_foot_leaves_the_mud(
        tmp_path: Path) -> None:
    run = _foot_run(tmp_path, 4000)
    touched = np.array([bool(row[0]) for row in run])
    first, last = int(np.argmax(touched)), len(touched) - 1 - int(np.argmax(touched[::-1]))
    assert 0 < first < last < len(run) - 100, 'the foot enters and leaves the mud'
    assert touched[first:last + 1].all()
    assert not np.any([row[1] for row in run[:first]])
    assert not np.any([row[1] for row in run[last + 1:]])
    # In the mud it sinks at about its terminal speed m g / c (0.4 m/s), not 2 m/s.
    assert abs(run[last][3][2]) < 0.6


def _mud_model(tmp_path: Path, centre: str, half_size: str = '1 1 0.2',
               sleep: bool = False) -> Path:
    """Atlas with a mud box (contype and conaffinity 0) in its world; with `sleep`, MuJoCo's
    sleeping bodies enabled, as in the VRC world (its collision then reads body poses)."""
    box = (f'<geom name="mud_atlas" type="box" size="{half_size}" pos="{centre}" '
           'contype="0" conaffinity="0" group="1"/>\n    <body name="pelvis"')
    text = MODEL_PATH.read_text().replace('<body name="pelvis"', box, 1)
    if sleep:
        text = text.replace('cone="elliptic"/>', 'cone="elliptic"><flag sleep="enable"/></option>',
                            1)
    path = tmp_path / 'atlas_mud.xml'
    path.write_text(text)
    return path


def _sim(path: Path, **kwargs: float) -> AtlasSimulator:
    return AtlasSimulator(load_model(path), load_gains_yaml(DEFAULT_GAINS_FILE),
                          time_to_unpin_s=0.1, **kwargs)


def test_without_a_mud_box_nothing_runs_and_the_config_is_unchanged() -> None:
    sim = _sim(MODEL_PATH)
    assert sim.mud is None
    assert 'mud_damping' not in sim.config().to_dict()


def test_mud_far_away_changes_nothing_bit_for_bit(tmp_path: Path) -> None:
    plain, far = _sim(MODEL_PATH), _sim(_mud_model(tmp_path, '50 50 0'))
    assert far.mud is not None
    for _ in range(300):
        plain.step()
        far.step()
        assert not len(far.mud.touching)
    np.testing.assert_array_equal(plain.data.qpos, far.data.qpos)
    np.testing.assert_array_equal(plain.data.qvel, far.data.qvel)


def test_atlas_standing_in_mud_replays_exactly_with_its_torques_and_inputs(
        tmp_path: Path) -> None:
    path = _mud_model(tmp_path, '0 0 0.15')
    live, replay = _sim(path, mud_damping=70.0), _sim(path, mud_damping=70.0)
    assert live.config().mud_damping == 70.0
    wrench = WrenchInput((5.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    live.apply_input(wrench)
    replay.apply_input(wrench)
    viewer = np.zeros_like(live.data.xfrc_applied)
    viewer[1] = [1.0, 2.0, 3.0, 0.0, 0.0, 0.0]  # a mouse force the viewer holds
    live.data.xfrc_applied[:] = viewer
    replay.data.xfrc_applied[:] = viewer
    touched = set()
    for _ in range(600):
        live.step()
        touched.update(live.mud.bodies[live.mud.touching].tolist())
        replay.step(live.torque_nm.copy())
        np.testing.assert_array_equal(replay.data.qpos, live.data.qpos)
        np.testing.assert_array_equal(replay.data.qvel, live.data.qvel)
        np.testing.assert_array_equal(live.data.xfrc_applied, viewer)
    assert touched == set(live.mud.bodies.tolist())  # both feet and both lower legs
    assert np.isfinite(live.data.qvel).all()


def test_bad_damping_and_a_mud_that_is_not_a_box_are_refused(tmp_path: Path) -> None:
    with pytest.raises(CourseError, match='finite number >= 0'):
        _sim(_mud_model(tmp_path, '0 0 0.15'), mud_damping=float('nan'))
    sphere = tmp_path / 'sphere.xml'
    sphere.write_text(_mud_model(tmp_path, '0 0 0.15').read_text().replace(
        'name="mud_atlas" type="box"', 'name="mud_atlas" type="sphere"'))
    with pytest.raises(ModelError, match="'mud_atlas' must be a box"):
        _sim(sphere)


def test_the_contact_points_are_mujocos_own_for_a_box_that_collides(tmp_path: Path) -> None:
    # Away from the origin, where the bodies' poses matter to MuJoCo's broad phase too.
    path = _mud_model(tmp_path, '20 -15 0.15', sleep=True)
    model = mujoco.MjModel.from_xml_path(str(path))
    colliding = mujoco.MjModel.from_xml_string(
        path.read_text().replace('contype="0" conaffinity="0" group="1"', 'conaffinity="1"'))
    data, reference = mujoco.MjData(model), mujoco.MjData(colliding)
    mud = MudDrag.for_model(model, path)
    assert mud is not None
    link_of = {int(geom): link for geom, link in zip(mud.geoms, mud.geom_link)}
    rng = np.random.default_rng(1)
    links_seen = 0
    for _ in range(20):  # the legs bent at random, the pelvis at 0.8-1.0 m, turned
        data.qpos[:] = model.qpos0
        data.qpos[0:3] = [20.0, -15.0, 0.9 + rng.uniform(-0.1, 0.1)]
        data.qpos[3:7] = [np.cos(0.7), 0.0, 0.0, np.sin(0.7)]  # turned 80 degrees
        data.qpos[7:] += rng.normal(0.0, 0.2, model.nq - 7)
        mujoco.mj_forward(model, data)
        mud.update(data, 1e-3)
        reference.qpos[:] = data.qpos
        mujoco.mj_forward(colliding, reference)
        points: dict[int, list[np.ndarray]] = {}
        for contact in reference.contact[:reference.ncon]:
            other = [int(geom) for geom in contact.geom if geom != mud.mud_geom]
            if len(other) == 1 and other[0] in link_of:
                points.setdefault(link_of[other[0]], []).append(contact.pos.copy())
        assert sorted(points) == mud.touching.tolist()
        for row, link in enumerate(sorted(points)):
            np.testing.assert_allclose(mud.points_m[row], np.mean(points[link], axis=0),
                                       atol=1e-12)
        links_seen += len(points)
    assert links_seen > 40
