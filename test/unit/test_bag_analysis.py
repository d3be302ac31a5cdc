"""Tests of bag_analysis: reading synthetic bags and the metrics, with known answers."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from rosbags.rosbag1 import Reader, Writer
from rosbags.typesys import get_types_from_msg

from tutorial_atlas_control.synthetic_bags import (
    STANDING_HEIGHT_M,
    TYPESTORE,
    clock,
    control_mode,
    joint_commands,
    joint_state,
    odometry,
    run_records,
    tracking_records,
    unindexed_copy,
    write_bag,
    write_run_bag,
)
from tutorial_atlas_control import bag_analysis
from tutorial_atlas_control.bag_analysis import (
    EFFORT_LIMITS_NM,
    BagAnalysisError,
    analyze,
    analyze_bag,
    load_typestore,
    read_bag,
)
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.ros1_fields import parse_names_arrays

ELX = JOINT_NAMES.index('l_arm_elx')
KNY = JOINT_NAMES.index('l_leg_kny')


def states(times_s, value_at=lambda t_s: np.zeros(NUM_JOINTS), **kwargs):
    return [joint_state(t_s, value_at(t_s), **kwargs) for t_s in times_s]


def with_joint(index: int, value: float) -> np.ndarray:
    position = np.zeros(NUM_JOINTS)
    position[index] = value
    return position


# ---------------------------------------------------------------- wire-format fast path


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
    reader = bag_analysis._open_reader(path)
    try:
        for topic, messages in expected.items():
            connections = [c for c in reader.connections if c.topic == topic]
            times_ns, raws = bag_analysis._read_raw(reader, connections)
            assert list(zip(times_ns.tolist(), raws)) == messages, topic
    finally:
        reader.close()


def test_joint_state_fast_path_matches_generic_deserializer() -> None:
    rng = np.random.default_rng(7)
    raws = []
    for step in range(20):
        record = joint_state(0.001 * step + 3.0, rng.normal(size=NUM_JOINTS),
                             rng.normal(size=NUM_JOINTS), rng.normal(size=NUM_JOINTS), seq=step)
        raws.append(bytes(TYPESTORE.serialize_ros1(record.message, 'sensor_msgs/msg/JointState')))
    stamps_ns, names, (position, velocity, effort) = bag_analysis._joint_states_fast(raws)
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
    assert bag_analysis._joint_states_fast(raws) is None


def test_odometry_fast_path_matches_generic_deserializer() -> None:
    raws = [bytes(TYPESTORE.serialize_ros1(odometry(1.5 + step, 0.9 - step, 0.1 * step, -0.2,
                                                     vz_m_s=0.3 * step).message,
                                            'nav_msgs/msg/Odometry')) for step in range(5)]
    stamps_ns, floats = bag_analysis._odometry_fast(raws)
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
        bag_analysis.JOINT_COMMANDS_MD5)


# ---------------------------------------------------------------- topics, modes, fall


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


def test_mode_timeline_collapses_repeats_and_uses_bag_time(tmp_path: Path) -> None:
    records = [clock(0.5), control_mode(0.5, 'Stand'), control_mode(0.75, 'Stand'),
               control_mode(1.5, 'User'), control_mode(2.25, 'Freeze'),
               control_mode(2.5, 'ragdoll')]
    analysis = analyze_bag(write_bag(tmp_path / 'run.bag', records))
    assert analysis.mode_timeline == [(0.0, 'Stand'), (1.0, 'User'), (1.75, 'Freeze'),
                                      (2.0, 'ragdoll')]
    assert analysis.to_dict()['mode_timeline'][1] == {'time': 1.0, 'mode': 'User'}


def test_fall_time_is_first_pelvis_height_below_threshold(tmp_path: Path) -> None:
    # Bag starts at 0.25 s sim time; the pelvis first dips below 0.5 m at 3.137 s.
    fall_s = 3.137
    records = [clock(0.25)] + [odometry(t_s, 0.93 if t_s < fall_s else 0.3)
                               for t_s in np.round(0.25 + np.arange(500) * 0.001 * 11, 6)]
    records.append(odometry(fall_s, 0.49))
    analysis = analyze_bag(write_bag(tmp_path / 'run.bag', records))
    assert analysis.fell is True
    assert analysis.fall_time_s == pytest.approx(fall_s - 0.25, abs=1e-3)
    assert analysis.min_pelvis_height_m == pytest.approx(0.3)


def test_no_fall_when_pelvis_stays_up(tmp_path: Path) -> None:
    records = [odometry(t_s, 0.5 + 0.1 * t_s) for t_s in np.arange(10) * 0.1]
    analysis = analyze_bag(write_bag(tmp_path / 'run.bag', records))
    assert (analysis.fell, analysis.fall_time_s) == (False, None)
    assert 'joints' in analysis.unavailable


# ---------------------------------------------------------------- tracking and commands


@pytest.mark.parametrize('names_style', ['bare', 'prefixed', 'empty', 'subset'])
def test_tracking_error_known_answer(tmp_path: Path, names_style: str) -> None:
    analysis = analyze_bag(write_bag(tmp_path / 'run.bag', tracking_records(names_style)))
    assert list(analysis.joints) == ['l_arm_elx']
    joint = analysis.joints['l_arm_elx']
    assert joint.samples == 10
    assert joint.commanded
    assert joint.rms_error_rad == pytest.approx(np.sqrt((5 * 0.05**2 + 5 * 0.15**2) / 10), abs=1e-6)
    assert joint.max_error_rad == pytest.approx(0.15, abs=1e-6)
    assert analysis.to_dict()['joints']['l_arm_elx']['max_error'] == pytest.approx(0.15, abs=1e-6)


def test_subset_commands_hold_each_joints_last_value(tmp_path: Path) -> None:
    """A command for l_arm_elx only must not erase the held value of l_leg_kny."""
    records = [joint_commands(0.0, [0.3, 0.1], names=['l_leg_kny', 'atlas::l_arm_elx']),
               joint_commands(0.01, [0.2], names=['l_arm_elx'])]
    records += states([0.005, 0.015], lambda _: with_joint(KNY, 0.3) + with_joint(ELX, 0.2))
    data = read_bag(write_bag(tmp_path / 'run.bag', records))
    np.testing.assert_allclose(data.commands.held[1, [KNY, ELX]], [0.3, 0.2])
    assert np.isnan(data.commands.position[1, KNY])
    analysis = analyze(data)
    assert analysis.joints['l_arm_elx'].max_error_rad == pytest.approx(0.1)
    assert 'l_leg_kny' not in analysis.joints  # commanded constant, measured constant


def test_joint_that_moved_without_command_is_reported(tmp_path: Path) -> None:
    records = states(np.arange(10) * 0.01, lambda t_s: with_joint(KNY, t_s))
    analysis = analyze_bag(write_bag(tmp_path / 'run.bag', records))
    assert list(analysis.joints) == ['l_leg_kny']
    joint = analysis.joints['l_leg_kny']
    assert (joint.commanded, joint.rms_error_rad, joint.samples) == (False, None, 0)
    assert joint.measured_range_rad == pytest.approx(0.09)
    assert 'commands' in analysis.unavailable and 'command_age' in analysis.unavailable


def test_command_rate_and_age(tmp_path: Path) -> None:
    records = [joint_commands(t_s, np.zeros(NUM_JOINTS)) for t_s in (0.0, 0.02, 0.04)]
    records += states([0.005, 0.015, 0.025, 0.045])
    analysis = analyze_bag(write_bag(tmp_path / 'run.bag', records))
    assert analysis.command_rate_hz == pytest.approx(50.0)
    assert analysis.command_age_mean_s == pytest.approx((0.005 + 0.015 + 0.005 + 0.005) / 4)
    assert analysis.command_age_max_s == pytest.approx(0.015)


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
    assert md5 != bag_analysis.JOINT_COMMANDS_MD5
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


@pytest.mark.parametrize('compression', ['bz2', 'lz4'])
def test_compressed_bag(tmp_path: Path, compression: str) -> None:
    path = write_bag(tmp_path / 'run.bag', tracking_records('bare'), compression=compression)
    assert analyze_bag(path).joints['l_arm_elx'].max_error_rad == pytest.approx(0.15)


# ---------------------------------------------------------------- effort saturation


def test_effort_limit_time(tmp_path: Path) -> None:
    """l_leg_kny at +-limit (or within tolerance) for 20 of 100 1-kHz samples -> 20 ms."""
    limit = EFFORT_LIMITS_NM['l_leg_kny']
    records = []
    for step in range(100):
        effort = np.zeros(NUM_JOINTS)
        if 10 <= step < 30:
            effort[KNY] = (limit, -limit, limit - 0.005)[step % 3]
        elif step == 50:
            effort[KNY] = limit - 1.0  # close, but not at the limit
        effort[JOINT_NAMES.index('neck_ay')] = 4.0
        records.append(joint_state(step * 0.001, np.zeros(NUM_JOINTS), effort=effort))
    analysis = analyze_bag(write_bag(tmp_path / 'run.bag', records))
    assert list(analysis.effort_saturation) == ['l_leg_kny']
    saturation = analysis.effort_saturation['l_leg_kny']
    assert saturation.duration_s == pytest.approx(0.020, abs=1e-9)
    assert saturation.first_time_s == pytest.approx(0.010)
    assert (saturation.samples, saturation.limit_nm) == (20, 220.0)


def test_effort_limit_table() -> None:
    assert list(EFFORT_LIMITS_NM) == list(JOINT_NAMES)
    assert EFFORT_LIMITS_NM['back_mby'] == 206.843
    assert EFFORT_LIMITS_NM['r_leg_lhy'] == EFFORT_LIMITS_NM['l_leg_lhy'] == 260.0
    assert EFFORT_LIMITS_NM['r_arm_mwx'] == 60.0


# ---------------------------------------------------------------- missing data and errors


def test_bag_without_joint_states_still_summarizes(tmp_path: Path) -> None:
    records = [control_mode(0.0, 'Stand'), odometry(0.0, 0.9), odometry(1.0, 0.2),
               joint_commands(0.5, np.zeros(NUM_JOINTS))]
    analysis = analyze_bag(write_bag(tmp_path / 'run.bag', records))
    assert analysis.fell is True and analysis.fall_time_s == pytest.approx(1.0)
    assert analysis.joints == {} and analysis.effort_saturation is None
    assert set(analysis.unavailable) == {'joints', 'command_age', 'effort_saturation'}
    assert '/atlas/joint_states' in analysis.unavailable['joints']


def test_empty_bag(tmp_path: Path) -> None:
    path = tmp_path / 'empty.bag'
    with Writer(path):
        pass
    analysis = analyze_bag(path)
    assert (analysis.data.topics, analysis.data.duration_s, analysis.fell) == ({}, 0.0, None)


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


def test_analysis_is_deterministic(tmp_path: Path) -> None:
    path = write_run_bag(tmp_path / 'run.bag', 3.0, with_imu=False, fall_time_s=1.5)
    first, second = analyze_bag(path).to_dict(), analyze_bag(path).to_dict()
    assert first == second
    # The pelvis sinks 0.73 m/s from 0.93 m at 1.5 s: below 0.5 m after 1.5 + 0.43/0.73 s,
    # seen at the next 100 Hz odometry sample.
    assert first['fell'] and first['fall_time'] == pytest.approx(2.09, abs=1e-6)
