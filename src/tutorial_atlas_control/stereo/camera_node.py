"""The stereo pair's ROS side: renders /multisense_sl/camera/{left,right} from the
simulator's world state, only while someone looks.

usage: multisense_cameras.py MODEL_FILE [ROS arguments]   (atlas.launch starts it)

Rendering 800 x 800 in software takes tens of milliseconds a frame, so it is done here, in a
process of its own at low priority, never in the simulator's stepping thread. While any of
its topics has a subscriber, this node subscribes to /atlas/render_state (the world's qpos,
which the simulator sends only while someone listens, at ~render_state_rate), takes the
states due at the frame rate and renders the sides asked for; each image and camera_info is
stamped with the sim time of the state rendered. When it falls behind, frames are skipped.
With nobody subscribed it holds no subscription and renders nothing.
"""

from __future__ import annotations

import io
import threading
import time

import numpy as np
import rospy
from sensor_msgs.msg import CameraInfo, CompressedImage, Image, JointState
from std_msgs.msg import Float64

from tutorial_atlas_control import topics
from tutorial_atlas_control.stereo.frame_rate import FrameClock, fps_request
from tutorial_atlas_control.stereo.head_cameras import StereoRenderer
from tutorial_atlas_control.stereo.multisense import DEFAULT_FPS, OPTICAL_FRAME, SIDES, intrinsics

__all__ = ['CameraNode', 'camera_info']

#: image_transport's compressed format for a JPEG of an rgb8 image (decoded as bgr8).
JPEG_FORMAT = 'rgb8; jpeg compressed bgr8'
JPEG_QUALITY = 90
#: How often (wall seconds) the subscribers are counted again, besides rospy's callbacks.
DEMAND_POLL_S = 1.0


def camera_info(side: str, stamp: rospy.Time) -> CameraInfo:
    """The camera_info of `side` at `stamp` (plumb_bob, no distortion, R identity)."""
    numbers = intrinsics(side)
    info = CameraInfo()
    info.header.stamp = stamp
    info.header.frame_id = OPTICAL_FRAME
    info.width, info.height = numbers.width, numbers.height
    info.distortion_model = 'plumb_bob'
    info.D = [0.0] * 5
    info.K = list(numbers.k)
    info.R = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    info.P = list(numbers.p)
    return info


class _Outlets:
    """One side's publishers: image_raw, image_raw/compressed, camera_info."""

    def __init__(self, namespace: str, listener: rospy.SubscribeListener) -> None:
        self.image = rospy.Publisher(f'{namespace}/image_raw', Image, queue_size=1,
                                     subscriber_listener=listener)
        self.compressed = rospy.Publisher(f'{namespace}/image_raw/compressed', CompressedImage,
                                          queue_size=1, subscriber_listener=listener)
        self.info = rospy.Publisher(f'{namespace}/camera_info', CameraInfo, queue_size=1,
                                    subscriber_listener=listener)

    def wants_image(self) -> bool:
        return self.image.get_num_connections() + self.compressed.get_num_connections() > 0

    def heard(self) -> bool:
        return self.wants_image() or self.info.get_num_connections() > 0


class _DemandListener(rospy.SubscribeListener):
    """Tells the node when a subscriber comes or goes."""

    def __init__(self, node: CameraNode) -> None:
        super().__init__()
        self.node = node

    def peer_subscribe(self, *_args: object) -> None:
        self.node.demand_changed()

    def peer_unsubscribe(self, *_args: object) -> None:
        self.node.demand_changed()


class CameraNode:
    """Subscribes to the world state while heard, renders what is due, publishes it."""

    def __init__(self, renderer: StereoRenderer) -> None:
        self.renderer = renderer
        self.clock = FrameClock(DEFAULT_FPS)
        self.ready = threading.Condition()
        self.pending: tuple[rospy.Time, np.ndarray] | None = None
        self.state_sub: rospy.Subscriber | None = None
        self.recount = True  # count the subscribers again (in spin's thread)
        self.frames = 0
        self.images = 0
        self.render_s = 0.0
        listener = _DemandListener(self)
        self.outlets = {side.name: _Outlets(side.namespace, listener) for side in SIDES}
        rospy.Subscriber(topics.SET_FPS, Float64, self.on_set_fps, queue_size=10)

    def demand_changed(self) -> None:
        """A subscriber came or went (rospy's thread): spin counts them again."""
        with self.ready:
            self.recount = True
            self.ready.notify()

    def update_demand(self) -> None:
        """Subscribes to the world state while any topic is heard; unsubscribes when none."""
        heard = any(outlets.heard() for outlets in self.outlets.values())
        with self.ready:
            self.recount = False
            if heard and self.state_sub is None:
                self.state_sub = rospy.Subscriber(topics.RENDER_STATE, JointState,
                                                  self.on_state, queue_size=1, tcp_nodelay=True)
            elif not heard and self.state_sub is not None:
                self.state_sub.unregister()
                self.state_sub = None
                self.pending = None

    def on_set_fps(self, msg: Float64) -> None:
        request = fps_request(msg.data)
        if request.line:
            (rospy.logwarn if request.warning else rospy.loginfo)(request.line)
        if request.fps is not None:
            with self.ready:
                self.clock.set_fps(request.fps)

    def on_state(self, msg: JointState) -> None:
        """Keeps the state when a frame is due (the latest such, if the renderer is busy)."""
        with self.ready:
            if self.clock.take(msg.header.stamp.to_nsec()):
                self.pending = (msg.header.stamp, np.asarray(msg.position))
                self.ready.notify()

    def spin(self) -> None:
        """Renders each due state until shutdown."""
        next_poll = time.monotonic()
        while not rospy.is_shutdown():
            if self.recount or time.monotonic() >= next_poll:
                self.update_demand()
                next_poll = time.monotonic() + DEMAND_POLL_S
            with self.ready:
                if self.pending is None and not self.recount:
                    self.ready.wait(0.1)
                job, self.pending = self.pending, None
            if job is not None:
                self.publish_frame(*job)

    def publish_frame(self, stamp: rospy.Time, qpos: np.ndarray) -> None:
        """The images and camera_infos of one state, for the sides someone listens to."""
        sides = [name for name, outlets in self.outlets.items() if outlets.wants_image()]
        start = time.perf_counter()
        images = self.renderer.render_sides(qpos, sides) if sides else {}
        self.render_s += time.perf_counter() - start
        self.frames += 1
        self.images += len(images)
        for name, outlets in self.outlets.items():
            image = images.get(name)
            if image is not None and outlets.image.get_num_connections():
                outlets.image.publish(_image_msg(image, stamp))
            if image is not None and outlets.compressed.get_num_connections():
                outlets.compressed.publish(_jpeg_msg(image, stamp))
            if outlets.info.get_num_connections():
                outlets.info.publish(camera_info(name, stamp))

    def summary(self) -> str:
        """One line: frames and images rendered, and the mean render time of an image."""
        mean_ms = 1e3 * self.render_s / self.images if self.images else 0.0
        return (f'multisense cameras: {self.frames} frames, {self.images} images rendered, '
                f'{mean_ms:.1f} ms per image')


def _image_msg(image: np.ndarray, stamp: rospy.Time) -> Image:
    msg = Image()
    msg.header.stamp = stamp
    msg.header.frame_id = OPTICAL_FRAME
    msg.height, msg.width = image.shape[:2]
    msg.encoding = 'rgb8'
    msg.step = msg.width * 3
    msg.data = image.tobytes()
    return msg


def _jpeg_msg(image: np.ndarray, stamp: rospy.Time) -> CompressedImage:
    """image_transport's compressed form of the image: a JPEG (PIL's encoder)."""
    from PIL import Image as PilImage  # noqa: PLC0415 - only when someone records images

    buffer = io.BytesIO()
    PilImage.fromarray(image).save(buffer, 'JPEG', quality=JPEG_QUALITY)
    msg = CompressedImage()
    msg.header.stamp = stamp
    msg.header.frame_id = OPTICAL_FRAME
    msg.format = JPEG_FORMAT
    msg.data = buffer.getvalue()
    return msg
