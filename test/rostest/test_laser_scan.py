#!/usr/bin/env python3
"""rostest: the MultiSense SL head's laser on atlas.launch.

sensor_msgs/LaserScan by type and MD5, 720 ranges in head_hokuyo_frame, one scan every
25 ms of sim time; standing with the spindle at 0 the scan plane is level (the ground is 77
m ahead: every range +inf); set_spindle_speed 50 RPM turns hokuyo_joint, and the scans then
meet the ground: their points, placed in the world by /tf (world -> hokuyo_link, the
simulator's) and the URDF's laser frame, lie on the floor (z = 0) within 3 cm.
"""

from __future__ import annotations

import threading
import unittest

import numpy as np
import rospy
import rostest
import tf2_ros
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState, LaserScan
from std_msgs.msg import Float64

from tutorial_atlas_control import topics
from tutorial_atlas_control.processes import wait_until
from tutorial_atlas_control.sensors import HOKUYO, HOKUYO_FRAME, MAX_SPINDLE_SPEED

PKG = 'tutorial_atlas_control'
#: Sim time (s) the spindle stays at 0, then spins, before the scans are judged.
STILL_UNTIL_S = 2.0
SPIN_FOR_S = 1.5
#: A floor point's height tolerance (m): 3 sigma of noise, the pose's interpolation in /tf.
FLOOR_TOLERANCE_M = 0.03
#: No point lies below the floor by more than the noise can put it: six standard deviations
#: (over the ~10^4 floor points of a run, 3 sigma is passed about once: a run's lowest point
#: at -3.07 cm failed a 3 cm bound; a ray through the floor would read far below it).
BELOW_FLOOR_M = 6.0 * HOKUYO.noise_m
WALL_TIMEOUT_S = 60.0


def _not_shut_down() -> None:
    if rospy.is_shutdown():
        raise AssertionError('rospy shut down while waiting')


class LaserScanTest(unittest.TestCase):
    """The scan stream of a standing robot, still then spinning."""

    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node('test_laser_scan')
        cls.lock = threading.Lock()
        cls.scans: list[LaserScan] = []
        cls.headers: list[dict[str, str]] = []
        cls.spindle: list[JointState] = []
        cls.clock_s = 0.0
        cls.buffer = tf2_ros.Buffer(cache_time=rospy.Duration(30))
        cls.listener = tf2_ros.TransformListener(cls.buffer)
        rospy.Subscriber(topics.LASER_SCAN, rospy.AnyMsg, cls._on_scan, queue_size=1000)
        rospy.Subscriber(topics.HEAD_JOINT_STATES, JointState, cls._on_spindle,
                         queue_size=5000)
        rospy.Subscriber(topics.CLOCK, Clock, cls._on_clock, queue_size=10)
        speed = rospy.Publisher(topics.SET_SPINDLE_SPEED, Float64, queue_size=1, latch=True)
        cls._wait(lambda: cls.clock_s > STILL_UNTIL_S, f'sim time {STILL_UNTIL_S} s')
        with cls.lock:
            cls.spin_from_s = cls.clock_s
        speed.publish(Float64(MAX_SPINDLE_SPEED))
        cls._wait(lambda: cls.clock_s > cls.spin_from_s + SPIN_FOR_S + 0.2,
                  'the spindle spinning')
        # The spinning scans as of now, and /tf caught up with the last of them (a scan can
        # come before the transform of its step).
        with cls.lock:
            cls.spun = [s for s in cls.scans if s.header.stamp.to_sec() > cls.spin_from_s + 0.5]
        last = cls.spun[-1].header.stamp if cls.spun else rospy.Time(0)
        cls._wait(lambda: cls.buffer.can_transform('world', 'hokuyo_link', last),
                  f'/tf of hokuyo_link at {last.to_sec():.3f} s')

    @classmethod
    def _wait(cls, predicate, what: str) -> None:
        wait_until(predicate, WALL_TIMEOUT_S, f'no {what}', check=_not_shut_down)

    @classmethod
    def _on_clock(cls, msg: Clock) -> None:
        with cls.lock:
            cls.clock_s = msg.clock.to_sec()

    @classmethod
    def _on_scan(cls, msg: rospy.AnyMsg) -> None:
        scan = LaserScan().deserialize(msg._buff)
        with cls.lock:
            cls.scans.append(scan)
            cls.headers.append(dict(msg._connection_header))

    @classmethod
    def _on_spindle(cls, msg: JointState) -> None:
        with cls.lock:
            cls.spindle.append(msg)

    def test_the_scan_is_drcsims_message_at_40_hz(self) -> None:
        with self.lock:
            scans, header = list(self.scans), self.headers[0]
        self.assertEqual(header['type'], 'sensor_msgs/LaserScan')
        self.assertEqual(header['md5sum'], LaserScan._md5sum)
        stamps = np.array([scan.header.stamp.to_nsec() for scan in scans])
        self.assertGreater(len(scans), 100)
        # 40 Hz of sim time, none lost (the state before the first step may come 1 ms early).
        self.assertEqual(set(np.diff(stamps[1:])), {25_000_000})
        for scan in scans[:3]:
            self.assertEqual(scan.header.frame_id, 'head_hokuyo_frame')
            self.assertEqual(len(scan.ranges), HOKUYO.samples)
            self.assertAlmostEqual(scan.angle_min, HOKUYO.min_angle, places=6)
            self.assertAlmostEqual(scan.range_max, HOKUYO.range_max, places=6)

    def test_standing_with_the_spindle_at_0_the_level_plane_sees_nothing(self) -> None:
        with self.lock:
            still = [s for s in self.scans if 0.5 < s.header.stamp.to_sec() < self.spin_from_s]
        self.assertGreater(len(still), 40)
        for scan in still:
            self.assertTrue(np.all(np.isposinf(scan.ranges)), scan.header.stamp)

    def test_set_spindle_speed_turns_hokuyo_joint(self) -> None:
        with self.lock:
            states = [s for s in self.spindle
                      if s.header.stamp.to_sec() > self.spin_from_s + SPIN_FOR_S]
        self.assertEqual(states[0].name, ['hokuyo_joint'])
        self.assertAlmostEqual(states[-1].velocity[0], MAX_SPINDLE_SPEED, delta=0.05)
        angles = np.unwrap([s.position[0] for s in states])
        span_s = states[-1].header.stamp.to_sec() - states[0].header.stamp.to_sec()
        self.assertAlmostEqual(angles[-1] - angles[0], MAX_SPINDLE_SPEED * span_s, delta=0.05)

    def test_spinning_the_scans_meet_the_floor(self) -> None:
        """The spinning scans' points meet the floor (z = 0 within 3 cm), and none lies
        below it by more than the noise can put it."""
        spinning = self.spun
        floor_points, lowest = 0, []
        angles = HOKUYO.angles()
        for scan in spinning:
            ranges = np.array(scan.ranges)
            hit = np.isfinite(ranges)
            if not hit.any():
                continue
            pose = self.buffer.lookup_transform('world', 'hokuyo_link', scan.header.stamp)
            t, q = pose.transform.translation, pose.transform.rotation
            rotation = _matrix(q.x, q.y, q.z, q.w)
            origin = np.array([t.x, t.y, t.z]) + rotation @ np.array(HOKUYO_FRAME.xyz_m)
            rays = np.stack((np.cos(angles[hit]), np.sin(angles[hit]), np.zeros(hit.sum())))
            z = origin[2] + (rotation @ rays)[2] * ranges[hit]
            floor_points += int(np.sum(np.abs(z) < FLOOR_TOLERANCE_M))
            lowest.append(float(z.min()))
        self.assertGreater(floor_points, 500)
        self.assertGreater(min(lowest), -BELOW_FLOOR_M)


def _matrix(x: float, y: float, z: float, w: float) -> np.ndarray:
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


if __name__ == '__main__':
    rostest.rosrun(PKG, 'laser_scan', LaserScanTest)
