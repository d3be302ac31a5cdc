#!/usr/bin/env python3
"""Floods /atlas/joint_commands from outside; prints one JSON line of figures.

    flood_commands.py --kind valid|bad --rate HZ --duration S [--start-sim S]
                      [--subscribers N] [--elbow RAD] [--neck RAD] [--last-neck RAD]

The reliability tests (test/reliability) and the benchmark's `load` section run it against
a running atlas.launch, as a separate process.
`valid`: one full 28-joint command (the standing pose, left elbow at --elbow, the
parameter-server gains) over and over: the load's publishers. `--neck` sets its neck_ay
target, so that several publishers send different commands; `--last-neck`, a last one sent
right after the flood with that neck_ay target: which command was applied last shows.
`bad`: one valid command (the same), then a cycle of every kind of broken message and of
bad /atlas/control_mode strings: the flooding test. The simulator must refuse them all.

Pacing is by wall clock (not sim time): a flood is an outside load. The JSON line gives
what was sent and how far sim time advanced meanwhile (the simulator's real-time factor).
"""

from __future__ import annotations

import argparse
import io
import json
import math
import socket
import sys
import threading
import time
import warnings

import genpy
import rospy
from osrf_msgs.msg import JointCommands
from rosgraph_msgs.msg import Clock
from std_msgs.msg import String

from tutorial_atlas_control.joints import JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.node.transport import subscriber_names
from tutorial_atlas_control.trajectories.traj_yaml_node import build_command, read_gains

#: The valid command's default left elbow target (rad).
DEFAULT_ELBOW_RAD = 1.2
ELBOW = JOINT_NAMES.index('l_arm_elx')
NECK = JOINT_NAMES.index('neck_ay')
#: Every `BAD_MODE_EVERY`-th bad message is followed by a bad control mode.
BAD_MODE_EVERY = 50
BAD_MODES = ('', 'Dance', 'user', 'U' * 100_000, 'User\x00Stand')


def valid_command(elbow_rad: float, neck_rad: float = 0.0) -> JointCommands:
    """What traj_yaml.py sends (all 28 joints, parameter-server gains): stand, elbow bent."""
    position = [0.0] * NUM_JOINTS
    position[ELBOW] = elbow_rad
    position[NECK] = neck_rad
    return build_command(JointCommands, position, read_gains(), rospy.Time())


def bad_commands() -> list[JointCommands]:
    """One message per way of being wrong; each would move the robot if it were applied."""
    full = valid_command(DEFAULT_ELBOW_RAD)

    def variant(**fields: object) -> JointCommands:
        arrays = {field: list(getattr(full, field)) for field in full.__slots__
                  if field not in ('header', 'name')}
        names = fields.pop('name', list(full.name))
        arrays.update(fields)
        return JointCommands(name=names, **arrays)

    zeros = [0.0] * NUM_JOINTS
    with_value = lambda value: [value] + zeros[1:]  # noqa: E731 - a table of cases
    return [
        variant(position=zeros[:-1]),                                # 27 entries
        variant(position=zeros + [0.0]),                             # 29 entries
        variant(position=with_value(math.nan)),                      # NaN
        variant(position=with_value(math.inf)),                      # Inf
        variant(effort=with_value(-math.inf)),
        variant(kd_position=with_value(math.nan)),
        variant(name=['atlas::nose'] + list(JOINT_NAMES[1:]), position=zeros),  # unknown
        variant(name=['l_arm_elx', 'atlas::l_arm_elx'], position=[0.0, 0.0], velocity=[],
                effort=[], kp_position=[], ki_position=[], kd_position=[], kp_velocity=[],
                i_effort_min=[], i_effort_max=[]),                   # duplicate name
        variant(kp_position=[1e12] * NUM_JOINTS, position=zeros),    # absurd gains
        variant(kd_position=[-1e12] * NUM_JOINTS, position=zeros),
        variant(effort=[1e12] * NUM_JOINTS, position=zeros),         # absurd efforts
        variant(effort=[-1e300] * NUM_JOINTS, position=zeros),
        variant(velocity=[1e9] * NUM_JOINTS, kp_velocity=[1e3] * NUM_JOINTS),
        variant(name=['l_arm_elx', 'r_arm_elx', 'neck_ay'], position=zeros),  # 3 names, 28
    ]


class Preserialized(genpy.Message):
    """A message serialized once and sent as is: a flood costs the sender no serialization.

    Keeps the real type and MD5, so subscribers see an ordinary osrf_msgs/JointCommands
    (only the header's seq and stamp are frozen).
    """

    _type = JointCommands._type
    _md5sum = JointCommands._md5sum
    _full_text = JointCommands._full_text
    _has_header = False  # stops rospy from rewriting a header we do not decode
    __slots__ = ['raw']

    def __init__(self, message: JointCommands) -> None:
        buffer = io.BytesIO()
        message.serialize(buffer)
        self.raw = buffer.getvalue()

    def serialize(self, buff: io.BytesIO) -> None:
        buff.write(self.raw)


#: How long (s, wall) the flood waits at its end for its subscribers to read what it sent.
UNREAD_TIMEOUT_S = 60.0
#: How long (s, wall) the subscribers' connections must stay as they are before a flood.
CONNECTIONS_SETTLE_S = 0.2


class ClockWatch:
    """The latest /clock, for the real-time factor and for --start-sim."""

    def __init__(self) -> None:
        self.ns = -1
        self.lock = threading.Lock()
        rospy.Subscriber('/clock', Clock, self._on_clock, queue_size=1)

    def _on_clock(self, msg: Clock) -> None:
        with self.lock:
            self.ns = msg.clock.to_nsec()

    def now_ns(self) -> int:
        with self.lock:
            return self.ns


def _tcp_queues() -> dict[tuple[str, str], tuple[int, int]]:
    """(local, remote) address in /proc/net/tcp's hex form -> (tx_queue, rx_queue) bytes."""
    queues = {}
    for table in ('/proc/net/tcp', '/proc/net/tcp6'):
        try:
            with open(table, encoding='ascii') as lines:
                next(lines)
                for line in lines:
                    fields = line.split()
                    tx, rx = fields[4].split(':')
                    queues[(fields[1], fields[2])] = (int(tx, 16), int(rx, 16))
        except OSError:
            continue
    return queues


def _hex_address(address: tuple) -> str:
    """An IPv4 (host, port) as /proc/net/tcp writes it: 0100007F:1F90."""
    host = socket.inet_aton(address[0])
    return f'{int.from_bytes(host, "little"):08X}:{address[1]:04X}'


def wait_until_read(pub: rospy.Publisher, timeout_s: float = UNREAD_TIMEOUT_S) -> None:
    """Stay registered until every subscriber has read what was sent to it.

    When a publisher unregisters, roscpp's subscribers (the recorder) drop the connection at
    once, discarding what their kernel has received but they have not read yet: a recorder
    starved of CPU lost the last seconds of two floods (2771 and 3820 of 60 001 commands,
    load 9). So the flood ends only once no byte waits in either direction, or after
    `timeout_s` (then with one line on stderr).
    """
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline and not rospy.is_shutdown():
        queues = _tcp_queues()
        waiting = 0
        for connection in list(pub.impl.connections):
            sock = getattr(connection, 'socket', None)
            try:
                local, remote = sock.getsockname(), sock.getpeername()
                ours = (_hex_address(local), _hex_address(remote))
            except (AttributeError, OSError, ValueError):
                continue  # closed, or not IPv4: nothing to wait for that can be seen
            tx, _ = queues.get(ours, (0, 0))
            _, rx = queues.get((ours[1], ours[0]), (0, 0))
            waiting += tx + rx
        if waiting == 0:
            return
        time.sleep(0.05)
    print(f'flood_commands.py: subscribers still had bytes to read after {timeout_s:.0f} s',
          file=sys.stderr, flush=True)


def flood(kind: str, rate_hz: float, duration_s: float, start_sim_s: float,
          subscribers: int, elbow_rad: float, neck_rad: float = 0.0,
          last_neck_rad: float | None = None) -> dict:
    # queue_size=None: synchronous writes, no per-connection writer thread to hand off to.
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', SyntaxWarning)  # rospy: "explicit queue_size"
        commands = rospy.Publisher('/atlas/joint_commands', Preserialized, queue_size=None,
                                   tcp_nodelay=True)
    modes = rospy.Publisher('/atlas/control_mode', String, queue_size=10)
    clock = ClockWatch()
    deadline = time.monotonic() + 60.0
    settled_since: float | None = None
    while True:
        # Every subscriber connected once, for CONNECTIONS_SETTLE_S: a subscriber may connect
        # twice at first and drop one; what is sent on the dropped one alone would be lost to it.
        names = subscriber_names(commands)
        ready = (clock.now_ns() >= start_sim_s * 1e9 and len(names) >= subscribers
                 and len(commands.impl.connections) == len(names))
        now_s = time.monotonic()
        if not ready:
            settled_since = None
        elif settled_since is None:
            settled_since = now_s
        elif now_s - settled_since >= CONNECTIONS_SETTLE_S:
            break
        if now_s > deadline or rospy.is_shutdown():
            raise SystemExit(f'flood_commands.py: no /clock, or fewer than {subscribers} '
                             'subscribers to /atlas/joint_commands')
        time.sleep(0.01)
    valid = Preserialized(valid_command(elbow_rad, neck_rad))
    bad = [Preserialized(message) for message in bad_commands()]
    if kind == 'bad':
        commands.publish(valid)
        time.sleep(0.5)  # the one valid command lands before the flood
    period_s = 1.0 / rate_hz
    sent = bad_modes = 0
    sim0_ns, wall0_s = clock.now_ns(), time.monotonic()
    # One line when the flood begins: the benchmark waits for it before its memory baseline.
    print(f'flood_commands.py: started at sim {sim0_ns / 1e9:.3f} s', file=sys.stderr,
          flush=True)
    next_s = wall0_s
    while not rospy.is_shutdown():
        now_s = time.monotonic()
        if now_s - wall0_s >= duration_s:
            break
        if kind == 'valid':
            commands.publish(valid)
        else:
            commands.publish(bad[sent % len(bad)])
            if sent % BAD_MODE_EVERY == 0:
                modes.publish(String(data=BAD_MODES[bad_modes % len(BAD_MODES)]))
                bad_modes += 1
        sent += 1
        next_s += period_s  # on average exactly `rate_hz`, whatever sleep() overshoots
        pause_s = next_s - time.monotonic()
        if pause_s > 0.0:
            time.sleep(pause_s)
    if last_neck_rad is not None and not rospy.is_shutdown():
        commands.publish(Preserialized(valid_command(elbow_rad, last_neck_rad)))  # no pause
        sent += 1
    wall_s = time.monotonic() - wall0_s
    sim_s = (clock.now_ns() - sim0_ns) / 1e9
    wait_until_read(commands)
    return {'kind': kind, 'sent': sent, 'bad_modes': bad_modes, 'wall_s': wall_s,
            'sim_s': sim_s, 'rate_hz': sent / wall_s, 'real_time_factor': sim_s / wall_s,
            'sim_start_s': sim0_ns / 1e9}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--kind', choices=('valid', 'bad'), required=True)
    parser.add_argument('--rate', type=float, default=1000.0, help='messages per second (wall)')
    parser.add_argument('--duration', type=float, default=10.0, help='seconds (wall)')
    parser.add_argument('--start-sim', type=float, default=0.0,
                        help='start once sim time reaches this (s)')
    parser.add_argument('--subscribers', type=int, default=2,
                        help='wait until this many nodes are connected (default: the simulator and '
                        'the recorder)')
    parser.add_argument('--elbow', type=float, default=DEFAULT_ELBOW_RAD,
                        help='left elbow target of the valid command (rad, default %(default)g)')
    parser.add_argument('--neck', type=float, default=0.0,
                        help='neck_ay target of the valid command (rad, default %(default)g)')
    parser.add_argument('--last-neck', type=float, default=None,
                        help='send one last valid command with this neck_ay target (rad)')
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node('flood_commands', anonymous=True)
    figures = flood(args.kind, args.rate, args.duration, args.start_sim, args.subscribers,
                    args.elbow, args.neck, args.last_neck)
    print(json.dumps(figures), flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
