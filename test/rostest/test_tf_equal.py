#!/usr/bin/env python3
"""rostest: the simulator's links' transforms equal Debian's robot_state_publisher's on the
same /atlas/joint_states: same frames, same stamps, within 1e-9.

The launch (tf_equal.test) starts paused with a second robot_state_publisher on /tf_rsp;
the test waits for both publishers, unpauses and watches WATCH_S of sim time.

robot_state_publisher subscribes with a queue of 1: on a busy machine it misses joint_states
messages and publishes the next one instead, and its later stamps shift with it (21 ms,
41 ms, ...), so few of its stamps may be the simulator's (every 20 ms). Hence two links:
each robot_state_publisher message equals the port's computation (link_transforms.py) on
the joint_states of its stamp, and each of the simulator's messages is exactly that
computation on the joint_states of its own stamp; where the stamps coincide, the two
messages are compared directly too.
"""

from __future__ import annotations

import threading
import time
import unittest
from collections.abc import Callable
from xmlrpc.client import ServerProxy

import numpy as np
import rosgraph
import rosnode
import rospy
import rostest
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_srvs.srv import Empty
from tf2_msgs.msg import TFMessage

from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.sim.link_transforms import LinkTransforms
from tutorial_atlas_control.sim.urdf import read_joints

PKG = 'tutorial_atlas_control'
#: Translations (m) and sign-normalized quaternions agree to this.
EQUAL_WITHIN = 1e-9
#: Sim time (s) watched, and the publications expected in it (50 Hz, the first at 20 ms).
WATCH_S = 3.0
EXPECTED_STAMPS = 150
#: robot_state_publisher (queue of 1) misses some joint_states on a busy machine, and then
#: publishes the next: at least this share of EXPECTED_STAMPS is still asked of it.
COMMON_SHARE = 0.8
WALL_TIMEOUT_S = 120.0
NS_PER_MS = 1_000_000
#: stamp (ns) -> (parent, child) -> translation (m) and sign-normalized quaternion (x y z w).
ByStamp = dict[int, dict[tuple[str, str], np.ndarray]]


def _rsp_hears_the_simulator() -> bool:
    """Whether robot_state_publisher's /atlas/joint_states connection to the simulator is
    up (the simulator's bus info), so that it sees the joint states from the first step."""
    try:
        uri = rosnode.get_api_uri(rosgraph.Master('/test_tf_equal'), '/atlas_sim')
        _code, _text, connections = ServerProxy(uri).getBusInfo('/test_tf_equal')
    except (OSError, rosnode.ROSNodeIOException):
        return False
    return any(topic == '/atlas/joint_states' and peer == '/reference_state_publisher'
               and connected for _id, peer, _direction, _transport, topic, connected, *_rest
               in connections)


def _by_stamp(store: ByStamp, msg: TFMessage) -> None:
    for transform in msg.transforms:
        if (transform.header.frame_id, transform.child_frame_id) in (
                ('world', 'pelvis'), ('head', 'hokuyo_link')):
            continue  # the simulator's ground truth, the laser's spindle: not URDF joints
        t, r = transform.transform.translation, transform.transform.rotation
        quaternion = np.array([r.x, r.y, r.z, r.w])
        if quaternion[3] < 0:  # q and -q are one rotation
            quaternion = -quaternion
        store.setdefault(transform.header.stamp.to_nsec(), {})[
            (transform.header.frame_id, transform.child_frame_id)] = np.r_[
                t.x, t.y, t.z, quaternion]


class TfEqualTest(unittest.TestCase):
    """The links' /tf: the simulator's and robot_state_publisher's, side by side."""

    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node('test_tf_equal')
        cls.lock = threading.Lock()
        cls.sim: ByStamp = {}
        cls.rsp: ByStamp = {}
        cls.static: dict[str, list[TFMessage]] = {'sim': [], 'rsp': []}
        cls.clock_s = 0.0
        cls.joint_states: dict[int, np.ndarray] = {}
        rospy.Subscriber('/atlas/joint_states', JointState, cls._on_joint_states,
                         queue_size=10_000)
        sim_sub = rospy.Subscriber('/tf', TFMessage, cls._on(cls.sim), queue_size=1000)
        rsp_sub = rospy.Subscriber('/tf_rsp', TFMessage, cls._on(cls.rsp), queue_size=1000)
        rospy.Subscriber('/tf_static', TFMessage, cls.static['sim'].append, queue_size=10)
        rospy.Subscriber('/tf_static_rsp', TFMessage, cls.static['rsp'].append, queue_size=10)
        rospy.Subscriber('/clock', Clock, cls._on_clock, queue_size=10)
        cls._wait(lambda: sim_sub.get_num_connections() >= 1
                  and rsp_sub.get_num_connections() >= 1 and _rsp_hears_the_simulator(),
                  'both /tf publishers, and robot_state_publisher on /atlas/joint_states')
        rospy.wait_for_service('/gazebo/unpause_physics', timeout=WALL_TIMEOUT_S)
        rospy.ServiceProxy('/gazebo/unpause_physics', Empty)()
        cls._wait(lambda: cls.clock_s >= WATCH_S, f'{WATCH_S} s of sim time')
        time.sleep(0.5)  # the messages stamped before it arrive

    @classmethod
    def _on(cls, store: ByStamp) -> Callable[[TFMessage], None]:
        def on_tf(msg: TFMessage) -> None:
            with cls.lock:
                _by_stamp(store, msg)
        return on_tf

    @classmethod
    def _on_joint_states(cls, msg: JointState) -> None:
        assert tuple(msg.name) == JOINT_NAMES
        with cls.lock:
            cls.joint_states[msg.header.stamp.to_nsec()] = np.array(msg.position)

    @classmethod
    def _on_clock(cls, msg: Clock) -> None:
        cls.clock_s = msg.clock.to_sec()

    @classmethod
    def _wait(cls, predicate, what: str) -> None:
        deadline = time.monotonic() + WALL_TIMEOUT_S
        while not predicate():
            if time.monotonic() > deadline or rospy.is_shutdown():
                raise AssertionError(f'timed out after {WALL_TIMEOUT_S} s waiting for {what}')
            time.sleep(0.01)

    def _watched(self, store: ByStamp) -> ByStamp:
        with self.lock:
            return {stamp: dict(frames) for stamp, frames in store.items()
                    if stamp <= WATCH_S * 1e9}

    def test_simulator_stamps_are_robot_state_publishers_rule(self) -> None:
        """Every joint_states reaches the simulator's schedule: a stamp every 20 ms from 20 ms."""
        stamps = sorted(self._watched(self.sim))
        self.assertEqual(stamps, [k * 20 * NS_PER_MS for k in range(1, EXPECTED_STAMPS + 1)])

    def _port(self, stamp: int) -> dict[tuple[str, str], np.ndarray]:
        """The port's transforms on the joint_states stamped `stamp` (as _by_stamp keeps)."""
        links = LinkTransforms(read_joints(rospy.get_param('/robot_description'))[1],
                               JOINT_NAMES)
        translations, rotations = np.zeros((len(links), 3)), np.zeros((len(links), 4))
        with self.lock:
            positions = self.joint_states[stamp]
        links.compute(positions, translations, rotations)
        rotations *= np.where(rotations[:, 3:] < 0, -1.0, 1.0)
        return {frames: np.r_[t, r] for frames, t, r in zip(links.frames, translations,
                                                             rotations)}

    def _worst(self, ours: dict[tuple[str, str], np.ndarray],
               theirs: dict[tuple[str, str], np.ndarray], stamp: int) -> tuple[float, float]:
        """Largest difference (translation m, quaternion) of two messages' transforms."""
        self.assertEqual(sorted(ours), sorted(theirs), f'frames at {stamp} ns')
        self.assertEqual(len(ours), 28)
        return (max(float(np.abs(ours[f][:3] - theirs[f][:3]).max()) for f in ours),
                max(float(np.abs(ours[f][3:] - theirs[f][3:]).max()) for f in ours))

    def test_links_equal_robot_state_publishers_on_the_same_joint_states(self) -> None:
        sim, rsp = self._watched(self.sim), self._watched(self.rsp)
        self.assertGreaterEqual(len(rsp), COMMON_SHARE * EXPECTED_STAMPS)
        # RSP's every message against the port's computation on the same joint_states.
        worst = [self._worst(self._port(stamp), frames, stamp) for stamp, frames in rsp.items()]
        worst_m, worst_q = (max(column) for column in zip(*worst))
        # The simulator's messages are that computation, to the bit.
        for stamp, frames in sim.items():
            self.assertEqual(self._worst(frames, self._port(stamp), stamp), (0.0, 0.0))
        common = sorted(set(sim) & set(rsp))
        direct = [self._worst(sim[stamp], rsp[stamp], stamp) for stamp in common]
        direct_m, direct_q = (max(column) for column in zip(*direct)) if direct else (0, 0)
        line = (f'links /tf vs robot_state_publisher on the same joint_states: {len(rsp)} '
                f'messages, max difference {worst_m:.3g} m, quaternion {worst_q:.3g}; '
                f'{len(common)} stamps in common with the simulator\'s {len(sim)}: '
                f'{direct_m:.3g} m, {direct_q:.3g}')
        rospy.loginfo(line)
        print(line, flush=True)
        for value in (worst_m, worst_q, direct_m, direct_q):
            self.assertLessEqual(value, EQUAL_WITHIN)
        # The robot moved (it settles after the pin): not constants compared.
        first, last = min(sim), max(sim)
        moved = max(float(np.abs(sim[first][f] - sim[last][f]).max()) for f in sim[first])
        self.assertGreater(moved, 1e-4)

    def test_tf_static_is_robot_state_publishers(self) -> None:
        """The URDF's fixed joints (the head's six sensor frames): each latches one message
        with the same transforms, in the same order, within EQUAL_WITHIN."""
        self._wait(lambda: self.static['sim'] and self.static['rsp'], 'both /tf_static')
        self.assertEqual(len(self.static['sim']), 1)
        self.assertEqual(len(self.static['rsp']), 1)
        sim, rsp = (self._static_rows(self.static[side][0]) for side in ('sim', 'rsp'))
        self.assertEqual([frames for frames, _ in sim], [frames for frames, _ in rsp])
        self.assertEqual(len(sim), 6)
        self.assertIn(('hokuyo_link', 'head_hokuyo_frame'), [frames for frames, _ in sim])
        for (frames, mine), (_, theirs) in zip(sim, rsp, strict=True):
            np.testing.assert_allclose(mine, theirs, atol=EQUAL_WITHIN, err_msg=str(frames))

    @staticmethod
    def _static_rows(msg: TFMessage) -> list[tuple[tuple[str, str], np.ndarray]]:
        rows = []
        for transform in msg.transforms:
            t, r = transform.transform.translation, transform.transform.rotation
            quaternion = np.array([r.x, r.y, r.z, r.w])
            rows.append(((transform.header.frame_id, transform.child_frame_id),
                         np.r_[t.x, t.y, t.z, quaternion if quaternion[3] >= 0 else -quaternion]))
        return rows

if __name__ == '__main__':
    rostest.rosrun(PKG, 'tf_equal', TfEqualTest)
