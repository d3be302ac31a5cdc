"""Issue 27's gravity-stiffness figures, checked against the model: with the tutorial's gains
single support is statically unstable at the stance hip roll and ankle roll; with
config/stepping_gains.yaml it is not."""

from __future__ import annotations

from pathlib import Path

import pytest

from support.statics import gravity_stiffness
from tutorial_atlas_control.joints import JOINT_INDEX
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import load_gains_yaml

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope='module')
def atlas() -> atlas_model.AtlasModel:
    return atlas_model.load_model()


def test_the_issue_figures_hold_for_the_stance_hip_roll(atlas: atlas_model.AtlasModel) -> None:
    """The issue: about 75 kg whose centre of mass is about 0.17 m above the hip roll,
    about 121 N m/rad. The model: 76.5 kg, 0.175 m, 131 N m/rad."""
    hip = gravity_stiffness(atlas, 'l_leg_mhx')
    assert hip.mass_kg == pytest.approx(75.0, abs=2.5)
    assert hip.height_m == pytest.approx(0.17, abs=0.01)
    assert hip.stiffness_nm_rad == pytest.approx(121.0, rel=0.1)


def test_the_issue_figure_holds_for_the_stance_ankle_roll(atlas: atlas_model.AtlasModel) -> None:
    """The issue: about 800 N m/rad at the ankle roll. The model: 89.0 kg at 0.943 m, 824."""
    ankle = gravity_stiffness(atlas, 'l_leg_lax')
    assert ankle.mass_kg == pytest.approx(89.0, abs=0.5)
    assert ankle.stiffness_nm_rad == pytest.approx(800.0, rel=0.05)


def test_the_two_legs_are_mirror_images(atlas: atlas_model.AtlasModel) -> None:
    for joint in ('mhx', 'lax'):
        left = gravity_stiffness(atlas, f'l_leg_{joint}')
        right = gravity_stiffness(atlas, f'r_leg_{joint}')
        assert left.stiffness_nm_rad == pytest.approx(right.stiffness_nm_rad, rel=1e-3)


@pytest.mark.parametrize(('gains_file', 'holds'), [
    (REPO / 'config' / 'atlas_controller.yaml', False),
    (REPO / 'config' / 'stepping_gains.yaml', True),
])
def test_which_gains_hold_one_leg(atlas: atlas_model.AtlasModel, gains_file: Path,
                                  holds: bool) -> None:
    """p against m·g·h at the stance roll joints: the tutorial's mhx 100 and lax 300 are
    below (its step falls), the stepping gains above."""
    gains = load_gains_yaml(gains_file)
    for joint in ('l_leg_mhx', 'l_leg_lax'):
        p = float(gains.p[JOINT_INDEX[joint]])
        assert (p > gravity_stiffness(atlas, joint).stiffness_nm_rad) is holds, joint
