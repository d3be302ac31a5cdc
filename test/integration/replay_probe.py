#!/usr/bin/env python3
"""test_replay_live.py's ROS side, in its own process: waits for the fresh simulator to stand
free, plays the bag's mode switch and commands with `rosbag play`, watches for the fall, and
prints one JSON line: the pelvis height before, the sim times the commands arrived at, the
lowest pelvis height, and rosbag play's outcome (or `error`).

`rosbag play --wait-for-subscribers` starts once each topic has one subscriber: the
simulator could be connected and this probe not yet, which would miss the first commands.
So the player starts paused, and is resumed (its `pause_playback` service) once its
getBusInfo lists a connection to every subscriber the master knows for each played topic.
The player is kept alive past the bag's end (`--keep-alive`) until every command in the bag
(`--commands`) has been read here, then stopped with SIGINT: rosbag play calls ros::shutdown
right after its last publish, which would drop whatever its outgoing queue still held for a
slow reader, and the wait runs from the resume with the whole `--timeout`, not from the
player's exit.

Its own process so that the test's pytest process never holds a rospy node (init_node is
once per process) nor a ROS_MASTER_URI of its own: later tests do not depend on it.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable

import rospy
from nav_msgs.msg import Odometry
from osrf_msgs.msg import JointCommands
from rosgraph_msgs.msg import Clock
from std_srvs.srv import SetBool

from tutorial_atlas_control import processes

PLAYED_TOPICS = ('/atlas/control_mode', '/atlas/joint_commands')
#: rosbag play's node name: `play` made anonymous (`/play_<stamp>`), whatever __name says.
PLAYER_PREFIX = '/play_'
#: rosbag play's outgoing queue per topic (messages): more than a tutorial bag holds.
PLAYER_QUEUE = 10000
#: Wall s rosbag play gets to stop (SIGINT) once every command has arrived.
STOP_TIMEOUT_S = 30.0


class Probe:
    """Sim time, pelvis height, arrival of played commands."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.clock_s = 0.0
        self.min_z_m = float('inf')
        self.z_m: float | None = None
        self.command_arrivals_s: list[float] = []
        rospy.Subscriber('/clock', Clock, self._on_clock, queue_size=10)
        rospy.Subscriber('/ground_truth_odom', Odometry, self._on_odom, queue_size=10)
        # Unbounded: with 100, a probe starved on a loaded host (its /clock and odometry
        # callbacks at 1 kHz each) dropped played commands from its own queue.
        rospy.Subscriber('/atlas/joint_commands', JointCommands, self._on_command,
                         queue_size=None)

    def _on_clock(self, msg: Clock) -> None:
        with self.lock:
            self.clock_s = msg.clock.to_sec()

    def _on_odom(self, msg: Odometry) -> None:
        with self.lock:
            self.z_m = msg.pose.pose.position.z
            self.min_z_m = min(self.min_z_m, self.z_m)

    def _on_command(self, _msg: JointCommands) -> None:
        with self.lock:
            self.command_arrivals_s.append(self.clock_s)

    def wait_for(self, condition, timeout_s: float, what: str,
                 check: Callable[[], None] | None = None) -> None:
        deadline = time.monotonic() + timeout_s
        while True:
            if check is not None:
                check()
            with self.lock:
                if condition(self):
                    return
            if time.monotonic() > deadline:
                raise TimeoutError(f'{what}: not reached within {timeout_s:g} s')
            time.sleep(0.01)


def connected_player(master_uri: str, caller: str) -> str | None:
    """rosbag play's node name once it is connected to every subscriber of every played
    topic (the master's lists against the player's getBusInfo); None until then."""
    try:
        publishers, subscribers = processes.system_state(master_uri)
        players = {node for topic in PLAYED_TOPICS for node in publishers.get(topic, [])
                   if node.startswith(PLAYER_PREFIX)}
        if len(players) != 1:
            return None
        player = players.pop()
        code, _, bus = processes.node_api(master_uri, player, caller).getBusInfo(caller)
    except OSError:
        return None
    if code != 1:
        return None
    for topic in PLAYED_TOPICS:
        readers = set(subscribers.get(topic, []))
        connected = {row[1] for row in bus if row[2] == 'o' and row[4] == topic}
        if not readers or not readers <= connected:
            return None
    return player


def play(bag: str, probe: Probe, commands: int,
         timeout_s: float) -> subprocess.CompletedProcess:
    """`rosbag play --pause --keep-alive` of the played topics, resumed once every subscriber
    is connected, stopped once `commands` joint commands have arrived at `probe`.

    Raises TimeoutError if the player is not connected, or the commands have not all
    arrived, within `timeout_s` each.
    """
    player = subprocess.Popen(
        # --queue beyond the bag's commands: a slow reader backs the player up, never
        # makes it drop (its default queue is 100).
        ['rosbag', 'play', '--quiet', '--pause', '--keep-alive', f'--queue={PLAYER_QUEUE}',
         bag, '--topics', *PLAYED_TOPICS],
        stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        def player_ended() -> None:
            if player.poll() is not None:
                raise TimeoutError(f'rosbag play ended early, exit status {player.returncode}')

        found: list[str] = []

        def connected() -> bool:
            name = connected_player(os.environ['ROS_MASTER_URI'], rospy.get_name())
            if name is not None:
                found.append(name)
            return name is not None

        processes.wait_until(connected, timeout_s, 'rosbag play was not connected',
                             check=player_ended)
        name = found[0]
        rospy.wait_for_service(f'{name}/pause_playback', timeout=timeout_s)
        resumed = rospy.ServiceProxy(f'{name}/pause_playback', SetBool)(False)
        if not resumed.success:
            raise TimeoutError(f'rosbag play did not resume: {resumed.message}')
        probe.wait_for(lambda p: len(p.command_arrivals_s) >= commands, timeout_s,
                       f'all {commands} played commands to arrive', check=player_ended)
        player.send_signal(signal.SIGINT)
        output, _ = player.communicate(timeout=STOP_TIMEOUT_S)
    except subprocess.TimeoutExpired as err:
        raise TimeoutError(f'rosbag play did not stop within {STOP_TIMEOUT_S:g} s') from err
    except (rospy.ROSException, processes.ProcessError) as err:
        raise TimeoutError(str(err)) from err
    finally:
        if player.poll() is None:
            player.kill()
            player.wait()
    return subprocess.CompletedProcess(player.args, player.returncode, output, '')


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument('bag')
    parser.add_argument('--play-at', type=float, required=True, help='sim s to start playing')
    parser.add_argument('--fallen-below', type=float, required=True, help='m')
    parser.add_argument('--fall-window', type=float, required=True,
                        help='sim s watched after the last played command')
    parser.add_argument('--timeout', type=float, required=True, help='wall s per wait')
    parser.add_argument('--commands', type=int, required=True,
                        help='joint commands in the bag: waited for after playing')
    args = parser.parse_args()
    rospy.init_node('replay_live_probe', anonymous=True)
    probe = Probe()
    result: dict[str, object] = {}
    try:
        probe.wait_for(lambda p: p.clock_s >= args.play_at and p.z_m is not None,
                       args.timeout, 'simulator start')
        result['z_before_m'] = probe.z_m
        played = play(args.bag, probe, args.commands, args.timeout)
        result['play_returncode'] = played.returncode
        result['play_output'] = played.stdout
        with probe.lock:
            played_until_s = probe.clock_s
        probe.wait_for(lambda p: p.min_z_m < args.fallen_below
                       or p.clock_s > played_until_s + args.fall_window,
                       args.timeout, 'fall watch')
    except TimeoutError as err:
        result['error'] = str(err)
    with probe.lock:
        result['arrivals_s'] = list(probe.command_arrivals_s)
        result['min_z_m'] = probe.min_z_m
    print(json.dumps(result), flush=True)
    rospy.signal_shutdown('done')
    return 0


if __name__ == '__main__':
    sys.exit(main())
