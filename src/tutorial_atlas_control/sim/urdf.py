"""The URDF that goes with a MuJoCo model, for robot_state_publisher and rviz.

tools/make_atlas_mjcf.py writes sim/atlas_v1.urdf beside sim/atlas_v1.xml from one table.
A model variant (launch argument model:=...) has a URDF only if someone wrote one beside
it with the same name; when it is missing or describes other kinematics, TF would draw a
robot that is not the one simulated, so the simulator turns TF off and says why.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.sim.model import PELVIS_BODY

__all__ = ['UrdfError', 'UrdfJoint', 'matching_urdf', 'read_joints', 'urdf_path_for']

#: Joint origins and axes of the URDF and the MJCF agree to this (m, unit vector).
KINEMATICS_TOLERANCE = 1e-6


class UrdfError(AtlasControlError):
    """There is no URDF that describes the simulated model; the message says why."""


@dataclass(frozen=True)
class UrdfJoint:
    """One URDF joint, as robot_state_publisher reads it."""

    name: str
    kind: str
    parent: str
    child: str
    origin_m: np.ndarray
    rpy_rad: np.ndarray
    axis: np.ndarray
    lower_rad: float
    upper_rad: float


def urdf_path_for(model_path: Path | str) -> Path:
    """Where a model's URDF must be: beside it, same name, suffix .urdf."""
    return Path(model_path).with_suffix('.urdf')


def _vector(element: ET.Element | None, attribute: str, default: str) -> np.ndarray:
    text = default if element is None else element.get(attribute, default)
    return np.array([float(value) for value in text.split()])


def read_joints(text: str, source: str = 'URDF') -> tuple[list[str], list[UrdfJoint]]:
    """(link names, joints) of a URDF text, in file order.

    Raises:
        UrdfError: the text is not a URDF robot.
    """
    try:
        root = ET.fromstring(text)
    except ET.ParseError as err:
        raise UrdfError(f'{source} is not valid XML: {err}') from err
    if root.tag != 'robot':
        raise UrdfError(f'{source} is not a URDF: its root element is <{root.tag}>, not <robot>')
    links = [link.get('name', '') for link in root.findall('link')]
    joints = []
    try:
        for joint in root.findall('joint'):
            origin, limit = joint.find('origin'), joint.find('limit')
            joints.append(UrdfJoint(
                name=joint.get('name', ''), kind=joint.get('type', ''),
                parent=joint.find('parent').get('link', ''),
                child=joint.find('child').get('link', ''),
                origin_m=_vector(origin, 'xyz', '0 0 0'), rpy_rad=_vector(origin, 'rpy', '0 0 0'),
                axis=_vector(joint.find('axis'), 'xyz', '1 0 0'),
                lower_rad=float(limit.get('lower', 0.0)) if limit is not None else 0.0,
                upper_rad=float(limit.get('upper', 0.0)) if limit is not None else 0.0))
    except (AttributeError, ValueError) as err:
        raise UrdfError(f'{source}: a <joint> lacks its parent, child or a number ({err})') from err
    return links, joints


#: Joints that may carry a URDF link that is not a body of the model: a fixed frame (a
#: sensor's), or a spindle the model turns without a body (the laser's hokuyo_joint).
FRAME_JOINTS = ('fixed', 'continuous')


def _check_frames(extra_links: list[str], bodies: set[str], joints: list[UrdfJoint],
                  mismatch: str) -> None:
    """Every URDF link that is not a body hangs below one through FRAME_JOINTS only: a frame
    on the robot (the head's sensors), which robot_state_publisher publishes and the
    physics has no use for. Anything else is a link the model lacks.

    Raises:
        UrdfError: such a link has no body above it through frame joints (`mismatch`: the
            message's start).
    """
    into = {joint.child: joint for joint in joints}
    for link in extra_links:
        name = link
        while name not in bodies:
            joint = into.get(name)
            if joint is None or joint.kind not in FRAME_JOINTS:
                raise UrdfError(f'{mismatch}: links and bodies differ ({link} is neither a body '
                                'nor a frame fixed or spun on one)')
            name = joint.parent


def matching_urdf(model_path: Path | str, model: mujoco.MjModel) -> tuple[Path, str]:
    """The URDF beside `model_path` and its text, if it describes `model`'s kinematics.

    Every hinge joint of the model must be a URDF revolute joint of the same name between
    the same two links, with the same origin and axis; the URDF's links are the robot's
    bodies (the pelvis's tree: a world's loose bodies are not in the URDF) and frames
    fixed or spun on them (FRAME_JOINTS: the head's sensor frames).

    Raises:
        UrdfError: no such file, or it describes a different robot (the message says what).
    """
    path = urdf_path_for(model_path)
    if not path.is_file():
        raise UrdfError(f'the model {model_path} has no URDF beside it ({path} does not exist)')
    text = path.read_text()
    links, joints = read_joints(text, str(path))
    twice = sorted({link for link in links if links.count(link) > 1})
    if twice:  # rviz's RobotModel refuses such a robot ("link ... is not unique")
        raise UrdfError(f'{path}: link {twice[0]!r} is described twice')
    by_name = {joint.name: joint for joint in joints}
    # The robot's bodies: the pelvis's tree (a course's loose blocks are not the robot).
    robot_root = model.body_rootid[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, PELVIS_BODY)]
    bodies = {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in range(1, model.nbody)
              if model.body_rootid[b] == robot_root}
    missing = sorted(bodies - set(links))
    if missing:
        raise UrdfError(f'{path} does not match the model {model_path}: links and bodies differ '
                        f'({", ".join(missing[:5])})')
    _check_frames([link for link in links if link not in bodies], bodies, joints,
                  f'{path} does not match the model {model_path}')
    for joint_id in range(model.njnt):
        if model.jnt_type[joint_id] != mujoco.mjtJoint.mjJNT_HINGE:
            continue
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, joint_id)
        joint = by_name.get(name)
        body = int(model.jnt_bodyid[joint_id])
        child = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body)
        parent = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, int(model.body_parentid[body]))
        if joint is None or joint.kind not in ('revolute', 'continuous'):
            raise UrdfError(f'{path} does not match the model {model_path}: no revolute joint '
                            f'{name!r}')
        quat = np.zeros(4)
        mujoco.mju_euler2Quat(quat, joint.rpy_rad, 'XYZ')
        axis = joint.axis / np.linalg.norm(joint.axis)
        if ((joint.parent, joint.child) != (parent, child)
                or not np.allclose(joint.origin_m, model.body_pos[body], atol=KINEMATICS_TOLERANCE)
                or not np.allclose(np.abs(quat @ model.body_quat[body]), 1.0,
                                   atol=KINEMATICS_TOLERANCE)
                or not np.allclose(axis, model.jnt_axis[joint_id], atol=KINEMATICS_TOLERANCE)):
            raise UrdfError(f'{path} does not match the model {model_path}: joint {name!r} '
                            'connects other links or has another origin or axis')
    return path, text
