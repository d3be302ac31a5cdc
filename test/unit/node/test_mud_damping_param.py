"""The node's ~mud_damping: checked at start (one line), the simulator's mud takes it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
import yaml

from tutorial_atlas_control.sim import MODEL_PATH

sim_node = pytest.importorskip('tutorial_atlas_control.node.sim_node',
                               reason='needs the catkin workspace: source ./env.sh')

CONFIG = Path(__file__).resolve().parents[3] / 'config' / 'atlas_controller.yaml'


@pytest.fixture
def params(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> dict[str, Any]:
    """The node's parameters, a world with mud as its model."""
    world = tmp_path / 'atlas_in_mud.xml'
    world.write_text(MODEL_PATH.read_text().replace(
        '<body name="pelvis"', '<geom name="mud_atlas" type="box" size="1 1 0.2" '
        'pos="0 0 0.15" contype="0" conaffinity="0"/>\n    <body name="pelvis"', 1))
    values: dict[str, Any] = {
        'atlas_controller/gains': yaml.safe_load(CONFIG.read_text())['atlas_controller']['gains'],
        '~model_file': str(world)}
    monkeypatch.setattr(sim_node.rospy, 'get_param',
                        lambda name, default=None: values.get(name, default))
    monkeypatch.setattr(sim_node.rospy, 'resolve_name', lambda name: '/atlas_sim/' + name[1:])
    monkeypatch.setattr(sim_node, 'SimNode', lambda sim, *args: sim)
    return values


@pytest.mark.parametrize('bad', ['forty', -1.0, float('nan'), True])
def test_a_bad_mud_damping_stops_the_node_in_one_line(params: dict[str, Any], bad: Any) -> None:
    params['~mud_damping'] = bad
    with pytest.raises(sim_node.AtlasControlError,
                       match=r'^parameter /atlas_sim/mud_damping must be a finite number >= 0 '
                             r'\(N s/m\), got .+$'):
        sim_node.build_node()


def test_the_mud_takes_the_parameter_and_the_config_says_it(params: dict[str, Any]) -> None:
    assert sim_node.build_node().mud.damping == 40.0
    params['~mud_damping'] = 70
    sim = sim_node.build_node()
    assert sim.mud.damping == 70.0
    assert sim.config().to_dict()['mud_damping'] == 70.0
