"""Tests of bags.reader, records and rosbag1_fast: synthetic bags, fast paths against rosbags.

The fast reader and writer use rosbags internals (pinned in requirements.txt): the tests
against rosbags' public Reader and Writer here are the ones to run when the pin moves.
"""

from __future__ import annotations

import json
from dataclasses import fields, replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from rosbags.rosbag1 import Reader, Writer, WriterError
from rosbags.typesys import get_types_from_msg

from support.synthetic_bags import (
    STANDING_HEIGHT_M,
    TYPESTORE,
    Record,
    clock,
    control_mode,
    joint_commands,
    joint_state,
    odometry,
    run_records,
    tracking_records,
    unindexed_copy,
    write_bag,
)
from tutorial_atlas_control.bags import reader as bag_reader
from tutorial_atlas_control.bags.reader import BagData, read_bag
from tutorial_atlas_control.bags.records import IndexedBag, PublicBag, open_bag
from tutorial_atlas_control.bags.rosbag1_fast import BlockBagWriter, TopicConnection
from tutorial_atlas_control.bags.typestore import load_typestore
from tutorial_atlas_control.errors import AtlasControlError, BagAnalysisError
from tutorial_atlas_control.joints import JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.msgs.ros1_fields import parse_names_arrays

ELX = JOINT_NAMES.index('l_arm_elx')


def states(times_s, value_at=lambda t_s: np.zeros(NUM_JOINTS), **kwargs):
    return [joint_state(t_s, value_at(t_s), **kwargs) for t_s in times_s]


def sim_config(t_s: float, text: str) -> Record:
    msg = TYPESTORE.types['std_msgs/msg/String'](data=text)
    return Record('/atlas/sim_config', 'std_msgs/String', t_s, msg)


def assert_same_bag_data(fast: BagData, public: BagData) -> None:
    """Every field equal; arrays element by element (NaN equal to NaN)."""
    for name in ('path', 'start_time_s', 'duration_s', 'topics', 'modes', 'sim_configs',
                 'warnings'):
        assert getattr(fast, name) == getattr(public, name), name
    for name in ('joint_states', 'commands', 'pelvis'):
        fast_series, public_series = getattr(fast, name), getattr(public, name)
        assert (fast_series is None) == (public_series is None), name
        for column in fields(fast_series) if fast_series is not None else ():
            expected = getattr(public_series, column.name)
            if isinstance(expected, np.ndarray):
                np.testing.assert_array_equal(getattr(fast_series, column.name), expected,
                                              err_msg=f'{name}.{column.name}')
            else:
                assert getattr(fast_series, column.name) == expected, f'{name}.{column.name}'


# ---------------------------------------------------------------- fast path vs rosbags' public API


#: A run as the simulator records it (the numpy parsers apply), with a reset's sim_config...
STANDARD = run_records(0.3) + [sim_config(0.0, '{"timestep": 0.001}'),
                               sim_config(0.2, '{"last_reset_time": 0.2}')]
#: ...and messages the numpy parsers decline: joint names that change, unknown, prefixed
#: or absent, unstamped commands, states stamped 0 but recorded later.
IRREGULAR = [
    joint_state(0.0, [0.1, 0.2], names=['atlas::l_leg_kny', 'l_arm_elx']),
    replace(joint_state(0.0, [0.3], names=['l_arm_elx']), t_s=0.012),
    joint_state(0.02, np.ones(NUM_JOINTS), np.ones(NUM_JOINTS), np.ones(NUM_JOINTS), names=()),
    joint_commands(0.01, [1.0, 0.5], names=['atlas::hokuyo_joint', 'neck_ay']),
    joint_commands(0.015, np.zeros(NUM_JOINTS), stamp_s=0.0),
    odometry(0.0, 0.9), odometry(0.01, 0.4, x_m=0.1), control_mode(0.0, 'Stand'),
    control_mode(0.01, 'User'), clock(0.0), clock(0.02),
]


@pytest.mark.parametrize('records', ['standard', 'irregular'])
@pytest.mark.parametrize('compression', [None, 'bz2', 'lz4'])
def test_fast_path_equals_public_api(tmp_path: Path, records: str,
                                    compression: str | None) -> None:
    """read_bag with the numpy index and parsers gives what rosbags' public API gives.

    The fast path uses rosbags internals (pinned in requirements.txt): this is the test
    to run when the pin moves.
    """
    path = write_bag(tmp_path / 'run.bag', STANDARD if records == 'standard' else IRREGULAR,
                     compression=compression, chunk_bytes=20_000)
    fast, public = read_bag(path), read_bag(path, fast=False)
    assert fast.joint_states is not None and fast.commands is not None
    assert fast.pelvis is not None and fast.modes
    assert_same_bag_data(fast, public)


def test_public_bag_reads_nothing_for_no_connections(tmp_path: Path) -> None:
    """Reader.messages reads every connection when given none; PublicBag must not."""
    bag = open_bag(write_bag(tmp_path / 'run.bag', run_records(0.01)), fast=False)
    assert isinstance(bag, PublicBag)
    try:
        times_ns, raws = bag.raw_messages([])
        assert (len(times_ns), raws) == (0, [])
    finally:
        bag.close()


def test_sim_configs_are_read_with_their_bag_time(tmp_path: Path) -> None:
    """replay takes /atlas/sim_config from BagData, so the bag is opened once."""
    records = [clock(0.5), sim_config(0.5, json.dumps({'timestep': 0.001})),
               sim_config(1.25, '{"last_reset_time": 1.2}')]
    data = read_bag(write_bag(tmp_path / 'run.bag', records))
    assert data.sim_configs == [(0.0, '{"timestep": 0.001}'), (0.75, '{"last_reset_time": 1.2}')]
    assert data.topics['/atlas/sim_config'].count == 2


@pytest.mark.parametrize('compression', [None, 'lz4'])
def test_raw_reading_matches_rosbags_reader(tmp_path: Path, compression: str | None) -> None:
    """The bulk index and record slicing give what rosbags' Reader.messages gives."""
    path = write_bag(tmp_path / 'run.bag', run_records(0.3), compression=compression,
                     chunk_bytes=20_000)
    with Reader(path) as reader:
        assert len(reader.chunk_infos) > 5
        expected = {topic: [(time_ns, bytes(raw)) for _, time_ns, raw in
                            reader.messages(info.connections)]
                    for topic, info in reader.topics.items()}
    bag = open_bag(path)
    assert isinstance(bag, IndexedBag)
    try:
        for topic, messages in expected.items():
            connections = [c for c in bag.connections if c.topic == topic]
            times_ns, raws = bag.raw_messages(connections)
            assert list(zip(times_ns.tolist(), raws)) == messages, topic
            assert bag.times_ns(connections).tolist() == times_ns.tolist()
    finally:
        bag.close()


# ------------------------------------------------------------- fast writer vs rosbags' public API


WRENCH = 'geometry_msgs/msg/WrenchStamped'
STRING = 'std_msgs/msg/String'
#: The fast writer's connections here: latched and not, Noetic types and TFMessage (which
#: load_typestore registers), two topics written as numpy blocks.
WRITER_TOPICS = {
    '/atlas/sim_config': TopicConnection(STRING, '/atlas_sim', True),
    '/clock': TopicConnection('rosgraph_msgs/msg/Clock', '/atlas_sim', False),
    '/atlas/l_foot_contact': TopicConnection(WRENCH, '/atlas_sim', False),
    '/atlas/r_foot_contact': TopicConnection(WRENCH, '/atlas_sim', False),
    '/tf': TopicConnection('tf2_msgs/msg/TFMessage', '/atlas_sim', False),
    '/atlas/control_mode': TopicConnection(STRING, '/tutorial_atlas_control', True),
}
WRENCH_FRAME = 'l_foot'
#: Byte offset of WrenchStamped's six float64s: Header.seq, stamp, frame_id (length, text).
WRENCH_AT = 4 + 8 + 4 + len(WRENCH_FRAME)
STEP_NS = 1_000_000
#: Steps per RecordBlock, and the chunk size: a chunk holds about two blocks.
BLOCK_STEPS = 100
CHUNK_BYTES = 30_000


def serialize(message: Any, msgtype: str) -> bytes:
    return bytes(TYPESTORE.serialize_ros1(message, msgtype))


def wrench_stamped(seq: int, stamp_ns: int, values: np.ndarray) -> Any:
    types = TYPESTORE.types
    stamp = types['builtin_interfaces/msg/Time'](sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9)
    vector = types['geometry_msgs/msg/Vector3']
    return types[WRENCH](
        header=types['std_msgs/msg/Header'](seq=seq, stamp=stamp, frame_id=WRENCH_FRAME),
        wrench=types['geometry_msgs/msg/Wrench'](force=vector(*values[:3]),
                                                 torque=vector(*values[3:])))


def write_fast_bag(path: Path, steps: int) -> dict[str, list[tuple[int, bytes]]]:
    """`steps` 1 ms steps written with BlockBagWriter as the offline player writes them.

    /atlas/l_foot_contact goes through RecordBlock.add (the message copied as it is then),
    /atlas/r_foot_contact through float_view and take(times, stamps); the other topics are
    single messages, raw or serialized by the writer. Returns each topic's expected
    (bag time (ns), serialized message), in time order.
    """
    expected: dict[str, list[tuple[int, bytes]]] = {topic: [] for topic in WRITER_TOPICS}
    types = TYPESTORE.types
    writer = BlockBagWriter(path, TYPESTORE, WRITER_TOPICS, CHUNK_BYTES)
    template = bytearray(serialize(wrench_stamped(0, 0, np.zeros(6)), WRENCH))
    template_floats = np.frombuffer(template, dtype='<f8', count=6, offset=WRENCH_AT)
    left = writer.record_block('/atlas/l_foot_contact', np.frombuffer(template, np.uint8),
                               BLOCK_STEPS)
    right = writer.record_block('/atlas/r_foot_contact', np.frombuffer(template, np.uint8),
                                BLOCK_STEPS)
    right_floats = right.float_view(WRENCH_AT, 6)
    config = types[STRING](data='{"timestep": 0.001}')
    writer.write_message('/atlas/sim_config', 0, config)
    expected['/atlas/sim_config'].append((0, serialize(config, STRING)))
    times_ns, stamps_ns = [], []

    def take_block() -> None:
        writer.write_rows('/atlas/l_foot_contact', *left.take())
        writer.write_rows('/atlas/r_foot_contact',
                          *right.take(np.array(times_ns), np.array(stamps_ns)))
        times_ns.clear()
        stamps_ns.clear()
        writer.flush()

    for step in range(steps):
        time_ns, stamp_ns = step * STEP_NS, max(0, step * STEP_NS - STEP_NS // 2)
        values = np.arange(6.0) * 0.5 + step
        template_floats[:] = values
        left.add(time_ns, stamp_ns)
        right_floats[len(times_ns)] = -values
        times_ns.append(time_ns)
        stamps_ns.append(stamp_ns)
        expected['/atlas/l_foot_contact'].append(
            (time_ns, serialize(wrench_stamped(step + 1, stamp_ns, values), WRENCH)))
        expected['/atlas/r_foot_contact'].append(
            (time_ns, serialize(wrench_stamped(step + 1, stamp_ns, -values), WRENCH)))
        if step % 10 == 0:
            clock = types['rosgraph_msgs/msg/Clock'](
                clock=types['builtin_interfaces/msg/Time'](sec=0, nanosec=time_ns))
            raw = serialize(clock, 'rosgraph_msgs/msg/Clock')
            writer.write('/clock', time_ns, raw)
            expected['/clock'].append((time_ns, raw))
        if step % 7 == 3:
            tf = types['tf2_msgs/msg/TFMessage'](transforms=[])
            writer.write_message('/tf', time_ns, tf)
            expected['/tf'].append((time_ns, serialize(tf, 'tf2_msgs/msg/TFMessage')))
        if step == steps // 2:
            mode = types[STRING](data='User')
            writer.write_message('/atlas/control_mode', time_ns, mode)
            expected['/atlas/control_mode'].append((time_ns, serialize(mode, STRING)))
        if len(times_ns) == BLOCK_STEPS:
            take_block()
    take_block()
    writer.close()
    return expected


def write_public_bag(path: Path, expected: dict[str, list[tuple[int, bytes]]]) -> Path:
    """The same messages written with rosbags' public Writer, in time order."""
    writer = Writer(path)
    writer.chunk_threshold = CHUNK_BYTES
    with writer:
        connections = {topic: writer.add_connection(
            topic, connection.msgtype, typestore=TYPESTORE, callerid=connection.callerid,
            latching=1 if connection.latched else None)
            for topic, connection in WRITER_TOPICS.items()}
        for time_ns, topic, raw in sorted((time_ns, topic, raw)
                                          for topic, messages in expected.items()
                                          for time_ns, raw in messages):
            writer.write(connections[topic], time_ns, raw)
    return path


def read_public(path: Path) -> tuple[list[tuple[Any, ...]], dict[str, list[tuple[int, bytes]]],
                                     tuple[int, int]]:
    """(connections, each topic's (bag time (ns), raw message), (start, end) time (ns)) of the
    bag at `path`, read with rosbags' public Reader."""
    with Reader(path) as reader:
        connections = [(c.id, c.topic, c.msgtype, c.msgdef.data, c.digest, c.ext.callerid,
                        c.ext.latching) for c in reader.connections]
        messages = {c.topic: [(time_ns, bytes(raw)) for _, time_ns, raw in reader.messages([c])]
                    for c in reader.connections}
        counts = {topic: info.msgcount for topic, info in reader.topics.items()}
        assert counts == {topic: len(raws) for topic, raws in messages.items()}
        return connections, messages, (reader.start_time, reader.end_time)


def test_fast_writer_bag_reads_back_with_rosbags_public_reader(tmp_path: Path) -> None:
    """Connections, counts, bag times and message bytes as written, across many chunks."""
    path = tmp_path / 'fast.bag'
    steps = 10 * BLOCK_STEPS + BLOCK_STEPS // 2  # the last block is partly filled
    expected = write_fast_bag(path, steps)
    with Reader(path) as reader:
        assert len(reader.chunk_infos) >= 4
    connections, messages, (start_ns, end_ns) = read_public(path)
    assert connections == [
        (cid, topic, connection.msgtype, *TYPESTORE.generate_msgdef(connection.msgtype),
         connection.callerid, 1 if connection.latched else None)
        for cid, (topic, connection) in enumerate(WRITER_TOPICS.items())]
    assert messages == expected
    assert len(messages['/atlas/l_foot_contact']) == steps
    assert (start_ns, end_ns) == (0, (steps - 1) * STEP_NS + 1)  # end: just after the last


def test_fast_writer_bag_equals_public_writer_bag(tmp_path: Path) -> None:
    """The same messages through rosbags' public Writer: same connections and content,
    and the fast reader reads the fast writer's bag as rosbags reads it."""
    expected = write_fast_bag(tmp_path / 'fast.bag', 3 * BLOCK_STEPS + 7)
    write_public_bag(tmp_path / 'public.bag', expected)
    assert read_public(tmp_path / 'fast.bag') == read_public(tmp_path / 'public.bag')
    bag = open_bag(tmp_path / 'fast.bag')
    assert isinstance(bag, IndexedBag)
    try:
        for topic, messages in expected.items():
            times_ns, raws = bag.raw_messages([c for c in bag.connections if c.topic == topic])
            assert list(zip(times_ns.tolist(), raws)) == messages, topic
    finally:
        bag.close()


def test_fast_writer_refuses_an_existing_file(tmp_path: Path) -> None:
    path = tmp_path / 'fast.bag'
    path.write_bytes(b'previous')
    with pytest.raises(WriterError, match='exists already'):
        BlockBagWriter(path, TYPESTORE, WRITER_TOPICS, CHUNK_BYTES)
    assert path.read_bytes() == b'previous'


def test_joint_state_fast_path_matches_generic_deserializer() -> None:
    rng = np.random.default_rng(7)
    raws = []
    for step in range(20):
        record = joint_state(0.001 * step + 3.0, rng.normal(size=NUM_JOINTS),
                             rng.normal(size=NUM_JOINTS), rng.normal(size=NUM_JOINTS), seq=step)
        raws.append(bytes(TYPESTORE.serialize_ros1(record.message, 'sensor_msgs/msg/JointState')))
    stamps_ns, names, (position, velocity, effort) = bag_reader._joint_states_fast(raws)
    for row, raw in enumerate(raws):
        msg = TYPESTORE.deserialize_ros1(raw, 'sensor_msgs/msg/JointState')
        assert stamps_ns[row] == msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
        assert names == list(msg.name)
        np.testing.assert_array_equal(position[row], msg.position)
        np.testing.assert_array_equal(velocity[row], msg.velocity)
        np.testing.assert_array_equal(effort[row], msg.effort)


def test_joint_state_fast_path_declines_mixed_layouts() -> None:
    first = joint_state(0.0, np.zeros(NUM_JOINTS)).message
    other = joint_state(0.001, np.zeros(NUM_JOINTS), names=list(reversed(JOINT_NAMES))).message
    raws = [bytes(TYPESTORE.serialize_ros1(msg, 'sensor_msgs/msg/JointState'))
            for msg in (first, other)]
    assert bag_reader._joint_states_fast(raws) is None


def test_odometry_fast_path_matches_generic_deserializer() -> None:
    raws = [bytes(TYPESTORE.serialize_ros1(odometry(1.5 + step, 0.9 - step, 0.1 * step, -0.2,
                                                     vz_m_s=0.3 * step).message,
                                            'nav_msgs/msg/Odometry')) for step in range(5)]
    stamps_ns, floats = bag_reader._odometry_fast(raws)
    for row, raw in enumerate(raws):
        msg = TYPESTORE.deserialize_ros1(raw, 'nav_msgs/msg/Odometry')
        assert stamps_ns[row] == msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
        pose, twist = msg.pose.pose, msg.twist.twist
        np.testing.assert_array_equal(floats[row, :7], [
            pose.position.x, pose.position.y, pose.position.z, pose.orientation.x,
            pose.orientation.y, pose.orientation.z, pose.orientation.w])
        np.testing.assert_array_equal(floats[row, 43:49], [
            twist.linear.x, twist.linear.y, twist.linear.z, twist.angular.x, twist.angular.y,
            twist.angular.z])


@settings(max_examples=50, deadline=None)
@given(names=st.lists(st.text(max_size=12), max_size=6),
       values=st.lists(st.floats(allow_nan=False), max_size=6),
       stamp_s=st.integers(min_value=0, max_value=2**31 - 1))
def test_names_arrays_parser_matches_generic_deserializer(names, values, stamp_s) -> None:
    msg = joint_commands(float(stamp_s), values, names=names).message
    raw = bytes(TYPESTORE.serialize_ros1(msg, 'osrf_msgs/msg/JointCommands'))
    stamp_ns, parsed_names, (position,) = parse_names_arrays(raw, 1)
    assert stamp_ns == msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
    assert parsed_names == list(msg.name)
    np.testing.assert_array_equal(position, msg.position)


def test_joint_commands_definition_has_the_expected_md5() -> None:
    typestore = load_typestore()
    assert typestore.generate_msgdef('osrf_msgs/msg/JointCommands')[1] == (
        bag_reader.JOINT_COMMANDS_MD5)


def test_typestore_has_tf_messages_with_the_debian_md5() -> None:
    """rosbags' Noetic store lacks tf2_msgs/TFMessage; load_typestore adds it, as ROS has it."""
    assert load_typestore().generate_msgdef('tf2_msgs/msg/TFMessage')[1] == (
        '94810edda583a504dfda3829e70d7eec')


# ---------------------------------------------------------------- topics and series


def test_topics_counts_rates_and_duration(tmp_path: Path) -> None:
    records = states(np.arange(101) * 0.01) + [clock(t_s) for t_s in np.arange(11) * 0.1]
    records += [odometry(t_s, 0.9) for t_s in np.arange(51) * 0.02]
    data = read_bag(write_bag(tmp_path / 'run.bag', records))
    assert data.duration_s == pytest.approx(1.0, abs=1e-9)
    assert set(data.topics) == {'/atlas/joint_states', '/clock', '/ground_truth_odom'}
    joint_states = data.topics['/atlas/joint_states']
    assert (joint_states.msgtype, joint_states.count) == ('sensor_msgs/JointState', 101)
    assert joint_states.rate_hz == pytest.approx(100.0)
    assert data.topics['/clock'].rate_hz == pytest.approx(10.0)
    assert data.topics['/ground_truth_odom'].count == 51
    assert data.topics['/ground_truth_odom'].rate_hz == pytest.approx(50.0)


def test_single_message_topic_has_no_rate(tmp_path: Path) -> None:
    data = read_bag(write_bag(tmp_path / 'run.bag', [control_mode(0.0, 'Stand'), clock(1.0)]))
    assert data.topics['/atlas/control_mode'].rate_hz is None
    assert data.topics['/atlas/control_mode'].msgtype == 'std_msgs/String'


def test_unstamped_commands_use_bag_time(tmp_path: Path) -> None:
    records = [joint_commands(0.01, np.zeros(NUM_JOINTS), stamp_s=0.0)]
    data = read_bag(write_bag(tmp_path / 'run.bag', [clock(0.0)] + records))
    np.testing.assert_allclose(data.commands.t_s, [0.01])


def test_states_stamped_at_sim_time_zero_keep_their_stamp(tmp_path: Path) -> None:
    """The recorder writes what arrived before the first /clock at the first valid time."""
    early = [joint_state(k * 0.001, np.zeros(NUM_JOINTS)) for k in range(13)]
    early = [replace(record, t_s=0.012) for record in early + [odometry(0.0, STANDING_HEIGHT_M)]]
    later = [joint_state(k * 0.001, np.zeros(NUM_JOINTS)) for k in range(13, 100)]
    later += [odometry(0.01 * k, STANDING_HEIGHT_M) for k in range(2, 10)]
    data = read_bag(write_bag(tmp_path / 'run.bag', early + later))
    states_s = data.start_time_s + data.joint_states.t_s
    np.testing.assert_allclose(states_s, np.arange(100) * 0.001, atol=1e-9)
    assert data.start_time_s + data.pelvis.t_s[0] == pytest.approx(0.0, abs=1e-9)


def test_unknown_command_names_are_warned_about(tmp_path: Path) -> None:
    records = [joint_commands(0.0, [1.0, 0.5], names=['atlas::hokuyo_joint', 'neck_ay'])]
    data = read_bag(write_bag(tmp_path / 'run.bag', records))
    assert any('hokuyo_joint' in warning for warning in data.warnings)
    assert data.commands.position[0, JOINT_NAMES.index('neck_ay')] == 0.5


def test_joint_commands_use_the_bags_own_definition(tmp_path: Path) -> None:
    """A JointCommands with another layout (other MD5) is read through the bag's msgdef."""
    msgdef = 'Header header\nstring[] name\nfloat64[] velocity\nfloat64[] position\n'
    typestore = load_typestore()
    typestore.fielddefs.pop('osrf_msgs/msg/JointCommands')
    typestore.register(get_types_from_msg(msgdef, 'osrf_msgs/msg/JointCommands'))
    full_msgdef, md5 = typestore.generate_msgdef('osrf_msgs/msg/JointCommands')
    assert md5 != bag_reader.JOINT_COMMANDS_MD5
    cls = typestore.types['osrf_msgs/msg/JointCommands']
    header = joint_commands(0.0, [0.0]).message.header
    message = cls(header=header, name=['l_arm_elx'], velocity=np.array([9.0]),
                  position=np.array([0.7]))
    path = tmp_path / 'variant.bag'
    with Writer(path) as writer:
        connection = writer.add_connection('/atlas/joint_commands', 'osrf_msgs/msg/JointCommands',
                                           msgdef=full_msgdef, md5sum=md5)
        raw = typestore.serialize_ros1(message, 'osrf_msgs/msg/JointCommands')
        writer.write(connection, 1, raw)
    data = read_bag(path)
    assert data.commands.position[0, ELX] == 0.7


def test_states_with_changing_names_take_the_slow_path(tmp_path: Path) -> None:
    records = [joint_state(0.0, [0.1, 0.2], names=['atlas::l_leg_kny', 'l_arm_elx']),
               joint_state(0.001, [0.3], names=['l_arm_elx'])]
    data = read_bag(write_bag(tmp_path / 'run.bag', records))
    assert data.joint_states.names == ('l_leg_kny', 'l_arm_elx')
    np.testing.assert_array_equal(data.joint_states.position, [[0.1, 0.2], [np.nan, 0.3]])


# ---------------------------------------------------------------- errors


@pytest.mark.parametrize('name', ['run.bag', 'run.bag.active'])
def test_unindexed_bag_suggests_reindex(tmp_path: Path, name: str) -> None:
    good = write_bag(tmp_path / 'good.bag', tracking_records('bare'))
    path = unindexed_copy(good, tmp_path / name)
    with pytest.raises(BagAnalysisError, match=r'not indexed.*rosbag reindex'):
        read_bag(path)


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(BagAnalysisError, match='no such file'):
        read_bag(tmp_path / 'nothing.bag')


def test_missing_file_with_active_sibling_says_so(tmp_path: Path) -> None:
    (tmp_path / 'run.bag.active').write_bytes(b'#ROSBAG V2.0\n')
    with pytest.raises(BagAnalysisError, match=r'run\.bag\.active exists.*rosbag reindex'):
        read_bag(tmp_path / 'run.bag')


@pytest.mark.parametrize('content', [b'', b'hello, not a bag\n', b'\x89PNG\r\n'])
def test_not_a_bag(tmp_path: Path, content: bytes) -> None:
    path = tmp_path / 'notes.bag'
    path.write_bytes(content)
    with pytest.raises(BagAnalysisError, match='is not a ROS 1 bag'):
        read_bag(path)


def test_directory(tmp_path: Path) -> None:
    with pytest.raises(BagAnalysisError, match='is a directory'):
        read_bag(tmp_path)


def test_errors_share_the_package_base() -> None:
    assert issubclass(BagAnalysisError, AtlasControlError)
