"""course_markers.py's ROS side without a master: the shapes as one MarkerArray in the frame
`world` (a TRIANGLE_LIST for the terrain, a CUBE per box, their figures carried over), and a
model file it cannot load refused in one line, exit status 1."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

pytest.importorskip('visualization_msgs.msg', reason='needs ROS: source ./env.sh')

from visualization_msgs.msg import Marker

from support.vrc_world import WORLD_PATH
from tutorial_atlas_control.cli.course_markers import main
from tutorial_atlas_control.course import course_shapes, markers_node

#: The VRC world's static boxes: 5 gates of 3, the pen's 8 walls, the mud volume.
COURSE_BOXES = 5 * 3 + 8 + 1


def test_the_shapes_become_one_marker_array_in_the_world_frame() -> None:
    shapes = course_shapes(mujoco.MjModel.from_xml_path(str(WORLD_PATH)))
    array = markers_node.marker_array(shapes)
    terrain, *boxes = array.markers
    assert {marker.header.frame_id for marker in array.markers} == {'world'}
    assert terrain.type == Marker.TRIANGLE_LIST
    (mesh,) = shapes.terrains
    assert len(terrain.points) == len(terrain.colors) == 3 * len(mesh.triangles)
    last = terrain.points[-1]
    assert np.allclose([last.x, last.y, last.z], mesh.triangles[-1, 2])
    assert len(boxes) == COURSE_BOXES and {box.type for box in boxes} == {Marker.CUBE}
    assert len({(marker.ns, marker.id) for marker in array.markers}) == len(array.markers)
    assert {marker.ns for marker in boxes} == {'gate', 'pen', 'mud'}
    (mud,) = [marker for marker in boxes if marker.ns == 'mud']
    assert not any(marker.text for marker in array.markers)  # rviz warns of unused text
    assert (mud.pose.position.x, mud.pose.position.y, mud.pose.position.z) == (0.5, -16.6, -0.38)
    assert (mud.scale.x, mud.scale.y, mud.scale.z) == (8.0, 10.0, 0.5)
    assert mud.color.a == pytest.approx(0.4)


def test_a_model_it_cannot_load_is_one_line_and_exit_1(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    missing = tmp_path / 'no_such_course.xml'
    assert main(['course_markers.py', str(missing), '__name:=course_markers']) == 1
    err = capsys.readouterr().err.strip()
    assert err.startswith(f'course_markers.py: error: {missing}: ')
    assert len(err.splitlines()) == 1 and 'Traceback' not in err


def test_no_model_prints_the_usage_and_exit_1(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(['course_markers.py']) == 1
    assert 'usage: course_markers.py MODEL_FILE' in capsys.readouterr().err
