"""A live walker's height map from the head laser: the spindle set spinning, every scan
placed in the world by /tf (world -> the scan's frame, head_hokuyo_frame, at its stamp: the
spindle's hokuyo_link on /tf, the URDF's laser frame on /tf_static) and added to a
sensors/height_map.HeightMap with the pelvis's (x, y) of that stamp (its self filter). A
planner reads a copy of the map taken under the lock, not the map the scans are still going
into.
"""

from __future__ import annotations

import math
import threading
import time

import numpy as np
import rospy
import tf2_ros
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Float64

from tutorial_atlas_control import topics
from tutorial_atlas_control.sensors import HeightMap

__all__ = ['LaserListener']

WORLD_FRAME = 'world'
PELVIS_FRAME = 'pelvis'
#: How long (s, wall time) a scan waits for /tf to reach its stamp.
TF_WAIT_S = 0.2


def _matrix(x: float, y: float, z: float, w: float) -> np.ndarray:
    """A unit quaternion's rotation matrix."""
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


class LaserListener:
    """The scans of /multisense_sl/laser/scan into a height map, the spindle at `spin_rad_s`.
    Call after rospy.init_node."""

    def __init__(self, spin_rad_s: float) -> None:
        self.map = HeightMap()
        self.lock = threading.Lock()
        self.scans = 0
        self.dropped = 0
        self.buffer = tf2_ros.Buffer(cache_time=rospy.Duration(30))
        self._listener = tf2_ros.TransformListener(self.buffer)
        self._spindle = rospy.Publisher(topics.SET_SPINDLE_SPEED, Float64, queue_size=1,
                                        latch=True)
        self._spindle.publish(Float64(spin_rad_s))
        rospy.Subscriber(topics.LASER_SCAN, LaserScan, self._on_scan, queue_size=200)

    def _on_scan(self, scan: LaserScan) -> None:
        try:
            laser = self.buffer.lookup_transform(WORLD_FRAME, scan.header.frame_id,
                                                 scan.header.stamp, rospy.Duration(TF_WAIT_S))
            pelvis = self.buffer.lookup_transform(WORLD_FRAME, PELVIS_FRAME, scan.header.stamp,
                                                  rospy.Duration(TF_WAIT_S))
        except (tf2_ros.LookupException, tf2_ros.ExtrapolationException,
                tf2_ros.ConnectivityException):
            self.dropped += 1
            return
        t, q = laser.transform.translation, laser.transform.rotation
        angles = scan.angle_min + scan.angle_increment * np.arange(len(scan.ranges))
        where = pelvis.transform.translation
        with self.lock:
            self.map.add_scan(np.array([t.x, t.y, t.z]), _matrix(q.x, q.y, q.z, q.w), angles,
                              np.asarray(scan.ranges, dtype=float), (where.x, where.y))
            self.scans += 1

    def snapshot(self) -> HeightMap:
        """A copy of the map as it is now, to plan on."""
        copy = HeightMap(self.map.spec)
        with self.lock:
            points = self.map.points.copy()
        copy.add_points(points)
        return copy

    def wait_for_scans(self, count: int, timeout_s: float) -> bool:
        """Whether `count` more scans came within `timeout_s` (wall time)."""
        goal = self.scans + count
        deadline = time.monotonic() + timeout_s
        while self.scans < goal and time.monotonic() < deadline and not rospy.is_shutdown():
            time.sleep(0.05)
        return self.scans >= goal


def half_turn_scans(spin_rad_s: float, rate_hz: float = 40.0) -> int:
    """How many scans half a turn of the spindle takes (every direction once)."""
    return math.ceil(math.pi / spin_rad_s * rate_hz)
