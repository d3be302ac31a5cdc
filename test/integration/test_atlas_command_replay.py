"""A recorded run driven by /atlas/atlas_command replays offline bit for bit.

atlas.launch records (record:=true); a rospy publisher in a subprocess sends, in Stand mode,
AtlasCommands that hand l_arm_elx to a sine (k_effort 255 there, 0 elsewhere: blended with
the Stand hold), then switches to User and makes l_arm_shx limp (k_effort 0). The bag must
hold every AtlasCommand sent, and replay_bag must reproduce the run with 0.0 deviation.

Run with `python3 -m pytest test/integration/test_atlas_command_replay.py -q` after
`source env.sh`. Wall time about 40 s.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from support.launch import TestLaunch

pytest.importorskip('atlas_msgs.msg', reason='atlas_msgs is not built (source env.sh)')
if shutil.which('roslaunch') is None:
    pytest.skip('roslaunch is not on PATH (source env.sh)', allow_module_level=True)

from tutorial_atlas_control import topics
from tutorial_atlas_control.bags.reader import read_bag
from tutorial_atlas_control.offline.replay import replay_bag

#: The commands: 100 Hz, 1.5 s blended in Stand, then 1.5 s in User (steps of sim time).
PUBLISHER = r'''
import math, sys
import rospy
from atlas_msgs.msg import AtlasCommand
from rosgraph_msgs.msg import Clock
from std_msgs.msg import String

rospy.init_node('atlas_command_sender', disable_signals=True)
gains = rospy.get_param('atlas_controller/gains')
names = rospy.wait_for_message('/atlas/joint_states', __import__(
    'sensor_msgs.msg', fromlist=['JointState']).JointState, timeout=60).name
pub = rospy.Publisher('/atlas/atlas_command', AtlasCommand, queue_size=100)
mode = rospy.Publisher('/atlas/control_mode', String, queue_size=1, latch=True)
rospy.sleep(0.5)
elx, shx = names.index('l_arm_elx'), names.index('l_arm_shx')
command = AtlasCommand()
command.position = [0.0] * 28
command.velocity = [0.0] * 28
command.effort = [0.0] * 28
command.kp_position = [gains[n]['p'] for n in names]
command.ki_position = [gains[n]['i'] for n in names]
command.kd_position = [gains[n]['d'] for n in names]
command.kp_velocity = [0.0] * 28
command.i_effort_min = [-gains[n]['i_clamp'] for n in names]
command.i_effort_max = [gains[n]['i_clamp'] for n in names]
sent = 0
rate = rospy.Rate(100)
start = rospy.Time.now()
while (rospy.Time.now() - start).to_sec() < 3.0:
    t = (rospy.Time.now() - start).to_sec()
    user = t >= 1.5
    if user and sent and not getattr(mode, 'switched', False):
        mode.publish(String(data='User'))
        mode.switched = True
    command.header.stamp = rospy.Time.now()
    command.position[elx] = 0.4 * (1.0 - math.cos(2.0 * math.pi * t / 2.0))
    if user:
        command.k_effort = bytes(0 if k == shx else 255 for k in range(28))
    else:
        command.k_effort = bytes(255 if k == elx else 0 for k in range(28))
    pub.publish(command)
    sent += 1
    rate.sleep()
rospy.sleep(0.5)
print(sent)
'''


def test_an_atlas_command_run_replays_exactly(tmp_path: Path) -> None:
    with TestLaunch(tmp_path, 'record:=true', 'real_time_factor:=1.0') as launch:
        launch.wait_ready()
        launch.wait_sim_until(1.2)  # the torso is released at 1 s
        sender = subprocess.run([sys.executable, '-c', PUBLISHER], env=launch.env,
                                capture_output=True, text=True, timeout=120, check=False)
        assert sender.returncode == 0, sender.stderr
        sent = int(sender.stdout.split()[-1])
        launch.interrupt()
        bag = launch.bag()
    data = read_bag(bag)
    recorded = data.topics[topics.ATLAS_COMMAND]
    assert recorded.msgtype == 'atlas_msgs/AtlasCommand'
    assert recorded.count == sent > 250
    result = replay_bag(bag)
    assert result.reproduced, result.warnings
    assert result.joint_position.max_abs == 0.0
    assert result.pelvis_position is not None and result.pelvis_position.max_abs == 0.0
    # the run did what the commands asked: the elbow swung, the shoulder fell limp
    efforts = data.joint_states.effort
    names = list(data.joint_states.names)
    assert np.count_nonzero(efforts[:, names.index('l_arm_shx')] == 0.0) > 1000
    positions = data.joint_states.position[:, names.index('l_arm_elx')]
    assert positions.max() - positions.min() > 0.5
