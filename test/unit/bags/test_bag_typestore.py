"""Bags the package writes carry genmsg's MD5 of every atlas_msgs message.

rosbags 0.11.9 reads AtlasState's lower-case constants (`int32 back_lbz  = 0`) as fields:
its own MD5 for the type is f532b723..., and a bag written with it would not be accepted by
a ROS subscriber or read by Debian's rosbag as atlas_msgs/AtlasState. bags.typestore builds
every typestore the package writes with; these tests write bags through each writer.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from rosbags.rosbag1 import Reader
from rosbags.typesys import get_types_from_msg

from support import synthetic_bags as synthetic
from tutorial_atlas_control.bags.rosbag1_fast import BlockBagWriter, TopicConnection
from tutorial_atlas_control.bags.typestore import (
    ATLAS_MSGS,
    load_typestore,
    types_from_definition,
)
from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.msgs.wire import AtlasStateWire

atlas_msgs = pytest.importorskip('atlas_msgs.msg', reason='needs the catkin workspace')

ATLAS_STATE = 'atlas_msgs/msg/AtlasState'
#: genmsg's MD5 sums (the reference README's table; the vendored messages' genpy classes).
GENMSG_MD5 = {
    'AtlasCommand': '3a56dd1f50633ad975636160b665384a',
    'AtlasState': 'f401ea8c0dd89918d4fa3a58c57816e6',
    'ControllerStatistics': '628a0c6643f9fd5708402f085735e478',
    'ForceTorqueSensors': '608f43cae98f77f5fb6cfbbbfa4c9253',
    'SynchronizationStatistics': '27bc1701ef8ff889822573f985ebb2b6',
    'Test': '62f63cd4b6db15007d8d3d4a23411c4c',
    'VRCScore': '15d1f218676ad0e9382ec3bd7afd4995',
}
#: What rosbags alone computes for AtlasState (its constants taken for fields).
ROSBAGS_ATLAS_STATE_MD5 = 'f532b7233898211d080f25d52556e05d'


def test_rosbags_alone_gets_atlas_state_wrong() -> None:
    """The defect the typestore works around (if rosbags fixes it, this says so)."""
    typestore = load_typestore()
    typestore.fielddefs.pop(ATLAS_STATE)
    typestore.register(get_types_from_msg(atlas_msgs.AtlasState._full_text, ATLAS_STATE))
    assert typestore.generate_msgdef(ATLAS_STATE)[1] == ROSBAGS_ATLAS_STATE_MD5


@pytest.mark.parametrize('name', ATLAS_MSGS)
def test_the_typestore_has_genmsg_md5s(name: str) -> None:
    """Every atlas_msgs type the typestore registers has genmsg's MD5 (the AtlasSimInterface's
    are checked against ASI.md's table by test_message.py, through the same genpy classes)."""
    assert set(GENMSG_MD5) <= set(ATLAS_MSGS)
    genmsg_md5 = getattr(atlas_msgs, name)._md5sum
    assert genmsg_md5 == GENMSG_MD5.get(name, genmsg_md5)
    assert load_typestore().generate_msgdef(f'atlas_msgs/msg/{name}')[1] == genmsg_md5


def test_a_ros_written_definition_reads_as_ros_wrote_it() -> None:
    """A bag recorded by ROS holds genmsg's full text (constants with spaces): the types
    registered from it have the 18 fields, the 28 constants and the right MD5."""
    types = types_from_definition(atlas_msgs.AtlasState._full_text, ATLAS_STATE)
    constants, fields = types[ATLAS_STATE]
    assert [name for name, _, _ in constants][:2] == ['back_lbz', 'back_mby']
    assert constants[-1] == ('r_arm_mwx', 'int32', 27)
    assert len(fields) == 18
    typestore = load_typestore()
    typestore.fielddefs.pop(ATLAS_STATE)
    typestore.register(types)
    assert typestore.generate_msgdef(ATLAS_STATE)[1] == GENMSG_MD5['AtlasState']


def _state_bytes() -> tuple[bytes, np.ndarray]:
    """An AtlasState as the simulator serializes it (no TCPROS prefix), and its positions."""
    wire = AtlasStateWire(NUM_JOINTS)
    positions = np.linspace(-1.0, 1.0, NUM_JOINTS, dtype=np.float32)
    wire.arrays['position'][:] = positions
    wire.k_effort[:] = 255
    return wire.to_bytes(1_500_000_000)[4:], positions


def _check_bag(path: Path, positions: np.ndarray) -> None:
    """The bag's AtlasState connection has genmsg's MD5, and genpy reads its message."""
    with Reader(path) as reader:
        connection, = (c for c in reader.connections if c.topic == '/atlas/atlas_state')
        assert connection.digest == GENMSG_MD5['AtlasState']
        _, _, raw = next(reader.messages([connection]))
    message = atlas_msgs.AtlasState().deserialize(raw)
    assert np.array_equal(np.asarray(message.position, dtype=np.float32), positions)
    assert list(message.k_effort) == [255] * NUM_JOINTS


def test_the_fast_writer_writes_genmsg_md5(tmp_path: Path) -> None:
    raw, positions = _state_bytes()
    path = tmp_path / 'fast.bag'
    writer = BlockBagWriter(path, load_typestore(), {
        '/atlas/atlas_state': TopicConnection(ATLAS_STATE, '/atlas_sim', False)}, 1 << 20)
    writer.write('/atlas/atlas_state', 1_500_000_000, raw)
    writer.close()
    _check_bag(path, positions)


def test_the_synthetic_writer_writes_genmsg_md5(tmp_path: Path) -> None:
    raw, positions = _state_bytes()
    message = synthetic.TYPESTORE.deserialize_ros1(raw, ATLAS_STATE)
    path = synthetic.write_bag(tmp_path / 'synthetic.bag', [
        synthetic.Record('/atlas/atlas_state', 'atlas_msgs/AtlasState', 1.5, message)])
    _check_bag(path, positions)


def test_a_bad_constant_in_a_bag_definition_is_one_clear_error() -> None:
    from types import SimpleNamespace

    from tutorial_atlas_control.errors import BagAnalysisError

    connection = SimpleNamespace(topic='/broken', msgtype='demo_msgs/msg/Broken',
                                 msgdef=SimpleNamespace(data='int32 limit = ten\nint32 value\n'))
    with pytest.raises(BagAnalysisError, match=(
            r"^Could not use the bag's definition of 'demo_msgs/msg/Broken' on /broken: "
            r"Could not parse constant 'limit' of demo_msgs/msg/Broken: 'ten'\.$")):
        load_typestore([connection])
