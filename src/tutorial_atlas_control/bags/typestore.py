"""The one rosbags typestore builder: ROS 1 Noetic's types plus those this package's bags use.

Reading, writing and the synthetic test bags all serialize through rosbags; building their
typestore in one place keeps the definitions (and so the bags' MD5 sums) the same in each.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from rosbags.interfaces import Connection
from rosbags.typesys import Stores, TypesysError, get_types_from_msg, get_typestore

from tutorial_atlas_control.errors import BagAnalysisError

if TYPE_CHECKING:  # get_typestore's return type; rosbags.typesys does not re-export it
    from rosbags.typesys.store import Typestore

__all__ = [
    'JOINT_COMMANDS_MSG_RELPATH',
    'JOINT_COMMANDS_TYPE',
    'TF_MSG_DEFINITION',
    'TF_TYPE',
    'load_typestore',
    'rosbags_msgtype',
]

JOINT_COMMANDS_TYPE = 'osrf_msgs/msg/JointCommands'
#: Where osrf_msgs/JointCommands.msg lives relative to the package's root in a source checkout.
JOINT_COMMANDS_MSG_RELPATH = Path('msg') / 'osrf_msgs' / 'msg' / 'JointCommands.msg'
#: tf2_msgs/TFMessage, field for field (its definition as Debian's ros-tf2-msgs ships it);
#: rosbags' Noetic store does not have it.
TF_TYPE = 'tf2_msgs/msg/TFMessage'
TF_MSG_DEFINITION = 'geometry_msgs/TransformStamped[] transforms'


def rosbags_msgtype(ros1_type: str) -> str:
    """rosbags' name of the ROS 1 type `ros1_type`: 'pkg/Name' -> 'pkg/msg/Name'."""
    package, name = ros1_type.split('/')
    return f'{package}/msg/{name}'


def _find_joint_commands_msg() -> Path | None:
    """Locate osrf_msgs/JointCommands.msg in a source checkout or a ROS install."""
    for parent in Path(__file__).resolve().parents:
        candidate = parent / JOINT_COMMANDS_MSG_RELPATH
        if candidate.is_file():
            return candidate
    try:
        import rospkg  # noqa: PLC0415 - optional, only present in a ROS environment

        candidate = Path(rospkg.RosPack().get_path('osrf_msgs')) / 'msg' / 'JointCommands.msg'
    except Exception:  # noqa: BLE001 - any failure just means "not installed"
        return None
    return candidate if candidate.is_file() else None


def load_typestore(connections: Sequence[Connection] = ()) -> Typestore:
    """Return a ROS 1 Noetic rosbags typestore that knows every type in `connections`.

    Types missing from the Noetic store are registered from the bag's own message
    definitions first; then osrf_msgs/JointCommands comes from the package's .msg file
    (when found) and tf2_msgs/TFMessage from TF_MSG_DEFINITION, if the bag did not
    define them.

    Raises:
        BagAnalysisError: A definition in the bag cannot be parsed or registered.
    """
    typestore = get_typestore(Stores.ROS1_NOETIC)
    for connection in connections:
        msgdef = getattr(connection.msgdef, 'data', '')
        if connection.msgtype in typestore.fielddefs or not msgdef:
            continue
        try:
            typestore.register(get_types_from_msg(msgdef, connection.msgtype))
        except TypesysError as err:
            msg = (f'Could not use the bag\'s definition of {connection.msgtype!r} on '
                   f'{connection.topic}: {err}')
            raise BagAnalysisError(msg) from err
    if JOINT_COMMANDS_TYPE not in typestore.fielddefs:
        msg_file = _find_joint_commands_msg()
        if msg_file is not None:
            typestore.register(get_types_from_msg(msg_file.read_text(), JOINT_COMMANDS_TYPE))
    if TF_TYPE not in typestore.fielddefs:
        typestore.register(get_types_from_msg(TF_MSG_DEFINITION, TF_TYPE))
    return typestore
