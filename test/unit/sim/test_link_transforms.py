"""sim/link_transforms.py: the links' transforms the simulator publishes in
robot_state_publisher's stead, against MuJoCo's body poses and RSP 1.15's rules."""

from __future__ import annotations

import io
from pathlib import Path

import genpy
import mujoco
import numpy as np
import pytest
from geometry_msgs.msg import TransformStamped
from rospy.msg import serialize_message
from tf2_msgs.msg import TFMessage

from tutorial_atlas_control import topics
from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.msgs.wire import TransformsWire
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.sim.controller_statistics import CommandAgeStatistics
from tutorial_atlas_control.sim.link_transforms import (
    LinkTransforms,
    RspSchedule,
    quaternion_multiply,
    rpy_quaternion,
)
from tutorial_atlas_control.sim.simulator import AtlasSimulator
from tutorial_atlas_control.sim.urdf import UrdfJoint, read_joints
from tutorial_atlas_control.stepping.loop import LoopSettings, SteppingLoop
from tutorial_atlas_control.stepping.outputs import LoopOutputs
from tutorial_atlas_control.stepping.pacing import Pacer
from tutorial_atlas_control.units import NS_PER_S

ROOT = Path(__file__).resolve().parents[3]
URDF = ROOT / 'sim' / 'atlas_v1.urdf'
CONFIG = ROOT / 'config' / 'atlas_controller.yaml'
#: Double-precision agreement of two ways of composing the same few rotations.
EXACT = 1e-12


def sign_normalized(quaternions_xyzw: np.ndarray) -> np.ndarray:
    """q and -q are one rotation: make w (else the first non-zero) non-negative."""
    return quaternions_xyzw * np.where(quaternions_xyzw[..., 3:] < 0, -1.0, 1.0)


def atlas_links() -> LinkTransforms:
    return LinkTransforms(read_joints(URDF.read_text())[1], JOINT_NAMES)


def joint(name: str, kind: str, origin=(0.0, 0.0, 0.0), rpy=(0.0, 0.0, 0.0),
          axis=(1.0, 0.0, 0.0), parent: str = 'a', child: str = 'b') -> UrdfJoint:
    return UrdfJoint(name, kind, parent, child, np.array(origin, dtype=float),
                     np.array(rpy, dtype=float), np.array(axis, dtype=float), 0.0, 0.0)


def test_rpy_is_urdf_fixed_axis_roll_pitch_yaw() -> None:
    rng = np.random.default_rng(3)
    for rpy in rng.uniform(-np.pi, np.pi, size=(20, 3)):
        expected = np.zeros(4)
        mujoco.mju_euler2Quat(expected, rpy, 'XYZ')  # extrinsic x, y, z (w x y z)
        assert np.allclose(sign_normalized(rpy_quaternion(rpy)),
                           sign_normalized(np.r_[expected[1:], expected[0]]), atol=EXACT)
    # Yaw a quarter turn: z up.
    assert np.allclose(rpy_quaternion([0.0, 0.0, np.pi / 2]),
                       [0.0, 0.0, np.sqrt(0.5), np.sqrt(0.5)], atol=EXACT)


def test_quaternion_multiply_composes_rotations() -> None:
    quarter_z = np.array([0.0, 0.0, np.sqrt(0.5), np.sqrt(0.5)])
    quarter_x = np.array([np.sqrt(0.5), 0.0, 0.0, np.sqrt(0.5)])
    # Half turns compose to the half turn about z; x then z is not z then x.
    assert np.allclose(quaternion_multiply(quarter_z, quarter_z), [0.0, 0.0, 1.0, 0.0])
    assert not np.allclose(quaternion_multiply(quarter_z, quarter_x),
                           quaternion_multiply(quarter_x, quarter_z))


def test_atlas_links_equal_mujoco_body_poses_relative_to_their_parents() -> None:
    """For random joint angles, each transform is parent^-1 * child of MuJoCo's world poses."""
    atlas = atlas_model.load_model()
    model, data = atlas.model, mujoco.MjData(atlas.model)
    links = atlas_links()
    assert len(links) == len(JOINT_NAMES) == 28
    assert list(links.joint_names) == sorted(JOINT_NAMES)  # std::map order
    rng = np.random.default_rng(7)
    translations, rotations = np.zeros((28, 3)), np.zeros((28, 4))
    worst_m, worst_q = 0.0, 0.0
    for _ in range(10):
        positions = rng.uniform(atlas.lower_rad, atlas.upper_rad)
        data.qpos[:] = model.qpos0
        data.qpos[atlas.qpos_adr] = positions
        mujoco.mj_kinematics(model, data)
        links.compute(positions, translations, rotations)
        for k, (parent, child) in enumerate(links.frames):
            p, c = data.body(parent), data.body(child)
            inverse = np.zeros(4)
            mujoco.mju_negQuat(inverse, p.xquat)
            relative_wxyz, relative_m = np.zeros(4), np.zeros(3)
            mujoco.mju_mulQuat(relative_wxyz, inverse, c.xquat)
            mujoco.mju_rotVecQuat(relative_m, c.xpos - p.xpos, inverse)
            worst_m = max(worst_m, float(np.abs(translations[k] - relative_m).max()))
            expected = sign_normalized(np.r_[relative_wxyz[1:], relative_wxyz[0]])
            worst_q = max(worst_q, float(np.abs(sign_normalized(rotations[k]) - expected).max()))
    # MuJoCo's poses go through the whole chain from the world: agreement to 1e-9, not 1e-16.
    assert worst_m < 1e-9 and worst_q < 1e-9
    assert np.allclose(np.linalg.norm(rotations, axis=1), 1.0, atol=EXACT)


def test_prismatic_slides_along_its_rotated_axis_and_fixed_goes_static() -> None:
    links = LinkTransforms([joint('slide', 'prismatic', origin=(1.0, 0.0, 0.0),
                                  rpy=(0.0, 0.0, np.pi / 2), axis=(2.0, 0.0, 0.0)),
                            joint('hinge', 'revolute', axis=(0.0, 0.0, 1.0), child='c'),
                            joint('bolt', 'fixed', origin=(0.0, 0.5, 0.0), child='d'),
                            joint('free', 'floating', child='e'),
                            joint('unheard', 'revolute', child='f')],
                           position_names=('hinge', 'slide'))
    assert links.joint_names == ('hinge', 'slide')  # 'unheard' is not in joint_states
    translations, rotations = np.zeros((2, 3)), np.zeros((2, 4))
    links.compute(np.array([np.pi, 0.25]), translations, rotations)
    assert np.allclose(translations, [[0.0, 0.0, 0.0], [1.0, 0.25, 0.0]], atol=EXACT)
    assert np.allclose(rotations, [[0.0, 0.0, 1.0, 0.0],
                                   [0.0, 0.0, np.sqrt(0.5), np.sqrt(0.5)]], atol=EXACT)
    [bolt] = links.static
    assert (bolt.parent, bolt.child) == ('a', 'd')
    assert np.allclose(bolt.translation_m, [0.0, 0.5, 0.0])


def test_schedule_is_robot_state_publishers_rule() -> None:
    ms = NS_PER_S // 1000
    schedule = RspSchedule(50.0)
    assert schedule.interval_ns == 20 * ms
    # Every joint_states at 1 kHz: the first at 20 ms, then every 20 ms.
    published = [t for t in range(0, 101 * ms, ms) if schedule.due(t)]
    assert published == [20 * ms, 40 * ms, 60 * ms, 80 * ms, 100 * ms]
    # A message lost (queue of 1): the next one goes, and the interval counts from it.
    schedule = RspSchedule(50.0)
    assert [t for t in (19 * ms, 21 * ms, 40 * ms, 41 * ms) if schedule.due(t)] == [
        21 * ms, 41 * ms]
    # Time going back (reset_simulation) forgets the last publication.
    assert not schedule.due(5 * ms) and schedule.due(20 * ms)
    # publish_frequency below 1 Hz counts as 1 Hz, as in robot_state_publisher.
    assert RspSchedule(0.1).interval_ns == NS_PER_S


def test_transforms_wire_is_genpys_tf_message() -> None:
    frames = (('pelvis', 'ltorso'), ('l_leg_uhz', 'l_leg_mhx'), ('a', 'b'))
    message = TransformsWire(frames)
    rng = np.random.default_rng(2)
    values = rng.normal(size=(3, 7))
    message.translations[:] = values[:, :3]
    message.rotations_xyzw[:] = values[:, 3:]
    stamp_ns = 12 * NS_PER_S + 345_678
    expected = TFMessage()
    for (parent, child), row in zip(frames, values):
        transform = TransformStamped()
        transform.header.stamp = genpy.Time(12, 345_678)
        transform.header.frame_id, transform.child_frame_id = parent, child
        t, r = transform.transform.translation, transform.transform.rotation
        t.x, t.y, t.z, r.x, r.y, r.z, r.w = (float(v) for v in row)
        expected.transforms.append(transform)
    buffer = io.BytesIO()
    serialize_message(buffer, 0, expected)
    assert message.to_bytes(stamp_ns) == buffer.getvalue()
    # The next stamp rewrites every header; the numbers stay.
    for transform in expected.transforms:
        transform.header.stamp = genpy.Time(13, 0)
    buffer = io.BytesIO()
    serialize_message(buffer, 0, expected)
    assert message.to_bytes(13 * NS_PER_S) == buffer.getvalue()


class Outbox:
    def __init__(self) -> None:
        self.tf: list[bytes] = []

    def wanted(self, outlet: str) -> bool:
        return True

    def add(self, outlet: str, data: bytes | bytearray) -> None:
        if outlet == topics.TF:
            self.tf.append(bytes(data))

    def replace(self, outlet: str, data: bytes | bytearray) -> None:
        pass

    def flush(self) -> None:
        pass


class Log:
    def info(self, text: str) -> None:
        pass

    warning = error = info


@pytest.mark.parametrize('joint_states_rate_hz', [1000.0, 300.0])
def test_loop_publishes_links_at_robot_state_publishers_stamps(
        joint_states_rate_hz: float) -> None:
    """The links' /tf goes out with the joint_states RSP would publish from, holding their
    positions: stamps every 20 ms of sim time (at 300 Hz: the first joint_states 20 ms or
    more after the last), beside world -> pelvis at 100 Hz."""
    atlas = atlas_model.load_model()
    sim = AtlasSimulator(atlas, load_gains_yaml(CONFIG))
    outbox = Outbox()
    rates = {'joint_states': joint_states_rate_hz, 'odom': 100.0, 'imu': 1000.0,
             'contact': 1000.0, 'tf': 100.0}
    outlets = {topic: topic for topic in (
        topics.CLOCK, topics.JOINT_STATES, topics.IMU, topics.L_FOOT_CONTACT,
        topics.R_FOOT_CONTACT, topics.GROUND_TRUTH_ODOM, topics.TF,
        topics.CONTROLLER_STATISTICS)}
    loop = SteppingLoop(sim, LoopOutputs(outbox, outlets, Log(), lambda _json: None),
                        LoopSettings(rates, links=atlas_links()), CommandAgeStatistics(sim.dt_s),
                        pacer=Pacer(0.0))
    joint_states: dict[int, np.ndarray] = {}
    original = loop.publisher.publish

    def publish(count: int) -> None:
        original(count)
        joint_states[sim.sim_time_ns] = sim.data.qpos[atlas.qpos_adr].copy()
    loop.publisher.publish = publish
    steps = [0]
    loop.run(lambda: (steps.__setitem__(0, steps[0] + 1) or steps[0] > 100))
    links_messages = [m for m in outbox.tf if len(m) > 200]
    # The laser's spindle (head -> hokuyo_link) goes out with the links, stamped alike.
    spindle = [m for m in outbox.tf if len(m) <= 200 and b'hokuyo_link' in m]
    pelvis = [m for m in outbox.tf if len(m) <= 200 and b'hokuyo_link' not in m]
    assert len(pelvis) == 11  # steps 0, 10, ..., 100
    assert [TFMessage().deserialize(m[4:]).transforms[0].header.stamp for m in spindle] == [
        TFMessage().deserialize(m[4:]).transforms[0].header.stamp for m in links_messages]
    stamps = [TFMessage().deserialize(m[4:]).transforms[0].header.stamp.to_nsec()
              for m in links_messages]
    js_every_ms = 1 if joint_states_rate_hz == 1000.0 else 3
    schedule = RspSchedule(50.0)
    expected = [t * 1_000_000 for t in range(0, 101, js_every_ms)
                if schedule.due(t * 1_000_000)]
    assert stamps == expected and len(stamps) >= 4
    links = atlas_links()
    translations, rotations = np.zeros((28, 3)), np.zeros((28, 4))
    for raw, stamp in zip(links_messages, stamps):
        message = TFMessage().deserialize(raw[4:])
        assert [(t.header.frame_id, t.child_frame_id) for t in message.transforms] == list(
            links.frames)
        links.compute(joint_states[stamp], translations, rotations)
        got = np.array([[t.transform.rotation.x, t.transform.rotation.y,
                         t.transform.rotation.z, t.transform.rotation.w]
                        for t in message.transforms])
        assert np.array_equal(got, rotations)
    # The robot moved between the first and the last: not a constant compared.
    first, last = (TFMessage().deserialize(m[4:]) for m in (links_messages[0],
                                                              links_messages[-1]))
    assert first.transforms[0].transform.rotation != last.transforms[0].transform.rotation
