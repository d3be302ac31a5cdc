"""The one rosbags typestore builder: ROS 1 Noetic's types plus those this package's bags use.

Reading, writing and the synthetic test bags all serialize through rosbags; building their
typestore in one place keeps the definitions (and so the bags' MD5 sums) the same in each.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from rosbags.interfaces import Connection
from rosbags.typesys import Stores, TypesysError, get_types_from_msg, get_typestore

from tutorial_atlas_control.errors import BagAnalysisError
from tutorial_atlas_control.resources import message_file

if TYPE_CHECKING:  # get_typestore's return type; rosbags.typesys does not re-export it
    from rosbags.typesys.store import Typestore

__all__ = [
    'ATLAS_MSGS',
    'JOINT_COMMANDS_TYPE',
    'TF_MSG_DEFINITION',
    'TF_TYPE',
    'load_typestore',
    'rosbags_msgtype',
    'types_from_definition',
]

JOINT_COMMANDS_TYPE = 'osrf_msgs/msg/JointCommands'
#: tf2_msgs/TFMessage, field for field (its definition as Debian's ros-tf2-msgs ships it);
#: rosbags' Noetic store does not have it.
TF_TYPE = 'tf2_msgs/msg/TFMessage'
TF_MSG_DEFINITION = 'geometry_msgs/TransformStamped[] transforms'


#: The vendored atlas_msgs messages (msg/atlas_msgs), registered from their .msg files.
ATLAS_MSGS = ('AtlasCommand', 'AtlasState', 'ControllerStatistics', 'ForceTorqueSensors',
              'SynchronizationStatistics', 'Test', 'VRCScore',
              # the AtlasSimInterface's, each after the ones it holds
              'AtlasBehaviorStepData', 'AtlasBehaviorStepParams', 'AtlasBehaviorStandParams',
              'AtlasBehaviorPelvisServoParams', 'AtlasBehaviorManipulateParams',
              'AtlasBehaviorWalkParams', 'AtlasSimInterfaceCommand', 'AtlasPositionData',
              'AtlasBehaviorFeedback', 'AtlasBehaviorStepFeedback',
              'AtlasBehaviorWalkFeedback', 'AtlasBehaviorStandFeedback',
              'AtlasBehaviorManipulateFeedback', 'AtlasSimInterfaceState')
#: A constant as genmsg reads it: `TYPE NAME = VALUE`, any case, spaces around '=' or not.
_CONSTANT = re.compile(r'^\s*([a-z][a-z0-9]*)\s+([A-Za-z][A-Za-z0-9_]*)\s*=\s*(.*)$')
_INTEGER_TYPES = frozenset({'byte', 'char', 'int8', 'uint8', 'int16', 'uint16', 'int32',
                            'uint32', 'int64', 'uint64'})
#: The line before each further message of a full definition (genmsg's).
_SEPARATOR = '=' * 80


def _constant_value(typ: str, text: str) -> Any:
    """A constant's value (`text`: after '=', without a comment unless a string)."""
    text = text.strip()
    if typ == 'string':
        return text
    if typ in _INTEGER_TYPES:
        return int(text)
    if typ == 'bool':
        return text.lower() in ('true', '1')
    return float(text)


def types_from_definition(text: str, msgtype: str) -> dict[str, Any]:
    """rosbags' get_types_from_msg(text, msgtype), with the constants genmsg sees.

    rosbags 0.11.9 reads only UPPER_SNAKE names as constants: AtlasState's
    `int32 back_lbz  = 0` becomes a field, so its fields, its serialization and its MD5
    (f532b723... instead of genmsg's f401ea8c0dd89918d4fa3a58c57816e6) are wrong. Here every
    constant line is taken out before rosbags parses the text and put back as a constant of
    its message, in order: the MD5 is genmsg's and a bag written with it is what ROS writes.

    Raises:
        TypesysError: rosbags cannot parse what is left, or a constant's value.
    """
    constants: dict[str, list[tuple[str, str, Any]]] = {}
    kept: list[str] = []
    current = msgtype
    for line in text.splitlines():
        if line.startswith('MSG: '):
            current = rosbags_msgtype(line[5:].strip()) if '/msg/' not in line else line[5:]
        match = _CONSTANT.match(line.split('#', 1)[0])
        if match:
            typ, name, value = match.groups()
            if typ == 'string':  # its value is the rest of the line, '#' and all
                value = line.split('=', 1)[1]
            try:
                parsed = _constant_value(typ, value)
            except ValueError as err:
                raise TypesysError(f'Could not parse constant {name!r} of {current}: '
                                   f'{value!r}.') from err
            constants.setdefault(current, []).append((name, typ, parsed))
            continue
        kept.append(line)
    types = get_types_from_msg('\n'.join(kept) + '\n', msgtype)
    for name, found in constants.items():
        if name in types:
            types[name] = (found, types[name][1])
    return types


def rosbags_msgtype(ros1_type: str) -> str:
    """rosbags' name of the ROS 1 type `ros1_type`: 'pkg/Name' -> 'pkg/msg/Name'."""
    package, name = ros1_type.split('/')
    return f'{package}/msg/{name}'


def load_typestore(connections: Sequence[Connection] = ()) -> Typestore:
    """Return a ROS 1 Noetic rosbags typestore that knows every type in `connections`.

    Types missing from the Noetic store are registered from the bag's own message
    definitions first (types_from_definition: genmsg's constants); then
    osrf_msgs/JointCommands and ATLAS_MSGS come from the package's .msg files (when found)
    and tf2_msgs/TFMessage from TF_MSG_DEFINITION, if the bag did not define them.

    Raises:
        BagAnalysisError: A definition in the bag cannot be parsed or registered.
    """
    typestore = get_typestore(Stores.ROS1_NOETIC)
    for connection in connections:
        msgdef = getattr(connection.msgdef, 'data', '')
        if connection.msgtype in typestore.fielddefs or not msgdef:
            continue
        try:
            typestore.register(types_from_definition(msgdef, connection.msgtype))
        except TypesysError as err:
            msg = (f'Could not use the bag\'s definition of {connection.msgtype!r} on '
                   f'{connection.topic}: {err}')
            raise BagAnalysisError(msg) from err
    if JOINT_COMMANDS_TYPE not in typestore.fielddefs:
        msg_file = message_file('osrf_msgs', 'JointCommands')
        if msg_file is not None:
            typestore.register(types_from_definition(msg_file.read_text(), JOINT_COMMANDS_TYPE))
    if TF_TYPE not in typestore.fielddefs:
        typestore.register(get_types_from_msg(TF_MSG_DEFINITION, TF_TYPE))
    for name in ATLAS_MSGS:
        msgtype = f'atlas_msgs/msg/{name}'
        msg_file = message_file('atlas_msgs', name)
        if msgtype not in typestore.fielddefs and msg_file is not None:
            typestore.register(types_from_definition(msg_file.read_text(), msgtype))
    return typestore
