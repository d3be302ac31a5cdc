"""The simulator node's set-up from parameters and its rospy shell, without a ROS master."""

from __future__ import annotations

import hashlib
import shutil
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest
import yaml

from tutorial_atlas_control import topics
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.sim.sim_config import SimConfig
from tutorial_atlas_control.sim.simulator import AtlasSimulator, ControlMode, PhysicsDivergenceError

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


# -- the rospy shell around the stepping loop, on a fake rospy (support.fake_rospy) --------

@pytest.fixture
def sim() -> AtlasSimulator:
    return AtlasSimulator(atlas_model.load_model(), load_gains_yaml(CONFIG))


def test_the_node_advertises_the_topics_and_steps_until_shutdown(sim: AtlasSimulator) -> None:
    from support.fake_rospy import fake_ros_node

    with fake_ros_node(sim, steps=50) as node:
        assert node.spin() == 0
        assert set(node.fake_publishers) == {
            topics.CLOCK, topics.JOINT_STATES, topics.GROUND_TRUTH_ODOM, topics.IMU,
            topics.L_FOOT_CONTACT, topics.R_FOOT_CONTACT, topics.CONTROLLER_STATISTICS,
            topics.SIM_CONFIG, topics.CURRENT_CONTROL_MODE}
        config, = node.fake_publishers[topics.SIM_CONFIG].published
        mode, = node.fake_publishers[topics.CURRENT_CONTROL_MODE].published
        assert mode.data == 'Stand'
        node.on_control_mode(SimpleNamespace(data='User'))
        assert node.fake_publishers[topics.CURRENT_CONTROL_MODE].published[-1].data == 'User'
        assert SimConfig.from_json(config.data) == sim.config()
    assert sim.sim_time_ns == 50 * sim.step_ns


def test_a_diverging_model_shuts_the_node_down_with_status_1(
        sim: AtlasSimulator, monkeypatch: pytest.MonkeyPatch) -> None:
    from support.fake_rospy import fake_ros_node

    def diverge() -> None:
        raise PhysicsDivergenceError('physics diverged at t=0.001 s')
    monkeypatch.setattr(sim, 'step', diverge)
    with fake_ros_node(sim, steps=50) as node:
        assert node.spin() == 1
        sim_node.rospy.signal_shutdown.assert_called_once_with(
            'physics diverges after every reset')
        assert sim_node.rospy.logfatal.call_count == 1


def test_an_unknown_control_mode_is_refused_and_the_mode_kept(sim: AtlasSimulator) -> None:
    from std_msgs.msg import String

    from support.fake_rospy import fake_ros_node

    with fake_ros_node(sim, steps=0) as node:
        node.on_control_mode(String(data='user'))
        warning = sim_node.rospy.logwarn_throttle.call_args.args[1]
        assert warning.startswith("refused /atlas/control_mode: unknown control mode 'user'")
        assert sim.mode is ControlMode.STAND
        node.on_control_mode(SimpleNamespace(data='User'))
        assert sim.mode is ControlMode.USER
