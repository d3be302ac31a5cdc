"""topics.INTERFACE is the one declaration of what the simulator publishes and subscribes
to: the stepping loop, the node's advertising and subscriptions, offline bags and the
recorder's topic list each agree with it, and it renders as the README's table."""

from __future__ import annotations

import os
import stat
import subprocess
from collections.abc import Callable
from pathlib import Path

import pytest

from tutorial_atlas_control import topics
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.sim.controller_statistics import CommandAgeStatistics
from tutorial_atlas_control.sim.sim_messages import SimMessages
from tutorial_atlas_control.sim.simulator import AtlasSimulator
from tutorial_atlas_control.stepping.loop import LoopSettings, SteppingLoop
from tutorial_atlas_control.stepping.outputs import LoopOutputs
from tutorial_atlas_control.stepping.schedule import steps_between

REPO = Path(__file__).resolve().parents[2]
CONFIG = REPO / 'config' / 'atlas_controller.yaml'
PUBLISHED = topics.Direction.PUBLISHED
#: The loop's rows, by name.
LOOP_ROWS = {topic.name: topic for topic in topics.INTERFACE if topic.delivery.loop}
#: Sent only while the synchronization window is on: not in a plain run.
CONDITIONAL = {topics.SYNCHRONIZATION_STATISTICS}
STEPS = 20


@pytest.fixture(scope='module')
def sim() -> AtlasSimulator:
    return AtlasSimulator(atlas_model.load_model(), load_gains_yaml(CONFIG))


class ListeningOutbox:
    """Every outlet heard; keeps what each was sent (replace keeps the latest)."""

    def __init__(self) -> None:
        self.queued: dict[str, list[bytes]] = {}

    def wanted(self, _outlet: str) -> bool:
        return True

    def add(self, outlet: str, data: bytes | bytearray) -> None:
        self.queued.setdefault(outlet, []).append(bytes(data))

    def replace(self, outlet: str, data: bytes | bytearray) -> None:
        self.queued.setdefault(outlet, []).append(bytes(data))

    def flush(self) -> None:
        pass


class QuietLog:
    def __getattr__(self, _name: str) -> Callable[..., None]:
        return lambda *_args: None


def test_each_row_is_well_formed() -> None:
    names = [topic.name for topic in topics.INTERFACE]
    assert len(names) == len(set(names)), 'a topic declared twice'
    filled = set(SimMessages.SENSOR_MESSAGES) | {'joint_state', 'atlas_state',
                                                  'force_torque_sensors', 'debug_l', 'debug_r',
                                                  'render_state'}
    for topic in topics.INTERFACE:
        assert topic.delivery.message in filled | {''}, topic.name
        assert not topic.delivery.loop or topic.direction is PUBLISHED, topic.name
        assert not topic.delivery.message or topic.delivery.loop, topic.name
    assert set(topics.RECORDED_TOPICS) == {t.name for t in topics.INTERFACE if t.recorded}
    assert {t.name: t.msg_type for t in topics.INTERFACE} == topics.MSG_TYPES


def test_the_loop_sends_the_tables_topics_at_the_tables_rates(sim: AtlasSimulator) -> None:
    """Every row of the loop's is sent (the window's statistics are at least wired; the
    standing robot's feet touch the ground), nothing else is, and each topic with a rate
    parameter comes at its default rate."""
    outbox = ListeningOutbox()
    outlets = {name: name for name in LOOP_ROWS}
    loop = SteppingLoop(sim, LoopOutputs(outbox, outlets, QuietLog(), lambda _json: None),
                        LoopSettings(), CommandAgeStatistics(sim.dt_s))
    left = [STEPS]
    loop.run(lambda: (left.__setitem__(0, left[0] - 1) or left[0] < 0))
    assert set(outbox.queued) <= set(LOOP_ROWS)
    assert set(outbox.queued) == set(LOOP_ROWS) - CONDITIONAL
    assert loop.gate.outlet == topics.SYNCHRONIZATION_STATISTICS
    for name, topic in LOOP_ROWS.items():
        if topic.rate.key and name not in CONDITIONAL:
            every = steps_between(topic.rate.default_hz, sim.dt_s)
            assert len(outbox.queued[name]) == STEPS // every + 1, name


def test_the_node_advertises_and_subscribes_to_the_tables_topics() -> None:
    """Names, types and latching as the table has them (without ~tf: no /tf, /tf_static)."""
    sim_node = pytest.importorskip('tutorial_atlas_control.node.sim_node',
                                   reason='needs the catkin workspace: source ./env.sh')
    from support.fake_rospy import fake_ros_node

    sim = AtlasSimulator(atlas_model.load_model(), load_gains_yaml(CONFIG))
    with fake_ros_node(sim, 0) as node:
        subscribed = {call.args[0]: call.args[1]._type
                      for call in sim_node.rospy.Subscriber.call_args_list}
        advertised = {topic: publisher.advertised
                      for topic, publisher in node.fake_publishers.items()}
    assert advertised == {  # /vrc_score only in a scored run (test_course_scoring.py)
        topic.name: (topic.msg_type, topic.delivery.latched) for topic in topics.INTERFACE
        if topic.direction is PUBLISHED
        and topic.name not in (topics.TF, topics.TF_STATIC, topics.VRC_SCORE)}
    assert subscribed == {topic.name: topic.msg_type for topic in topics.INTERFACE
                          if topic.direction is topics.Direction.SUBSCRIBED}


def test_an_offline_bag_has_the_tables_offline_topics(tmp_path: Path) -> None:
    """Types, publishing node and latching of each connection, as a live run's."""
    from rosbags.rosbag1 import Reader

    from tutorial_atlas_control.offline.player import PLAYER_NODE, SIMULATOR_NODE, run_offline

    trajectory = tmp_path / 'still.yaml'
    trajectory.write_text('still:\n  - [0.02, "' + ' '.join(['0'] * 28) + '"]\n')
    bag = tmp_path / 'run.bag'
    run_offline(str(trajectory), 'still', bag, settle_s=0.05, start_after_s=0.05,
                gains_file=CONFIG)
    with Reader(bag) as reader:
        connections = {c.topic: (c.msgtype, c.ext.callerid, bool(c.ext.latching))
                       for c in reader.connections}
    assert connections == {
        topic.name: (topic.msg_type.replace('/', '/msg/'),
                     SIMULATOR_NODE if topic.direction is PUBLISHED else PLAYER_NODE,
                     topic.delivery.latched)
        for topic in topics.INTERFACE if topic.delivery.offline}


@pytest.mark.parametrize('recorder', ['atlas_recorder', 'rosbag'])
def test_the_recorder_records_the_tables_recorded_topics(tmp_path: Path, recorder: str) -> None:
    """scripts/record_run.sh hands the recorder exactly RECORDED_TOPICS (a fake rosrun
    prints what it is given)."""
    bin_dir = tmp_path / 'bin'
    bin_dir.mkdir()
    rosrun = bin_dir / 'rosrun'
    rosrun.write_text('#!/bin/sh\nfor arg in "$@"; do echo "$arg"; done\n')
    rosrun.chmod(rosrun.stat().st_mode | stat.S_IXUSR)
    bag_dir = tmp_path / 'bags'
    env = {**os.environ, 'PATH': f'{bin_dir}{os.pathsep}{os.environ["PATH"]}'}
    done = subprocess.run(['bash', str(REPO / 'scripts' / 'record_run.sh'), str(bag_dir),
                           recorder], capture_output=True, text=True, env=env, timeout=60,
                          check=False)
    assert done.returncode == 0, done.stderr
    args = done.stdout.splitlines()
    given = args[args.index(f'{bag_dir}/atlas') + 1:args.index('__name:=recorder')]
    assert tuple(given) == topics.RECORDED_TOPICS
    assert set(given) == {topic.name for topic in topics.INTERFACE if topic.recorded}


def test_the_markdown_table_has_one_row_per_topic() -> None:
    lines = topics.markdown_table().splitlines()
    assert lines[0] == ('| Topic | Type | Direction | Rate (parameter, default) | On demand '
                        '| Recorded |')
    assert len(lines) == 2 + len(topics.INTERFACE)
    for line, topic in zip(lines[2:], topics.INTERFACE):
        cells = [cell.strip() for cell in line.strip('|').split('|')]
        assert cells[:3] == [f'`{topic.name}`', f'`{topic.msg_type}`', topic.direction.value]
        assert cells[4:] == [('yes' if topic.on_demand else 'no'),
                             ('yes' if topic.recorded else 'no')]
    assert ('| `/atlas/joint_states` | `sensor_msgs/JointState` | published | '
            '`~joint_states_rate` (1000 Hz) | no | yes |') in lines


def test_the_docs_interface_table_is_the_table() -> None:
    page = (Path(__file__).resolve().parents[2] / 'docs' / 'ros_interface.md').read_text()
    start = '<!-- interface-table: generated by topics.markdown_table() -->\n'
    assert start in page, 'docs/ros_interface.md lost its interface table'
    shown = page.split(start, 1)[1].split('<!-- /interface-table -->', 1)[0]
    assert shown == topics.markdown_table(), (
        'docs/ros_interface.md disagrees with topics.INTERFACE: paste topics.markdown_table()')
