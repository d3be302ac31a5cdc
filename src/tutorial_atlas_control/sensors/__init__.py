"""The MultiSense SL head's sensors without ROS, placed on the simulated `head` body.

frames: the head's fixed frames as multisense_sl.urdf gives them (the laser's spindle and
frame, the stereo cameras, the head's IMU); spindle: `hokuyo_joint`, simulated beside the
model as DRCSim's plugin drove it (its PID, its limits); laser: the Hokuyo's scans by
MuJoCo's ray queries, with seeded noise (heightfield_march: where rays meet a
heightfield, cheaper than MuJoCo's test); head: their messages as wire bytes, for the
stepping loop and offline runs; height_map: the ground's heights from the laser's scans.
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'frames': ['CAMERA_FRAMES', 'HEAD_FRAMES', 'HEAD_HOKUYO_FRAME', 'HEAD_IMU', 'HEAD_IMU_FRAME',
               'HEAD_LINK', 'HOKUYO_AXIS', 'HOKUYO_FRAME', 'HOKUYO_JOINT', 'HOKUYO_LINK',
               'FixedFrame', 'frame_in_head', 'rpy_matrix', 'spindle_matrix'],
    'spindle': ['MAX_SPINDLE_SPEED', 'MIN_SPINDLE_SPEED', 'Spindle', 'SpindleCommand',
                'spindle_command'],
    'heightfield_march': ['BISECT_TOL_M', 'MARCH_STEP_M', 'TILE_CELLS', 'Heightfield'],
    'laser': ['COLLISION_GROUPS', 'HOKUYO', 'HokuyoLaser', 'LaserSpec'],
    'head': ['HeadSensors'],
    'height_map': ['GroundGrid', 'HeightMap', 'HeightMapSpec', 'ground_grid', 'scan_points'],
})
