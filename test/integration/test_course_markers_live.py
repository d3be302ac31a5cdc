"""course_markers.py on a private master: a client that starts after it gets the VRC course's
markers, latched, once (the terrain's mesh and the 24 static boxes, in `world`)."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

pytest.importorskip('visualization_msgs.msg', reason='needs ROS: source ./env.sh')

from support.vrc_world import WORLD_PATH
from tutorial_atlas_control.processes import RosMaster, stop_tree, system_state, wait_until
from tutorial_atlas_control.topics import COURSE_MARKERS_TOPIC

SCRIPT = Path(__file__).resolve().parents[2] / 'scripts' / 'course_markers.py'
#: Wall seconds for the node to load the course and advertise (a loaded 2-core machine).
ADVERTISE_TIMEOUT_S = 60.0
#: The terrain's one mesh, then 5 gates of 3 boxes, the pen's 8 walls, the mud.
EXPECTED_MARKERS = 1 + 5 * 3 + 8 + 1

#: A late subscriber: the latched array, summarized on one line.
CLIENT = textwrap.dedent(f'''
    import rospy
    from visualization_msgs.msg import Marker, MarkerArray
    rospy.init_node('course_markers_probe')
    array = rospy.wait_for_message({COURSE_MARKERS_TOPIC!r}, MarkerArray, timeout=60)
    meshes = [m for m in array.markers if m.type == Marker.TRIANGLE_LIST]
    cubes = [m for m in array.markers if m.type == Marker.CUBE]
    frames = sorted({{m.header.frame_id for m in array.markers}})
    print(len(array.markers), len(meshes), len(cubes), len(meshes[0].points) // 3, *frames)
''')


def test_a_late_client_gets_the_latched_course(tmp_path: Path) -> None:
    with RosMaster(tmp_path / 'roscore.log', tmp_path / 'ros_log') as master:
        master.wait_online()
        log = open(tmp_path / 'course_markers.log', 'w')  # noqa: SIM115 - closed below
        node = subprocess.Popen([sys.executable, str(SCRIPT), str(WORLD_PATH)], env=master.env,
                                stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
        try:
            wait_until(lambda: COURSE_MARKERS_TOPIC in dict(system_state(master.uri)[0]),
                       ADVERTISE_TIMEOUT_S, 'course_markers.py did not advertise')
            result = subprocess.run([sys.executable, '-c', CLIENT], env=master.env,
                                    capture_output=True, text=True, timeout=120)
        finally:
            stop_tree(node)
            log.close()
    assert result.returncode == 0, result.stderr
    markers, meshes, cubes, triangles, *frames = result.stdout.split()
    print(f'{markers} markers: {meshes} mesh of {triangles} triangles, {cubes} cubes')
    assert (int(markers), int(meshes), int(cubes)) == (EXPECTED_MARKERS, 1, EXPECTED_MARKERS - 1)
    assert 0 < int(triangles) <= 20_000
    assert frames == ['world']
    assert node.returncode is not None
