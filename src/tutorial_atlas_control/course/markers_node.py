"""Publish the VRC course's static shapes for rviz, once, latched (vrc_task_2.launch).

usage: course_markers.py MODEL_FILE [ROS arguments]

Loads MODEL_FILE (the launch's `model`), builds its shapes (course/markers.py: the terrain
as a height-coloured triangle mesh over the walked area, the gates, the pen's walls and
floor, the translucent mud volume) and publishes them as one visualization_msgs/MarkerArray
on /vrc_course/markers in the frame `world` (the simulator's /tf root), latched: rviz gets
them whenever it starts. Then it waits until shut down. rviz's MarkerArray display on that
topic shows them (rviz/vrc_task_2.rviz; `roslaunch tutorial_atlas_control rviz.launch
course:=true`).
"""

from __future__ import annotations

import numpy as np
import rospy
from geometry_msgs.msg import Point
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

from tutorial_atlas_control.course.markers import BoxShape, CourseShapes, TerrainMesh
from tutorial_atlas_control.topics import COURSE_MARKERS_TOPIC, WORLD_FRAME

#: The terrains' namespace in rviz's display; a box's is its name's first word (`gate`,
#: `pen`, `mud`), so that the display's Namespaces turn each kind on and off.
TERRAIN_NAMESPACE = 'terrain'


def _point(xyz: np.ndarray) -> Point:
    return Point(float(xyz[0]), float(xyz[1]), float(xyz[2]))


def _colour(rgba: np.ndarray) -> ColorRGBA:
    return ColorRGBA(*(float(value) for value in rgba))


def _marker(namespace: str, marker_id: int, marker_type: int) -> Marker:
    marker = Marker()
    marker.header.frame_id = WORLD_FRAME
    marker.ns, marker.id, marker.type = namespace, marker_id, marker_type
    marker.action = Marker.ADD
    marker.pose.orientation.w = 1.0
    return marker


def terrain_marker(mesh: TerrainMesh, marker_id: int) -> Marker:
    """A TRIANGLE_LIST marker of the mesh, coloured per corner (scale 1: points in metres)."""
    marker = _marker(TERRAIN_NAMESPACE, marker_id, Marker.TRIANGLE_LIST)
    marker.scale.x = marker.scale.y = marker.scale.z = 1.0
    marker.color.r = marker.color.g = marker.color.b = marker.color.a = 1.0
    marker.points = [_point(xyz) for xyz in mesh.triangles.reshape(-1, 3)]
    marker.colors = [_colour(rgba) for rgba in mesh.colours.reshape(-1, 4)]
    return marker


def box_marker(box: BoxShape, marker_id: int) -> Marker:
    """A CUBE marker of the box: its pose, full size and colour (no text: rviz warns of
    text on a marker that does not show it)."""
    marker = _marker(box.name.split('_')[0], marker_id, Marker.CUBE)
    position, orientation = marker.pose.position, marker.pose.orientation
    position.x, position.y, position.z = (float(v) for v in box.centre)
    orientation.w, orientation.x, orientation.y, orientation.z = (float(v) for v in box.quat)
    marker.scale.x, marker.scale.y, marker.scale.z = (float(v) for v in box.size)
    marker.color = _colour(box.rgba)
    return marker


def marker_array(shapes: CourseShapes) -> MarkerArray:
    """The MarkerArray of all the shapes: terrains first, then the boxes."""
    markers = [terrain_marker(mesh, index) for index, mesh in enumerate(shapes.terrains)]
    markers += [box_marker(box, index) for index, box in enumerate(shapes.boxes)]
    return MarkerArray(markers=markers)


def publish_and_wait(shapes: CourseShapes, node_name: str = 'course_markers') -> None:
    """Publish the shapes once, latched, then keep the node up until shut down."""
    rospy.init_node(node_name)
    publisher = rospy.Publisher(COURSE_MARKERS_TOPIC, MarkerArray, queue_size=1, latch=True)
    array = marker_array(shapes)
    publisher.publish(array)
    triangles = sum(len(mesh.triangles) for mesh in shapes.terrains)
    rospy.loginfo(f'{len(array.markers)} course markers on {COURSE_MARKERS_TOPIC} '
                  f'({triangles} terrain triangles, {len(shapes.boxes)} boxes)')
    rospy.spin()
