"""Where a foot went during a recorded run, from the recorded pose (no foot topic needed).

The bag has the pelvis pose (/ground_truth_odom) and the joint angles (/atlas/joint_states);
forward kinematics of the model in those poses gives the feet. The demo's summary uses it
to show a step: the right foot's displacement from the first applied command to the end.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from tutorial_atlas_control.bags.analysis import first_applied_command_s
from tutorial_atlas_control.bags.reader import BagData
from tutorial_atlas_control.bags.render import prepare_gl
from tutorial_atlas_control.joints import NUM_JOINTS, joint_index

__all__ = ['FootDisplacement', 'RecordedKinematics', 'foot_displacement', 'foot_line']

#: The MJCF body of the right foot (the swing foot of the package's steps).
RIGHT_FOOT_BODY = 'r_foot'


@dataclass(frozen=True)
class FootDisplacement:
    """A foot's world displacement (m) between two times (s from the bag's start)."""

    body: str
    start_s: float
    end_s: float
    displacement_m: np.ndarray  # (3,) x (forward at the start), y (left), z (up)


def _row_at(t_s: np.ndarray, at_s: float) -> int:
    """The last sample at or before `at_s` (the first one if none is)."""
    return int(np.clip(np.searchsorted(t_s, at_s, side='right') - 1, 0, len(t_s) - 1))


class RecordedKinematics:
    """The model placed as the bag recorded it, at any time of the run: the pelvis pose
    (/ground_truth_odom) and the joint angles (/atlas/joint_states; a joint the bag lacks at
    0), each the last sample at or before that time; forward kinematics only."""

    def __init__(self, data: BagData) -> None:
        pelvis, states = data.pelvis, data.joint_states
        if pelvis is None or states is None:
            raise ValueError('the bag has no pelvis pose or no joint states')
        prepare_gl()  # before mujoco's first import: a video may be rendered afterwards
        import mujoco  # noqa: PLC0415

        from tutorial_atlas_control.sim import load_model  # noqa: PLC0415 - imports mujoco

        self._mujoco = mujoco
        self.atlas = load_model()
        self.data = mujoco.MjData(self.atlas.model)
        self._pelvis, self._states = pelvis, states
        self._columns = [(column, index) for column, name in enumerate(states.names)
                         if (index := joint_index(name)) is not None]
        self._angles = np.zeros(NUM_JOINTS)

    def body_id(self, name: str) -> int:
        """The model's body `name` (-1 if it has none)."""
        return self._mujoco.mj_name2id(self.atlas.model, self._mujoco.mjtObj.mjOBJ_BODY, name)

    def place(self, at_s: float) -> Any:
        """The MjData (kinematics computed) as recorded at `at_s` (s from the bag's start)."""
        pelvis, states, atlas, data = self._pelvis, self._states, self.atlas, self.data
        pose_row, joint_row = _row_at(pelvis.t_s, at_s), _row_at(states.t_s, at_s)
        for column, index in self._columns:
            self._angles[index] = states.position[joint_row, column]
        adr = atlas.free_qpos_adr
        data.qpos[adr:adr + 3] = pelvis.position_m[pose_row]
        data.qpos[adr + 3:adr + 7] = pelvis.orientation_xyzw[pose_row, [3, 0, 1, 2]]
        data.qpos[atlas.qpos_adr] = self._angles
        self._mujoco.mj_kinematics(atlas.model, data)
        return data


def foot_displacement(data: BagData, body: str = RIGHT_FOOT_BODY) -> FootDisplacement | None:
    """`body`'s displacement from the first applied command (else the first pose) to the
    last pose both topics cover; None without pelvis pose or joint states."""
    pelvis, states = data.pelvis, data.joint_states
    if pelvis is None or states is None or not len(pelvis.t_s) or not len(states.t_s):
        return None
    first_s = max(float(pelvis.t_s[0]), float(states.t_s[0]))
    end_s = min(float(pelvis.t_s[-1]), float(states.t_s[-1]))
    start_s = max(first_s, first_applied_command_s(data) or first_s)
    if end_s < start_s:
        return None
    kinematics = RecordedKinematics(data)
    body_id = kinematics.body_id(body)
    if body_id < 0:
        return None

    def position_at(at_s: float) -> np.ndarray:
        return kinematics.place(at_s).xpos[body_id].copy()

    return FootDisplacement(body, start_s, end_s, position_at(end_s) - position_at(start_s))


def foot_line(data: BagData) -> str | None:
    """The summary's line on the right foot (None: the bag lacks the pose)."""
    moved = foot_displacement(data)
    if moved is None:
        return None
    dx, dy, dz = moved.displacement_m
    since = 'the first command' if first_applied_command_s(data) is not None else 'the start'
    return (f'right foot moved {dx:+.3f} m forward (x), {dy:+.3f} m sideways (y), {dz:+.3f} m '
            f'up from {since} (t = {moved.start_s:.2f} s) to the end (t = {moved.end_s:.2f} s)')
