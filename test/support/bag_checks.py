"""What the reliability tests read back from a recorded bag (rosbags, no ROS needed)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from tutorial_atlas_control.bags.reader import JointStateSeries
from tutorial_atlas_control.bags.typestore import load_typestore
from tutorial_atlas_control.sim.sim_config import SimConfig

#: rosgraph_msgs/Log levels.
WARN, ERROR, FATAL = 4, 8, 16
#: The simulator's step (s): /atlas/joint_states is published every step by default.
STEP_S = 0.001


def messages(bag: Path, topic: str) -> list[Any]:
    """Every message on `topic`, deserialized, in bag order."""
    from rosbags.rosbag1 import Reader

    with Reader(bag) as reader:
        connections = [c for c in reader.connections if c.topic == topic]
        if not connections:  # Reader.messages reads every connection when given none
            return []
        typestore = load_typestore(reader.connections)
        return [typestore.deserialize_ros1(raw, connection.msgtype)
                for connection, _, raw in reader.messages(connections=connections)]


def count(bag: Path, topic: str) -> int:
    from rosbags.rosbag1 import Reader

    with Reader(bag) as reader:
        return sum(c.msgcount for c in reader.connections if c.topic == topic)


def log_lines(bag: Path, node: str = '/atlas_sim', min_level: int = WARN) -> list[str]:
    """`node`'s /rosout messages at `min_level` or above."""
    return [msg.msg for msg in messages(bag, '/rosout')
            if msg.name == node and msg.level >= min_level]


def sim_configs(bag: Path) -> list[SimConfig]:
    return [SimConfig.from_json(msg.data) for msg in messages(bag, '/atlas/sim_config')]


def missing_steps(states: JointStateSeries) -> int:
    """Physics steps between the first and last joint state that have no message."""
    steps = np.rint(np.diff(states.t_s) / STEP_S).astype(np.int64)
    return int(np.sum(steps[steps > 1] - 1))


def all_finite(states: JointStateSeries) -> bool:
    return bool(np.isfinite(states.position).all() and np.isfinite(states.velocity).all()
                and np.isfinite(states.effort).all())
