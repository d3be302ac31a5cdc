"""The ROS master killed and restarted under a running atlas.launch.

The master runs apart from the launch (as `roscore` in a terminal of its own). It is
killed (SIGKILL) mid-run: the simulator says so in one line and goes on stepping, and the
recorder goes on recording, over the connections already made. A new roscore on the same
port: the simulator registers again its publications, subscriptions and services and sets
again the launch's parameters (one line), so that new clients find it; the recorder
(roscpp) is not registered again, but its recording never stopped.
"""

from __future__ import annotations

import os
import signal
import time
import xmlrpc.client
from pathlib import Path

import pytest

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

from support.bag_checks import missing_steps
from support.launch import TestLaunch
from tutorial_atlas_control import processes
from tutorial_atlas_control.bags.reader import read_bag

#: Wall seconds the master stays away (the simulation runs on meanwhile).
AWAY_S = 4.0
LINE_TIMEOUT_S = 60.0


class RoscoreOnPort(processes.RosMaster):
    """`roscore -p PORT` on a given port: the same URI again after a restart."""

    def __init__(self, log_path: Path, port: int, ros_log_dir: Path) -> None:
        self.port = port
        env = processes.ros_environment(port, ros_log_dir)
        processes._RosProcess.__init__(self, ['roscore', '-p', str(port)], env, log_path)


def test_master_killed_and_restarted(tmp_path: Path) -> None:
    port = processes.free_local_port()
    uri = f'http://localhost:{port}'
    first = RoscoreOnPort(tmp_path / 'roscore_1.log', port, tmp_path / 'ros_log')
    second = None
    try:
        first.wait_online()
        with TestLaunch(tmp_path, master=first) as launch:
            launch.wait_ready()
            launch.wait_sim_s(2.0)
            before_s = launch.sim_time_s()
            rosmaster = first.pid_of('rosmaster')
            assert rosmaster is not None
            os.kill(rosmaster, signal.SIGKILL)
            first.close()
            gone = ('the ROS master at ' + uri + ' went away: the simulation goes on over the '
                    'connections already made; new clients cannot find this node until a '
                    f'master is back at {uri}')
            launch.wait(lambda: gone in launch.output(), LINE_TIMEOUT_S, 'no line on the master')
            time.sleep(AWAY_S)  # the simulator and the recorder carry on meanwhile
            launch.check_running()
            second = RoscoreOnPort(tmp_path / 'roscore_2.log', port, tmp_path / 'ros_log')
            second.wait_online()
            back = f'a ROS master is back at {uri}: registered again '
            launch.wait(lambda: back in launch.output(), LINE_TIMEOUT_S, 'not registered again')
            line = next(text for text in launch.output().splitlines() if back in text)

            publishers, subscribers = processes.system_state(uri)
            assert '/atlas_sim' in publishers['/atlas/joint_states']
            assert '/atlas_sim' in subscribers['/atlas/joint_commands']
            assert '/recorder' not in subscribers.get('/atlas/joint_states', []), \
                'roscpp nodes do not register again (docs/troubleshooting.md)'
            master = xmlrpc.client.ServerProxy(uri)
            code, _, _ = master.lookupService('/test', '/gazebo/reset_simulation')
            assert code == 1, 'the services are found again'
            assert master.getParam('/test', '/use_sim_time')[2] is True
            assert master.getParam('/test', '/atlas/time_to_unpin')[2] == 1.0
            assert master.getParam('/test', '/atlas_controller/gains/l_arm_elx/p')[0] == 1
            launch.close_talker()  # the next reads and writes come from a new client
            after_s = launch.sim_time_s()
            assert after_s > before_s
            launch.set_mode('User')  # a new publisher reaches the simulator's subscription
            launch.wait(lambda: 'control mode: Stand -> User' in launch.output(),
                        LINE_TIMEOUT_S, 'the mode did not reach the simulator')
            launch.wait_sim_s(1.0)
            launch.interrupt()
            states = read_bag(launch.bag()).joint_states
        assert states is not None and missing_steps(states) == 0, 'recorded through it all'
        assert states.t_s[0] < before_s and states.t_s[-1] > after_s
        print(f'figures: master killed at sim ~{before_s:.1f} s, back after {AWAY_S:.0f} s '
              f'wall; {line.split(": ", 2)[-1]}; bag {states.t_s[0]:.3f}-{states.t_s[-1]:.2f} s, '
              'no step missing')
    finally:
        first.close()
        if second is not None:
            second.close()
