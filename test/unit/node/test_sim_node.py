"""The simulator node's set-up from parameters and its rospy shell, without a ROS master."""

from __future__ import annotations

import hashlib
import math
import shutil
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
import yaml

from tutorial_atlas_control import topics
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.sim.sim_config import SimConfig
from tutorial_atlas_control.sim.simulator import AtlasSimulator, ControlMode, PhysicsDivergenceError
from tutorial_atlas_control.sim.vrc import ModeInput, VrcMode
from tutorial_atlas_control.stepping.course_scoring import CourseScoring

sim_node = pytest.importorskip('tutorial_atlas_control.node.sim_node',
                               reason='needs the catkin workspace: source ./env.sh')

CONFIG = Path(__file__).resolve().parents[3] / 'config' / 'atlas_controller.yaml'


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
            topics.SIM_CONFIG, topics.ATLAS_STATE, topics.FORCE_TORQUE_SENSORS,
            topics.DEBUG_L_FOOT_CONTACT, topics.DEBUG_R_FOOT_CONTACT, topics.SIM_INPUTS,
            topics.CURRENT_CONTROL_MODE, topics.SYNCHRONIZATION_STATISTICS, topics.ASI_STATE,
            topics.ASI_STATE_RECORDED, topics.RENDER_STATE, topics.LASER_SCAN,
            topics.HEAD_JOINT_STATES, topics.HEAD_IMU}
        config, = node.fake_publishers[topics.SIM_CONFIG].published
        mode, = node.fake_publishers[topics.CURRENT_CONTROL_MODE].published
        assert mode.data == 'Stand'
        node.on_control_mode(SimpleNamespace(data='User'))
        assert node.fake_publishers[topics.CURRENT_CONTROL_MODE].published[-1].data == 'User'
        assert SimConfig.from_json(config.data) == sim.config()
    assert sim.sim_time_ns == 50 * sim.step_ns


@pytest.mark.parametrize(('sent', 'taken', 'warnings'), [
    (2.0, 2.0, 0), (9.0, 50 * 2 * math.pi / 60, 1), (-1.0, 0.0, 1), (math.nan, 0.0, 1)])
def test_set_spindle_speed_is_clamped_or_ignored_with_one_warning(
        sim: AtlasSimulator, sent: float, taken: float, warnings: int) -> None:
    """DRCSim's limits (0..50 RPM), NaN ignored (the spindle keeps its speed, here 0)."""
    from support.fake_rospy import fake_ros_node

    with fake_ros_node(sim, steps=1) as node:
        sim_node.rospy.logwarn_throttle.reset_mock()
        node.on_spindle_speed(SimpleNamespace(data=sent))
        assert node.loop.publisher.head.spindle.target == pytest.approx(taken)
        assert sim_node.rospy.logwarn_throttle.call_count == warnings


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


def test_refusals_are_throttled_per_topic(monkeypatch: pytest.MonkeyPatch) -> None:
    """One line per topic and kind every WARN_THROTTLE_S: a JointCommands flood does not hide
    a refused AtlasCommand."""
    lines: list[str] = []
    monkeypatch.setattr(sim_node.rospy, 'logwarn', lines.append)
    now_s = [0.0]
    log = sim_node.RosLog(clock=lambda: now_s[0])
    for _ in range(3):
        log.refused_command('refused /atlas/joint_commands: a', topics.JOINT_COMMANDS)
        log.refused_command('refused /atlas/atlas_command: b', topics.ATLAS_COMMAND)
        log.kept_fields('/atlas/atlas_command: c', topics.ATLAS_COMMAND)
        now_s[0] += 0.5
    now_s[0] = sim_node.WARN_THROTTLE_S
    log.refused_command('refused /atlas/joint_commands: d', topics.JOINT_COMMANDS)
    assert lines == ['refused /atlas/joint_commands: a', 'refused /atlas/atlas_command: b',
                     '/atlas/atlas_command: c', 'refused /atlas/joint_commands: d']


def test_the_node_hands_atlas_command_and_test_to_the_loop_in_order(sim: AtlasSimulator) -> None:
    from support.fake_rospy import fake_ros_node
    from tutorial_atlas_control.msgs.atlas_command import encode_atlas_command, encode_test

    with fake_ros_node(sim, steps=0) as node:
        command, test = sim_node.RawAtlasCommand(), sim_node.RawTest()
        node.on_atlas_command(command.deserialize(encode_atlas_command(0, {})))
        node.on_test(test.deserialize(encode_test(0, {})))
        assert [topic for topic, _raw in node.loop.inbox.pending] == [
            topics.ATLAS_COMMAND, topics.ATLAS_TEST]
        assert sim_node.RawAtlasCommand._md5sum == '3a56dd1f50633ad975636160b665384a'
        assert sim_node.RawTest._md5sum == '62f63cd4b6db15007d8d3d4a23411c4c'


# -- VRCPlugin's topics and /gazebo/reset_models --------------------------------------------

def _subscribed(topic: str) -> Any:
    """The callback the node subscribed to `topic` (rospy.Subscriber is a mock here)."""
    for call in sim_node.rospy.Subscriber.call_args_list:
        if call.args[0] == topic:
            return call.args[2]
    raise AssertionError(f'{topic} is not subscribed')


def _bad_and_good_messages() -> list[tuple[str, Any, Any, str]]:
    import genpy
    from geometry_msgs.msg import Point, Pose, Quaternion, Twist, Vector3, Wrench
    from std_msgs.msg import String
    from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

    def trajectory(names: list[str], times_s: list[float]) -> JointTrajectory:
        return JointTrajectory(joint_names=names, points=[
            JointTrajectoryPoint(positions=[0.1] * len(names),
                                 time_from_start=genpy.Duration.from_sec(t)) for t in times_s])
    nan = float('nan')
    return [
        (topics.MODE, String(data='flying'), String(data='pinned'),
         "unknown mode 'flying'; valid modes: harnessed, pinned"),
        (topics.SET_POSE, Pose(Point(nan, 0, 1), Quaternion(0, 0, 0, 1)),
         Pose(Point(0, 0, 1), Quaternion(0, 0, 0, 1)), 'position is not finite (nan)'),
        (topics.CMD_VEL, Twist(Vector3(0, 0, 0), Vector3(0, 0, float('inf'))),
         Twist(Vector3(0.1, 0, 0), Vector3(0, 0, 0)), 'angular velocity is not finite (inf)'),
        (topics.APPLY_PELVIS_FORCE, Wrench(Vector3(1e9, 0, 0), Vector3(0, 0, 0)),
         Wrench(Vector3(30, 0, 0), Vector3(0, 0, 0)), 'force 1e+09 exceeds 100000'),
        (topics.JOINT_TRAJECTORY, trajectory(['l_arm_shx', 'wing'], [0.0]),
         trajectory(['l_arm_shx'], [0.0, 0.1]), "unknown joint name 'wing'"),
        (topics.JOINT_TRAJECTORY, trajectory(['l_arm_shx'], [0.2, -0.1]),
         trajectory(['l_arm_shx'], [0.0, 0.1]), 'point 1 time_from_start -0.1 s is negative'),
    ]


def test_each_cheat_refuses_bad_input_in_one_line_and_applies_good_input(
        sim: AtlasSimulator) -> None:
    from support.fake_rospy import fake_ros_node

    with fake_ros_node(sim, steps=5) as node:
        rospy = sim_node.rospy
        for topic, bad, good, reason in _bad_and_good_messages():
            rospy.logwarn_throttle_identical.reset_mock()
            before = sim.data.qpos.copy()
            _subscribed(topic)(bad)
            (_, text), _ = rospy.logwarn_throttle_identical.call_args
            assert text.startswith(f'refused {topic}: ') and reason in text, text
            assert text.endswith('; nothing applied') and '\n' not in text
            assert not sim.inputs_since_reset and not sim.vrc.active
            assert (sim.data.qpos == before).all()
            _subscribed(topic)(good)
            assert sim.inputs_since_reset == 1
            event = node.fake_publishers[topics.SIM_INPUTS].published[-1].data
            assert '"seq": 0' in event and '"time_ns": 0' in event
            node.loop.reset_world()
        assert node.spin() == 0  # and it keeps stepping
    assert sim.sim_time_ns == 5 * sim.step_ns


def test_a_drcsim_era_trajectory_is_clamped_and_run_on_with_one_line_each(
        sim: AtlasSimulator) -> None:
    """As the animate-joints tutorial sends it: past the limits, every time 0.01 s."""
    import genpy
    from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

    from support.fake_rospy import fake_ros_node

    msg = JointTrajectory(joint_names=['atlas::l_arm_ely', 'atlas::l_arm_shx'], points=[
        JointTrajectoryPoint(positions=[-0.5 * k, 0.1 * k],
                             time_from_start=genpy.Duration(0, 10_000_000)) for k in range(3)])
    msg.header.frame_id = 'atlas::pelvis'
    with fake_ros_node(sim, steps=0) as node:
        rospy = sim_node.rospy
        rospy.logwarn.reset_mock()
        rospy.loginfo.reset_mock()
        _subscribed(topics.JOINT_TRAJECTORY)(msg)
        assert [call.args for call in rospy.logwarn.call_args_list] == [(
            "/joint_trajectory: positions outside their joints' limits, clamped to the limits: "
            'l_arm_ely by up to 1 rad beyond [0, 3.14159] (2 of 3 points)',)]
        assert [call.args for call in rospy.loginfo.call_args_list] == [(
            '/joint_trajectory: time_from_start does not increase (point 1: 0.01 s after '
            "0.01 s), read as DRCSim 2.5.2 read it: each point's time_from_start added to the "
            "previous point's time; the 3 points play over 0.02 s",),
            ('applied at t=0.000 s: /joint_trajectory 2 joints, 3 points',)]
        assert sim.inputs_since_reset == 1 and sim.playing
        event = node.fake_publishers[topics.SIM_INPUTS].published[-1].data
        assert '"positions": [[0.0, 0.0], [0.0, 0.1], [0.0, 0.2]]' in event
        assert '"times_ns": [0, 10000000, 20000000]' in event


def test_configuration_is_logged_as_not_implemented_and_reset_models_is_reset_world(
        sim: AtlasSimulator) -> None:
    from sensor_msgs.msg import JointState

    from support.fake_rospy import fake_ros_node

    with fake_ros_node(sim, steps=0) as node:
        rospy = sim_node.rospy
        _subscribed(topics.CONFIGURATION)(JointState(name=['l_arm_shx'], position=[1.0]))
        (_, text), _ = rospy.logerr_throttle.call_args
        assert text == '/atlas/configuration is not implemented (nor was it in DRCSim); ' \
                       'nothing applied'
        services = {call.args[0]: call.args[2] for call in rospy.Service.call_args_list}
        assert set(services) >= {topics.RESET_WORLD_SERVICE, topics.RESET_MODELS_SERVICE}
        node.loop.apply_input(ModeInput(VrcMode.NO_GRAVITY))
        services[topics.RESET_MODELS_SERVICE](None)
        assert not sim.vrc.active and not sim.inputs_since_reset and sim.pinned


def test_startup_mode_parameter_is_checked(monkeypatch: pytest.MonkeyPatch) -> None:
    params: dict[str, Any] = {
        'atlas_controller/gains': yaml.safe_load(CONFIG.read_text())['atlas_controller']['gains'],
        topics.STARTUP_MODE_PARAM: 'harnessed'}
    monkeypatch.setattr(sim_node.rospy, 'get_param',
                        lambda name, default=None: params.get(name, default))
    monkeypatch.setattr(sim_node.rospy, 'set_param', params.__setitem__)
    with pytest.raises(sim_node.AtlasControlError,
                       match='^parameter /atlas/startup_mode must be one of pinned_with_gravity, '
                             "pinned, bdi_stand, got 'harnessed'$"):
        sim_node.build_node()
    params[topics.STARTUP_MODE_PARAM] = 'bdi_stand'
    monkeypatch.setattr(sim_node, 'SimNode', lambda sim, *args: sim)
    assert sim_node.build_node().startup_mode is VrcMode.BDI_STAND


def test_start_parameter_places_the_robot_and_a_bad_one_is_one_line(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """~start: the pelvis at the start's (x, y) and yaw on the model's ground, named in
    /atlas/sim_config; a bad start stops the node with one line naming the parameter."""
    params: dict[str, Any] = {
        'atlas_controller/gains': yaml.safe_load(CONFIG.read_text())['atlas_controller']['gains'],
        '~start': '2 -1.5 0.9 nope'}
    monkeypatch.setattr(sim_node.rospy, 'get_param',
                        lambda name, default=None: params.get(name, default))
    monkeypatch.setattr(sim_node.rospy, 'set_param', params.__setitem__)
    monkeypatch.setattr(sim_node.rospy, 'resolve_name', lambda name: '/atlas_sim/start')
    with pytest.raises(sim_node.AtlasControlError,
                       match="^parameter /atlas_sim/start: start '2 -1.5 0.9 nope': yaw 'nope' "
                             'is not a finite number'):
        sim_node.build_node()
    params['~start'] = '2 -1.5 0.9 1.5707963267948966'
    monkeypatch.setattr(sim_node, 'SimNode', lambda sim, *args: sim)
    sim = sim_node.build_node()
    position, quat = atlas_model.pelvis_pose(sim.atlas, sim.data)
    np.testing.assert_allclose(position, (2.0, -1.5, atlas_model.SPAWN_HEIGHT_M), atol=1e-9)
    np.testing.assert_allclose(quat, (0.5 ** 0.5, 0.0, 0.0, 0.5 ** 0.5), atol=1e-9)
    assert sim.config().to_dict()['start'] == '2.0 -1.5 0.9 1.5707963267948966'


def test_tf_publisher_parameter_chooses_who_publishes_the_links(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """~tf_publisher: sim (default) sets /robot_description and hands the loop the links;
    robot_state_publisher leaves both to state_publisher.py; anything else is refused."""
    params: dict[str, Any] = {
        'atlas_controller/gains': yaml.safe_load(CONFIG.read_text())['atlas_controller']['gains']}
    monkeypatch.setattr(sim_node.rospy, 'get_param',
                        lambda name, default=None: params.get(name, default))
    monkeypatch.setattr(sim_node.rospy, 'set_param', params.__setitem__)
    monkeypatch.setattr(sim_node.rospy, 'resolve_name', lambda name: '/atlas_sim/' + name[1:])
    built: list[tuple[Any, ...]] = []
    monkeypatch.setattr(sim_node, 'SimNode', lambda *args: built.append(args))
    sim_node.build_node()
    tf, links = built[-1][3], built[-1][1].links  # SimNode(sim, settings, gui, tf, ...)
    assert tf and links.frames[:2] == (('pelvis', 'ltorso'), ('ltorso', 'mtorso'))
    # The 28 joints of /atlas/joint_states (not the spindle: the head's part publishes it);
    # the head's six fixed sensor frames on /tf_static.
    assert len(links) == 28 and 'hokuyo_joint' not in links.joint_names
    assert [(fixed.parent, fixed.child) for fixed in links.static][:2] == [
        ('hokuyo_link', 'head_hokuyo_frame'), ('head', 'head_imu_link')]
    assert len(links.static) == 6
    assert params[topics.ROBOT_DESCRIPTION_PARAM].startswith('<?xml')
    del params[topics.ROBOT_DESCRIPTION_PARAM]
    params['~tf_publisher'] = 'robot_state_publisher'
    sim_node.build_node()
    assert built[-1][3] and built[-1][1].links is None
    assert topics.ROBOT_DESCRIPTION_PARAM not in params
    params['~tf_publisher'] = 'rsp'
    with pytest.raises(sim_node.AtlasControlError,
                       match="^parameter /atlas_sim/tf_publisher must be one of sim, "
                             "robot_state_publisher, got 'rsp'$"):
        sim_node.build_node()


def test_vrc_scoring_parameters_choose_the_score_dir(monkeypatch: pytest.MonkeyPatch,
                                                     tmp_path: Path) -> None:
    """~vrc_scoring (false by default) scores into ~score_dir (DRCSim's /tmp/vrc_task_2 by
    default); a non-bool ~vrc_scoring and a score_dir that cannot be made are one line."""
    params: dict[str, Any] = {
        'atlas_controller/gains': yaml.safe_load(CONFIG.read_text())['atlas_controller']['gains'],
        '~tf': False}
    monkeypatch.setattr(sim_node.rospy, 'get_param',
                        lambda name, default=None: params.get(name, default))
    monkeypatch.setattr(sim_node.rospy, 'resolve_name', lambda name: '/atlas_sim/' + name[1:])
    built: list[tuple[Any, ...]] = []
    monkeypatch.setattr(sim_node, 'SimNode', lambda *args: built.append(args))
    sim_node.build_node()
    assert built[-1][1].score_dir is None
    params['~vrc_scoring'] = True
    sim_node.build_node()
    assert built[-1][1].score_dir == Path('/tmp/vrc_task_2')
    params['~score_dir'] = str(tmp_path / 'scores')
    sim_node.build_node()
    assert built[-1][1].score_dir == tmp_path / 'scores'
    params['~vrc_scoring'] = 'yes'
    with pytest.raises(sim_node.AtlasControlError,
                       match="^parameter /atlas_sim/vrc_scoring must be true or false, "
                             "got 'yes'$"):
        sim_node.build_node()
    blocker = tmp_path / 'file'
    blocker.write_text('')
    sim = AtlasSimulator(atlas_model.load_model(), load_gains_yaml(CONFIG))
    with pytest.raises(sim_node.AtlasControlError, match=r'^score log .*/file/score.log cannot '
                                                          r'be written: .*/file is not a '
                                                          r'directory$'):
        CourseScoring(sim, blocker)  # the loop's, from LoopSettings.score_dir
