#!/usr/bin/env python3
"""rostest: the port serves DRCSim 2.5.2's Atlas API lists (topic, type, publisher and
subscriber counts), as DRCSim's own ros_api_checker checked them against a running
`atlas.launch`.

The expected entries are written out below from DRCSim 2.5.2's atlas_rosapi.yaml and
atlas_cheats_rosapi.yaml (ANY: the lists' -1, any count). Out of scope: /drc_world/*,
/tf2_buffer_server/* and the multisense entries. Entries that other branches are adding
are in NOT_YET_SERVED: missing is fine, but once served they are checked like the rest
(and the test prints which could leave the set). As in DRCSim's strict check, a topic in the
graph that is in neither list nor PORT_OWN_TOPICS (nor the head's cameras') fails the test.

The test is a bare observer: it asks the master (rosgraph), and is no node of the graph.
"""

from __future__ import annotations

import time
import unittest
from typing import NamedTuple

import rosgraph
import rosservice
import rostest

PKG = 'tutorial_atlas_control'
#: A count the lists do not fix (their -1).
ANY = -1
#: How long (s, wall) the launch has to bring up every entry before the test judges.
WALL_TIMEOUT_S = 90.0
#: Once everything expected is up, this much longer (s) for late registrations to show.
SETTLE_S = 2.0


class Entry(NamedTuple):
    topic: str
    type: str
    publishers: int
    subscribers: int


#: DRCSim 2.5.2's lists, in scope.
DRCSIM_2_5_2 = (
    # atlas_rosapi.yaml: system
    Entry('/clock', 'rosgraph_msgs/Clock', 1, ANY),
    Entry('/rosout', 'rosgraph_msgs/Log', ANY, 1),
    Entry('/rosout_agg', 'rosgraph_msgs/Log', 1, ANY),
    # DRCSim: tf/tfMessage (the same definition and MD5 as tf2_msgs/TFMessage, which the
    # port's publishers use), one subscriber: /tf2_buffer_server, out of scope here.
    Entry('/tf', 'tf2_msgs/TFMessage', ANY, ANY),
    Entry('/tf_static', 'tf2_msgs/TFMessage', ANY, ANY),  # subscriber: the same server
    # atlas_rosapi.yaml: Atlas, published
    Entry('/atlas/controller_statistics', 'atlas_msgs/ControllerStatistics', 1, ANY),
    Entry('/atlas/force_torque_sensors', 'atlas_msgs/ForceTorqueSensors', 1, ANY),
    Entry('/atlas/imu', 'sensor_msgs/Imu', 1, ANY),
    Entry('/atlas/joint_states', 'sensor_msgs/JointState', 1, ANY),
    Entry('/atlas/atlas_state', 'atlas_msgs/AtlasState', 1, ANY),
    # atlas_rosapi.yaml: Atlas, subscribed
    Entry('/atlas/control_mode', 'std_msgs/String', ANY, 1),
    Entry('/atlas/joint_commands', 'osrf_msgs/JointCommands', ANY, 1),
    Entry('/atlas/atlas_command', 'atlas_msgs/AtlasCommand', ANY, 1),
    # atlas_cheats_rosapi.yaml: published
    Entry('/atlas/debug/l_foot_contact', 'geometry_msgs/WrenchStamped', 1, ANY),
    Entry('/atlas/debug/r_foot_contact', 'geometry_msgs/WrenchStamped', 1, ANY),
    Entry('/ground_truth_odom', 'nav_msgs/Odometry', 1, ANY),
    # atlas_cheats_rosapi.yaml: subscribed
    Entry('/atlas/cmd_vel', 'geometry_msgs/Twist', ANY, 1),
    Entry('/atlas/configuration', 'sensor_msgs/JointState', ANY, 1),
    Entry('/atlas/set_pose', 'geometry_msgs/Pose', ANY, 1),
    Entry('/joint_trajectory', 'trajectory_msgs/JointTrajectory', ANY, 1),
    Entry('/atlas/mode', 'std_msgs/String', ANY, 1),
    Entry('/atlas/debug/test', 'atlas_msgs/Test', ANY, 1),
    Entry('/atlas/apply_pelvis_force', 'geometry_msgs/Wrench', ANY, 1),
)

#: Beyond the 2.5.2 lists, from DRCSim's sources: AtlasPlugin 2.7.0's synchronization
#: topics (the publisher latched, the subscriber a cheat) and its AtlasSimInterface topics.
DRCSIM_2_7_0 = (
    Entry('/atlas/synchronization_statistics', 'atlas_msgs/SynchronizationStatistics', 1, ANY),
    Entry('/atlas/debug/sync_delay', 'std_msgs/String', ANY, 1),
    Entry('/atlas/atlas_sim_interface_state', 'atlas_msgs/AtlasSimInterfaceState', 1, ANY),
    Entry('/atlas/atlas_sim_interface_command', 'atlas_msgs/AtlasSimInterfaceCommand', ANY, 1),
)

#: Services (not in the yaml lists; AtlasPlugin 2.5.2 and DRCSim's gazebo_ros_api_plugin,
#: whose fork named reset_world `reset_models`): name -> type.
SERVICES = {
    '/atlas/reset_controls': 'atlas_msgs/ResetControls',
    '/gazebo/reset_models': 'std_srvs/Empty',
    '/gazebo/reset_simulation': 'std_srvs/Empty',
    '/gazebo/pause_physics': 'std_srvs/Empty',
    '/gazebo/unpause_physics': 'std_srvs/Empty',
}

#: Being added on other branches: absent is not (yet) a failure. Shrink this as
#: they merge; the test prints the entries that are served and could leave it.
NOT_YET_SERVED: frozenset[str] = frozenset()

#: The port's own topics, beside DRCSim's (docs/ros_interface.md): the per-step ankle wrenches, the
#: latched configuration and the applied cheats that offline replay reads, the mode now.
PORT_OWN_TOPICS = {
    '/atlas/l_foot_contact': 'geometry_msgs/WrenchStamped',
    '/atlas/r_foot_contact': 'geometry_msgs/WrenchStamped',
    '/atlas/sim_config': 'std_msgs/String',
    '/atlas/sim_inputs': 'std_msgs/String',
    '/atlas/current_control_mode': 'std_msgs/String',
    '/atlas/asi_state_recorded': 'atlas_msgs/AtlasSimInterfaceState',
    # The MultiSense SL head's laser, by DRCSim 2.7's names (not in the 2.5.2 lists).
    '/multisense_sl/laser/scan': 'sensor_msgs/LaserScan',
    '/multisense_sl/joint_states': 'sensor_msgs/JointState',
    '/multisense_sl/imu': 'sensor_msgs/Imu',
    '/multisense_sl/set_spindle_speed': 'std_msgs/Float64',
    '/atlas/render_state': 'sensor_msgs/JointState',
}
#: The multisense_sl head's stereo pair (docs/cameras.md), named as DRCSim's plugin named it
#: (its lists left the head out); image_raw/compressed is the port's JPEG beside each image.
MULTISENSE_CAMERA_TOPICS = {
    **{f'/multisense_sl/camera/{side}/{name}': msgtype for side in ('left', 'right')
       for name, msgtype in (('image_raw', 'sensor_msgs/Image'),
                             ('image_raw/compressed', 'sensor_msgs/CompressedImage'),
                             ('camera_info', 'sensor_msgs/CameraInfo'))},
    '/multisense_sl/set_fps': 'std_msgs/Float64',
}

EXPECTED = DRCSIM_2_5_2 + DRCSIM_2_7_0


class Graph(NamedTuple):
    """What the master knows: topic -> type, publishers and subscribers (node names); the
    services."""

    types: dict[str, str]
    publishers: dict[str, list[str]]
    subscribers: dict[str, list[str]]
    services: set[str]


def observe(master: rosgraph.Master) -> Graph:
    publishers, subscribers, services = master.getSystemState()
    return Graph(dict(master.getTopicTypes()), dict(publishers), dict(subscribers),
                 {name for name, _ in services})


def problems(graph: Graph) -> list[str]:
    """Every way the graph differs from EXPECTED and SERVICES (NOT_YET_SERVED may be
    missing), and the topics it has beyond them and PORT_OWN_TOPICS."""
    found = []
    for entry in EXPECTED:
        topic = entry.topic
        if topic not in graph.types:
            if topic not in NOT_YET_SERVED:
                found.append(f'{topic}: missing')
            continue
        if graph.types[topic] != entry.type:
            found.append(f'{topic}: type {graph.types[topic]}, expected {entry.type}')
        for what, expected, nodes in (
                ('publishers', entry.publishers, graph.publishers.get(topic, [])),
                ('subscribers', entry.subscribers, graph.subscribers.get(topic, []))):
            if expected != ANY and len(nodes) != expected:
                found.append(f'{topic}: {len(nodes)} {what} ({", ".join(nodes) or "none"}), '
                             f'expected {expected}')
    own = {**PORT_OWN_TOPICS, **MULTISENSE_CAMERA_TOPICS}
    for topic, msgtype in own.items():
        if graph.types.get(topic) != msgtype:
            found.append(f'{topic}: type {graph.types.get(topic)}, expected {msgtype}')
    known = {entry.topic for entry in EXPECTED} | set(own)
    found += [f'{topic}: not in the API lists (type {graph.types[topic]})'
              for topic in sorted(set(graph.types) - known)]
    for name, srv_type in SERVICES.items():
        if name not in graph.services:
            if name not in NOT_YET_SERVED:
                found.append(f'{name}: service missing')
        elif rosservice.get_service_type(name) != srv_type:
            found.append(f'{name}: service type {rosservice.get_service_type(name)}, '
                         f'expected {srv_type}')
    return found


class ApiListsTest(unittest.TestCase):
    def test_the_drcsim_2_5_2_api_lists(self) -> None:
        master = rosgraph.Master('/test_api_lists')
        deadline = time.monotonic() + WALL_TIMEOUT_S
        while problems(observe(master)) and time.monotonic() < deadline:
            time.sleep(0.5)
        time.sleep(SETTLE_S)
        graph = observe(master)
        found = problems(graph)
        served = sorted(name for name in NOT_YET_SERVED
                        if name in graph.types or name in graph.services)
        if served:
            print(f'served now, can leave NOT_YET_SERVED: {", ".join(served)}')
        self.assertEqual(found, [], '\n' + '\n'.join(found))


if __name__ == '__main__':
    rostest.rosrun(PKG, 'api_lists', ApiListsTest)
