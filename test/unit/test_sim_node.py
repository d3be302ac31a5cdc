"""The simulator node's set-up from parameters, without a ROS master."""

from __future__ import annotations

import hashlib
import shutil
from pathlib import Path
from typing import Any

import pytest
import yaml

from tutorial_atlas_control.sim import model as atlas_model

sim_node = pytest.importorskip('tutorial_atlas_control.node.sim_node',
                               reason='needs the catkin workspace: source ./env.sh')

CONFIG = Path(__file__).resolve().parents[2] / 'config' / 'atlas_controller.yaml'


def test_model_parameter_names_the_loaded_model_in_sim_config(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Under `model:=`, /atlas/sim_config must name the model simulated, not the default.

    Replay checks the run's model by this sha1, and the divergence FATAL names this file.
    """
    variant = tmp_path / 'atlas_variant.xml'
    shutil.copyfile(atlas_model.MODEL_PATH, variant)
    with variant.open('a') as stream:
        stream.write('<!-- a variant: same physics, another checksum -->\n')
    params: dict[str, Any] = {
        'atlas_controller/gains': yaml.safe_load(CONFIG.read_text())['atlas_controller']['gains'],
        '~model_file': str(variant),
    }
    monkeypatch.setattr(sim_node.rospy, 'get_param',
                        lambda name, default=None: params.get(name, default))
    monkeypatch.setattr(sim_node, 'SimNode', lambda sim, *args: sim)

    sim = sim_node.build_node()

    config = sim.config().to_dict()
    assert config['model_file'] == 'atlas_variant.xml'
    assert config['model_sha1'] == hashlib.sha1(variant.read_bytes()).hexdigest()
    assert sim.atlas_path == variant
