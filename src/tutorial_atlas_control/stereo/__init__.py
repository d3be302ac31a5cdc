"""The multisense_sl head's stereo cameras: their numbers, frame rate and rendering.

ROS-free but for camera_node.py, the rendering node's ROS side (imported by its module).
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'frame_rate': ['FpsRequest', 'FrameClock', 'MAX_FPS', 'MIN_FPS', 'fps_request'],
    'head_cameras': ['CAMERA_PREFIX', 'ImageNoise', 'StereoRenderer', 'camera_model'],
    'multisense': ['BASELINE_M', 'DEFAULT_FPS', 'HFOV_RAD', 'OPTICAL_FRAME', 'SIDES',
                   'CameraSide', 'Intrinsics', 'intrinsics'],
})
