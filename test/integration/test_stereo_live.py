"""The head's stereo pair live, through Debian's stereo_image_proc: from the rendered left
and right images and their camera_info it makes a disparity image and points2, and the
cloud's floor lies where the simulator says the floor is (the plane's distance from the
left camera is that camera's height); with record_images:=true the bag holds the images as
JPEGs, 800 x 800.

Run with `python3 -m pytest test/integration/test_stereo_live.py -q -s` after
`source env.sh` (needs roslaunch, stereo_image_proc and the workspace's messages).
"""

from __future__ import annotations

import io
import json
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

pytest.importorskip('stereo_msgs.msg', reason='needs python3-stereo-msgs: make setup')
pytest.importorskip('atlas_msgs.msg', reason='needs the catkin workspace: source ./env.sh')
if shutil.which('roslaunch') is None:
    pytest.skip('roslaunch is not on PATH (source env.sh)', allow_module_level=True)

from support.launch import TestLaunch
from tutorial_atlas_control import processes, topics
from tutorial_atlas_control.sim import MODEL_PATH

STEREO_IMAGE_PROC = Path('/usr/lib/stereo_image_proc/stereo_image_proc')
#: The floor's distance from the left camera against the camera's height (m): stereo at
#: 2-6 m resolves depth to a few cm per point; the plane is fitted over thousands.
FLOOR_TOLERANCE_M = 0.05

#: Waits for a disparity image and an organized cloud, fits a plane to the cloud's points
#: below the optical axis (the floor) and prints what the test judges, with the left
#: camera's height computed from the world state the simulator sent at the cloud's stamp.
PROBE = textwrap.dedent(f'''
    import json, numpy as np, rospy
    from sensor_msgs.msg import JointState, PointCloud2
    from stereo_msgs.msg import DisparityImage
    from tutorial_atlas_control.stereo import StereoRenderer, camera_model
    rospy.init_node('stereo_probe')
    states = {{}}
    rospy.Subscriber({topics.RENDER_STATE!r}, JointState,
                     lambda m: states.__setitem__(m.header.stamp.to_nsec(), m.position))
    ns = {topics.CAMERA_NAMESPACE!r}
    disparity = rospy.wait_for_message(ns + '/disparity', DisparityImage, timeout=45)
    cloud = rospy.wait_for_message(ns + '/points2', PointCloud2, timeout=45)
    rows = np.frombuffer(cloud.data, np.float32).reshape(-1, cloud.point_step // 4)[:, :3]
    points = rows[np.isfinite(rows).all(axis=1)]
    floor = points[(points[:, 1] > 0.2) & (points[:, 2] < 8.0)]
    centre = floor.mean(axis=0)
    normal = np.linalg.svd(floor - centre, full_matrices=False)[2][2]
    model = camera_model({str(MODEL_PATH)!r})
    renderer = StereoRenderer(model)
    stamp = cloud.header.stamp.to_nsec()
    renderer.set_state(np.asarray(states[stamp]))
    height = renderer.data.cam_xpos[model.camera('multisense_left').id][2]
    renderer.close()
    print(json.dumps({{'disparity_frame': disparity.header.frame_id,
        'valid': float(np.isfinite(rows).all(axis=1).mean()), 'floor_points': len(floor),
        'floor_distance': float(abs(normal @ centre)), 'camera_height': float(height),
        'frame': cloud.header.frame_id, 'width': cloud.width, 'height': cloud.height}}))
''')


def test_stereo_image_proc_sees_the_floor_where_it_is(tmp_path: Path) -> None:
    assert STEREO_IMAGE_PROC.exists(), 'install ros-stereo-image-proc: make setup'
    with TestLaunch(tmp_path, 'record_images:=true') as launch:
        launch.wait_ready()
        log = open(tmp_path / 'stereo_image_proc.log', 'w')  # noqa: SIM115 - closed below
        stereo = subprocess.Popen([str(STEREO_IMAGE_PROC), f'__ns:={topics.CAMERA_NAMESPACE}'],
                                  env=launch.env, stdout=log, stderr=subprocess.STDOUT,
                                  start_new_session=True)
        try:
            probe = launch.run(sys.executable, '-c', PROBE, timeout_s=100.0)
        finally:
            processes.stop_tree(stereo)
            log.close()
        launch.interrupt()
    assert probe.returncode == 0, (probe.stderr, launch.tail(),
                                   (tmp_path / 'stereo_image_proc.log').read_text())
    figures = json.loads(next(line for line in probe.stdout.splitlines() if line[:1] == '{'))
    print('figures:', figures)
    assert figures['frame'] == figures['disparity_frame'] == 'left_camera_optical_frame'
    assert (figures['width'], figures['height']) == (800, 800)
    assert figures['floor_points'] > 10_000
    assert figures['floor_distance'] == pytest.approx(figures['camera_height'],
                                                      abs=FLOOR_TOLERANCE_M)
    assert_images_recorded(launch.bag())


def assert_images_recorded(bag_path: Path) -> None:
    """Both sides' JPEGs and camera_info in the bag, no raw image."""
    import rosbag
    from PIL import Image

    with rosbag.Bag(str(bag_path)) as bag:
        counts = {name: info.message_count
                  for name, info in bag.get_type_and_topic_info().topics.items()}
        _, message, _ = next(bag.read_messages(
            topics=[f'{topics.CAMERA_NAMESPACE}/left/image_raw/compressed']))
    print('recorded:', {name: count for name, count in counts.items() if 'multisense' in name})
    for name in topics.IMAGE_RECORDED_TOPICS:
        assert counts.get(name, 0) > 0, name
    assert not any(name.endswith('image_raw') for name in counts)
    assert Image.open(io.BytesIO(message.data)).size == (800, 800)
