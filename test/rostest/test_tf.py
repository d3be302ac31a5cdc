#!/usr/bin/env python3
"""rostest: atlas.launch publishes the robot to TF (robot_description, the links' transforms,
world -> pelvis from the simulator), as rviz needs it.

The launch starts paused; the test subscribes to /tf and /ground_truth_odom, waits for the
/tf publishers (the simulator; with tf_publisher:=robot_state_publisher, that node too),
then unpauses: it sees /tf from sim time 0.
"""

from __future__ import annotations

import threading
import time
import unittest
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import rosgraph
import rospy
import rostest
import tf2_ros
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from rospy.impl.registration import get_topic_manager
from std_srvs.srv import Empty
from tf2_msgs.msg import TFMessage

from tutorial_atlas_control.sim import model as atlas_model

PKG = 'tutorial_atlas_control'
#: Every link of robot_description must be on /tf within this much sim time (s).
ALL_LINKS_WITHIN_S = 2.0
#: world -> pelvis and /ground_truth_odom at the same stamp agree within this (m).
POSE_TOLERANCE_M = 1e-3
#: Standing, the feet's TF heights are within this of the model's (m).
FOOT_HEIGHT_TOLERANCE_M = 0.03
#: When the feet are compared (s of sim time): standing, after the 1 s pin.
STANDING_AT_S = 3.0
#: Sim time (s) the test watches /tf and /ground_truth_odom for.
WATCH_S = 3.5
#: The head's sensor frames robot_description carries beside the robot's links.
SENSOR_FRAMES = {'hokuyo_link', 'head_hokuyo_frame', 'left_camera_frame',
                 'left_camera_optical_frame', 'right_camera_frame', 'right_camera_optical_frame',
                 'head_imu_link'}
#: Longest wall-clock wait (s).
WALL_TIMEOUT_S = 120.0


class TfTest(unittest.TestCase):
    """What rviz relies on, from the start of the simulation."""

    first_stamp_s: dict[str, float]
    pelvis_tf: dict[int, np.ndarray]
    pelvis_odom: dict[int, np.ndarray]

    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node('test_tf')
        cls.lock = threading.Lock()
        cls.first_stamp_s, cls.pelvis_tf, cls.pelvis_odom = {}, {}, {}
        cls.static_children: set[str] = set()
        cls.clock_s = 0.0
        cls.buffer = tf2_ros.Buffer(cache_time=rospy.Duration(60))
        cls.listener = tf2_ros.TransformListener(cls.buffer)
        tf_sub = rospy.Subscriber('/tf', TFMessage, cls._on_tf, queue_size=1000)
        rospy.Subscriber('/tf_static', TFMessage, cls._on_tf_static, queue_size=100)
        rospy.Subscriber('/ground_truth_odom', Odometry, cls._on_odom, queue_size=1000)
        rospy.Subscriber('/clock', Clock, cls._on_clock, queue_size=10)
        # robot_state_publisher: one for the links, one for the laser's spindle (DRCSim's).
        publishers = 3 if rospy.get_param('/atlas_sim/tf_publisher') != 'sim' else 1
        # The listener's /tf subscription is tf_sub's (one per topic in a rospy node); its
        # /tf_static one connects on its own, to every publisher the master lists.
        cls._wait(lambda: tf_sub.get_num_connections() >= publishers
                  and cls.tf_static_connected() and rospy.has_param('/robot_description'),
                  f'{publishers} publishers of /tf, and /tf_static\'s')
        rospy.wait_for_service('/gazebo/unpause_physics', timeout=WALL_TIMEOUT_S)
        rospy.ServiceProxy('/gazebo/unpause_physics', Empty)()
        # Each topic's messages come in order on its connection: once one stamped past the
        # watch has arrived, every message of the watch has.
        cls._wait(lambda: cls.latest_s('/tf') > WATCH_S and cls.latest_s('/odom') > WATCH_S,
                  f'/tf and /ground_truth_odom stamped after {WATCH_S} s')

    @classmethod
    def tf_static_connected(cls) -> bool:
        """Whether the listener's /tf_static subscription is connected to every publisher."""
        publishers, _subscribers, _services = rosgraph.Master('/test_tf').getSystemState()
        expected = len(dict(publishers).get('/tf_static', []))
        impl = get_topic_manager().get_subscriber_impl('/tf_static')
        return expected == 0 or (impl is not None and impl.get_num_connections() >= expected)

    @classmethod
    def latest_s(cls, topic: str) -> float:
        """The latest stamp (s) received on `topic` ('/tf': world -> pelvis; '/odom')."""
        with cls.lock:
            stamps = cls.pelvis_tf if topic == '/tf' else cls.pelvis_odom
            return max(stamps, default=-1) / 1e9

    @classmethod
    def _wait(cls, predicate, what: str) -> None:
        deadline = time.monotonic() + WALL_TIMEOUT_S
        while not predicate():
            if time.monotonic() > deadline or rospy.is_shutdown():
                raise AssertionError(f'timed out after {WALL_TIMEOUT_S} s waiting for {what}')
            time.sleep(0.01)

    @classmethod
    def _on_clock(cls, msg: Clock) -> None:
        cls.clock_s = msg.clock.to_sec()

    @classmethod
    def _on_tf(cls, msg: TFMessage) -> None:
        with cls.lock:
            for transform in msg.transforms:
                stamp_s = transform.header.stamp.to_sec()
                child = transform.child_frame_id
                cls.first_stamp_s[child] = min(stamp_s, cls.first_stamp_s.get(child, np.inf))
                if (transform.header.frame_id, child) == ('world', 'pelvis'):
                    t, r = transform.transform.translation, transform.transform.rotation
                    cls.pelvis_tf[transform.header.stamp.to_nsec()] = np.array(
                        [t.x, t.y, t.z, r.x, r.y, r.z, r.w])

    @classmethod
    def _on_tf_static(cls, msg: TFMessage) -> None:
        with cls.lock:
            cls.static_children.update(t.child_frame_id for t in msg.transforms)

    @classmethod
    def _on_odom(cls, msg: Odometry) -> None:
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        with cls.lock:
            cls.pelvis_odom[msg.header.stamp.to_nsec()] = np.array(
                [p.x, p.y, p.z, q.x, q.y, q.z, q.w])

    def test_every_link_of_robot_description_is_on_tf_within_2_s(self) -> None:
        """The robot's 29 links and the head's sensor frames: the moving ones on /tf within
        2 s of sim time (the laser's hokuyo_link among them), the fixed frames (the scan's
        head_hokuyo_frame, the cameras', the IMU's) on /tf_static."""
        root = ET.fromstring(rospy.get_param('/robot_description'))
        links = {link.get('name') for link in root.findall('link')}
        fixed = {joint.find('child').get('link') for joint in root.findall('joint')
                 if joint.get('type') == 'fixed'}
        self.assertEqual(len(links), 29 + len(SENSOR_FRAMES))
        self.assertEqual(fixed, SENSOR_FRAMES - {'hokuyo_link'})
        with self.lock:
            first, static = dict(self.first_stamp_s), set(self.static_children)
        self.assertEqual(sorted(fixed - static), [], 'fixed frames never seen on /tf_static')
        moving = links - fixed
        missing = sorted(moving - set(first))
        self.assertEqual(missing, [], 'links never seen on /tf')
        late = {link: first[link] for link in moving if first[link] > ALL_LINKS_WITHIN_S}
        self.assertEqual(late, {}, f'links first on /tf after {ALL_LINKS_WITHIN_S} s of sim time')
        rospy.loginfo(
            f'every link on /tf by {max(first[link] for link in moving):.3f} s of sim time')

    def test_world_to_pelvis_is_the_ground_truth(self) -> None:
        with self.lock:
            common = sorted(set(self.pelvis_tf) & set(self.pelvis_odom))
            pairs = [(self.pelvis_tf[s], self.pelvis_odom[s]) for s in common]
        # 100 Hz each over WATCH_S: nearly every stamp pairs up.
        self.assertGreater(len(pairs), 0.9 * 100 * WATCH_S)
        position_error_m = max(np.linalg.norm(tf[:3] - odom[:3]) for tf, odom in pairs)
        self.assertLessEqual(position_error_m, POSE_TOLERANCE_M)
        rotation_error = max(1.0 - abs(float(tf[3:] @ odom[3:])) for tf, odom in pairs)
        self.assertLess(rotation_error, 1e-9)
        # The pelvis moved (it settles after the pin): the comparison is not of constants.
        heights = [odom[2] for _tf, odom in pairs]
        self.assertGreater(max(heights) - min(heights), 1e-5)

    def test_standing_feet_heights_match_the_model(self) -> None:
        atlas = atlas_model.load_model()
        data = mujoco.MjData(atlas.model)
        atlas_model.reset_to_initial(atlas, data)
        for side in ('l', 'r'):
            expected_m = float(data.body(f'{side}_foot').xpos[2])
            stamp = rospy.Time.from_sec(STANDING_AT_S)
            transform = self.buffer.lookup_transform('world', f'{side}_foot', stamp,
                                                     rospy.Duration(5.0))
            height_m = transform.transform.translation.z
            rospy.loginfo(f'{side}_foot at {STANDING_AT_S} s: TF height {height_m:.4f} m, '
                          f'model {expected_m:.4f} m')
            self.assertAlmostEqual(height_m, expected_m, delta=FOOT_HEIGHT_TOLERANCE_M)


if __name__ == '__main__':
    rostest.rosrun(PKG, 'tf', TfTest)
