#!/usr/bin/env python3
"""rostest: the simulator serves UDPROS (node/udpros.py), as DRCSim's roscpp plugin did.

- every topic it publishes answers a UDPROS requestTopic as roscpp expects, and its
  messages arrive as UDPROS datagrams, cut into blocks no larger than the subscriber's
  max_datagram_size, that reassemble into messages of the topic's type (a receiver here,
  msgs/udpros.py's Reassembler);
- a roscpp subscriber (joint_commands_client, ~transport udp) killed with SIGKILL is dropped:
  its connection leaves getBusInfo and the simulator's socket to it is closed;
- a subscriber offering only a protocol the simulator cannot serve, or UDPROS for the wrong
  type, gets exactly one log line from the simulator naming it and the topic;
- this node's rospy subscriptions still get TCPROS.
"""

from __future__ import annotations

import os
import re
import select
import signal
import socket
import subprocess
import threading
import time
import unittest
import xmlrpc.client

import rosgraph
import roslib.message
import rospy
import rostest
from geometry_msgs.msg import Wrench
from osrf_msgs.msg import JointCommands
from rosgraph_msgs.msg import Log
from sim_probe import WALL_TIMEOUT_S, SimProbe, bus_connections, transports_to

from tutorial_atlas_control.msgs import udpros

PKG = 'tutorial_atlas_control'
SIM = '/atlas_sim'
#: Small enough that a joint state (about 1.1 kB) needs 3 datagrams.
PROBE_DATAGRAM_SIZE = 512
VICTIM = '/udp_victim'


class UdprosTest(unittest.TestCase):
    def setUp(self) -> None:
        rospy.init_node('test_udpros', anonymous=True)
        self.lock = threading.Lock()
        self.sim_log: list[str] = []
        rospy.Subscriber('/rosout', Log, self._on_log, queue_size=1000)
        self.victim_commands = 0
        rospy.Subscriber('/atlas/joint_commands', JointCommands, self._on_command,
                         queue_size=1000)
        self.probe = SimProbe()
        self.probe.wait_ready()
        self.master = rosgraph.Master(rospy.get_name())
        self.sim_api = xmlrpc.client.ServerProxy(self.master.lookupNode(SIM))

    def _on_log(self, msg: Log) -> None:
        if msg.name == SIM:
            with self.lock:
                self.sim_log.append(msg.msg)

    def _on_command(self, msg: JointCommands) -> None:
        if msg._connection_header.get('callerid') == VICTIM:
            self.victim_commands += 1

    def log_lines(self, text: str) -> list[str]:
        with self.lock:
            return [line for line in self.sim_log if text in line]

    def offer_udpros(self, topic: str, caller_id: str, md5sum: str = '*'
                     ) -> tuple[socket.socket, list]:
        """A bound UDP socket, and requestTopic's answer to offering it for `topic`."""
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        sock.bind(('127.0.0.1', 0))
        header = udpros.encode_connection_header(
            {'topic': topic, 'md5sum': md5sum, 'callerid': caller_id, 'type': '*'})
        answer = self.sim_api.requestTopic(caller_id, topic, [[
            'UDPROS', xmlrpc.client.Binary(header), '127.0.0.1', sock.getsockname()[1],
            PROBE_DATAGRAM_SIZE]])
        return sock, answer

    # -- every topic ---------------------------------------------------------------------
    def test_every_published_topic_is_served_over_udpros(self) -> None:
        published = sorted(topic for topic, nodes in self.master.getSystemState()[0]
                           if SIM in nodes)
        types = dict(self.master.getTopicTypes())
        self.assertIn('/atlas/joint_states', published)
        receivers: dict[socket.socket, tuple[str, udpros.Reassembler]] = {}
        for topic in published:
            sock, (code, text, answer) = self.offer_udpros(topic, '/udp_probe')
            self.assertEqual(code, 1, f'{topic}: {text}')
            self.assertEqual(answer[0], 'UDPROS')
            self.assertEqual([type(a) for a in answer[1:5]], [str, int, int, int])
            self.assertEqual(answer[4], PROBE_DATAGRAM_SIZE)
            header = udpros.decode_connection_header(answer[5].data)
            self.assertEqual((header['topic'], header['type'], header['callerid']),
                             (topic, types[topic], SIM))
            receivers[sock] = (topic, udpros.Reassembler())
        self.assertEqual(sorted(c[4] for c in bus_connections(SIM)
                                if c[1] == '/udp_probe' and c[3] == 'UDPROS'), published)
        # /atlas/sim_inputs and /rosout carry events: an applied cheat gives one of each.
        force = rospy.Publisher('/atlas/apply_pelvis_force', Wrench, queue_size=1, latch=True)
        force.publish(Wrench())
        # /atlas/synchronization_statistics is sent only while an AtlasCommand asks for the
        # synchronization window, which none does here: served, never sent.
        expected = [topic for topic in published
                    if topic != '/atlas/synchronization_statistics']
        received: dict[str, object] = {}
        blocks: dict[str, set[int]] = {}
        deadline = time.monotonic() + WALL_TIMEOUT_S
        while len(received) < len(expected) and time.monotonic() < deadline:
            ready, _, _ = select.select(list(receivers), [], [], 0.5)
            for sock in ready:
                datagram = sock.recv(65536)
                self.assertLessEqual(len(datagram), PROBE_DATAGRAM_SIZE)
                topic, reassembler = receivers[sock]
                head = udpros.DatagramHeader(*udpros.HEADER.unpack_from(datagram))
                if head.op == udpros.OP_DATA0:
                    blocks.setdefault(topic, set()).add(head.block)
                payload = reassembler.feed(datagram)
                if payload is not None and topic not in received:
                    msg_class = roslib.message.get_message_class(types[topic])
                    received[topic] = msg_class().deserialize(payload)
        for sock in receivers:
            sock.close()
        self.assertEqual(sorted(received), expected)
        rospy.loginfo(f'UDPROS: one message from each of {len(published)} topics; blocks '
                      f'per message (DATA0 counts): {blocks}')
        self.assertEqual(len(received['/atlas/joint_states'].name), 28)
        self.assertIn('timestep', received['/atlas/sim_config'].data)
        self.assertEqual(received['/atlas/current_control_mode'].data, 'Stand')
        # 1.1 kB in 504-byte payloads: 3 blocks; /clock's 12 bytes: 1.
        self.assertEqual(blocks['/atlas/joint_states'], {3})
        self.assertEqual(blocks['/clock'], {1})

    # -- a killed roscpp subscriber ------------------------------------------------------
    def test_a_killed_udp_subscriber_is_dropped(self) -> None:
        sim_pid = self.sim_api.getPid(rospy.get_name())[2]
        victim = subprocess.Popen(  # rosrun execs the client: this pid is the client's
            ['rosrun', PKG, 'joint_commands_client', f'__name:={VICTIM[1:]}', '_transport:=udp'])
        try:
            self.probe.wait_until(
                lambda: transports_to(VICTIM, '/atlas/joint_states') == ['UDPROS'],
                f'{VICTIM} to subscribe to /atlas/joint_states over UDPROS')
            [info] = [c[6] for c in bus_connections(SIM)
                      if c[1] == VICTIM and c[4] == '/atlas/joint_states']
            port = int(re.search(r'to \[[^\]]*:(\d+)\]', info).group(1))
            self.assertIn(port, udp_peer_ports(sim_pid))
            # It answers joint states: it receives them.
            self.probe.wait_until(lambda: self.victim_commands > 10, f'{VICTIM} to answer')
        finally:
            victim.send_signal(signal.SIGKILL)
            victim.wait()
        self.probe.wait_until(lambda: transports_to(VICTIM, '/atlas/joint_states') == [],
                              f'{SIM} to drop the killed {VICTIM}')
        self.assertNotIn(port, udp_peer_ports(sim_pid))
        # The simulator goes on.
        self.probe.wait_sim(0.1)

    # -- unservable offers -----------------------------------------------------------------
    def test_an_unservable_offer_is_named_in_one_log_line(self) -> None:
        for _ in range(2):
            code, text, answer = self.sim_api.requestTopic(
                '/fooros_subscriber', '/atlas/joint_states', [['FOOROS']])
            self.assertEqual((code, answer), (0, []), text)
        # A servable protocol after the unservable one is chosen, without a word.
        code, _text, answer = self.sim_api.requestTopic(
            '/fooros_then_tcpros', '/atlas/joint_states', [['FOOROS'], ['TCPROS']])
        self.assertEqual((code, answer[0]), (1, 'TCPROS'))
        # UDPROS for the wrong type.
        sock, (code, _text, answer) = self.offer_udpros('/clock', '/wrong_type', md5sum='0' * 32)
        sock.close()
        self.assertEqual((code, answer), (0, []))
        # The last line: once it is in, any earlier one is too (one publisher, in order).
        self.sim_api.requestTopic('/fooros_subscriber', '/clock', [['FOOROS']])
        self.probe.wait_until(lambda: self.log_lines('/fooros_subscriber of /clock'),
                              'the log line about /clock')
        self.assertEqual(self.log_lines('/fooros_subscriber of /atlas/joint_states'), [
            'subscriber /fooros_subscriber of /atlas/joint_states offers only FOOROS; '
            '/atlas_sim serves TCPROS and UDPROS: not connected (roscpp: '
            'ros::TransportHints().reliable() or .unreliable())'])
        self.assertEqual(self.log_lines('/fooros_then_tcpros'), [])
        self.assertEqual(self.log_lines('/wrong_type'), [
            'UDPROS subscriber /wrong_type of /clock refused: it expects type * (MD5 '
            f'{"0" * 32}), the topic is rosgraph_msgs/Clock (MD5 '
            'a9c97c1d230cfc112e270351a944ee47)'])

    # -- rospy subscribers -----------------------------------------------------------------
    def test_rospy_subscribers_keep_tcpros(self) -> None:
        self.assertEqual(transports_to(rospy.get_name(), '/atlas/joint_states'), ['TCPROS'])
        self.probe.wait_sim(0.1)


def udp_peer_ports(pid: int) -> list[int]:
    """The remote ports of process `pid`'s connected UDP sockets (/proc/net/udp)."""
    inodes = set()
    for fd in os.listdir(f'/proc/{pid}/fd'):
        try:
            target = os.readlink(f'/proc/{pid}/fd/{fd}')
        except OSError:  # closed meanwhile
            continue
        if target.startswith('socket:['):
            inodes.add(target[8:-1])
    ports = []
    with open('/proc/net/udp') as table:
        next(table)
        for line in table:
            fields = line.split()
            if fields[9] in inodes:
                ports.append(int(fields[2].split(':')[1], 16))
    return ports


if __name__ == '__main__':
    rostest.rosrun(PKG, 'udpros', UdprosTest)
