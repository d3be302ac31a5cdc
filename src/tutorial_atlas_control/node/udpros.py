"""UDPROS for the node's publishers: a transport handler registered with rospy.

rospy serves TCPROS only. A roscpp subscriber that asks for `ros::TransportHints().unreliable()`
alone (DRCSim's C++ tutorial does, for /atlas/joint_states) offers only UDPROS, rospy's
requestTopic answers "no supported protocol", roscpp logs that at debug level, and the
subscription never connects. DRCSim's plugin was roscpp and served UDP.

serve() adds UdprosHandler to the node's rospy protocol handlers (ROSHandler.protocol_handlers,
the list requestTopic asks `supports(protocol)` in the subscriber's order of preference):
for an offered ['UDPROS', header, host, port, max_datagram_size] it checks the header,
opens a UDP socket connected to the subscriber, and adds a UdprosConnection to the topic's
publisher like a TCPROS connection. Both publish paths then reach it:

- the stepping loop's (transport.ConnectionWriter): it writes each publisher's batch
  of TCPROS-framed messages with `connection.socket.sendall(batch)`; here `socket` is a
  DatagramStream, which cuts the batch into messages and sends each as its datagrams, so
  the TCP path is untouched;
- rospy's Publisher.publish() (the latched /atlas/sim_config, /atlas/current_control_mode,
  /atlas/sim_inputs, and the latched message on connecting): `write_data()`.

A subscriber that goes away (closed, killed) closes its port; the kernel then answers the
next datagram with ICMP port unreachable, the connected socket's next send fails with
ECONNREFUSED, and the connection is dropped as a TCP one whose peer reset it.

serve() also makes requestTopic say, once per subscriber and topic, when a subscriber
offers only protocols the node cannot serve: roscpp itself only logs that at debug level.
The pure protocol (headers, blocks, negotiation) is msgs/udpros.py.
"""

from __future__ import annotations

import itertools
import socket
import threading
import xmlrpc.client
from collections.abc import Callable
from typing import Any

import rosgraph.network
import rospy
from rospy.impl.registration import RegManager, get_registration_listeners, get_topic_manager
from rospy.impl.tcpros_base import TransportTerminated
from rospy.impl.transport import OUTBOUND, ProtocolHandler, Transport

from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.msgs import (
    HEADER,
    HEADER_SIZE,
    OP_DATA0,
    OP_DATAN,
    PROTOCOL,
    UdprosError,
    framed_messages,
    message_blocks,
    next_message_id,
)
from tutorial_atlas_control.msgs import parse_request as parse_udpros_request
from tutorial_atlas_control.msgs import reply as udpros_reply
from tutorial_atlas_control.node.transport import SEND_TIMEOUT_S

__all__ = ['DatagramStream', 'UdprosConnection', 'UdprosHandler', 'serve']

#: Host names and address prefixes that mean "this machine only" (as roscpp's
#: network::isOnlyLocalhostAllowed: ROS_HOSTNAME=localhost or ROS_IP=127.x).
LOOPBACK_NAMES = ('localhost', '127.', '::1')


class DatagramStream:
    """A UDPROS connection seen as the byte stream transport.ConnectionWriter writes:
    sendall() takes TCPROS-framed messages back to back and sends each as its datagrams.

    A lock keeps one message's datagrams together when two threads send (rospy's latched
    send on connecting and a publish).
    """

    def __init__(self, sock: socket.socket, connection_id: int, max_datagram_size: int) -> None:
        self.sock = sock
        self.connection_id = connection_id
        self.max_datagram_size = max_datagram_size
        self.max_payload = max_datagram_size - HEADER_SIZE
        self.message_id = 0
        self.datagrams_sent = 0
        self._lock = threading.Lock()

    def gettimeout(self) -> float | None:
        return self.sock.gettimeout()

    def settimeout(self, timeout_s: float | None) -> None:
        self.sock.settimeout(timeout_s)

    def fileno(self) -> int:
        return self.sock.fileno()

    def close(self) -> None:
        self.sock.close()

    def sendall(self, data: bytes | bytearray) -> None:
        """Send every message in `data`; OSError (ECONNREFUSED once the subscriber's port
        is closed, a timeout) as socket.sendall raises it."""
        header, connection_id, sock = HEADER, self.connection_id, self.sock
        with self._lock:
            for frame in framed_messages(data):
                message_id = self.message_id = next_message_id(self.message_id)
                if len(frame) <= self.max_payload:  # the usual case: one datagram
                    sock.sendmsg((header.pack(connection_id, OP_DATA0, message_id, 1),
                                  frame))
                    self.datagrams_sent += 1
                    continue
                blocks = message_blocks(frame, self.max_datagram_size)
                sock.sendmsg((header.pack(connection_id, OP_DATA0, message_id,
                                          len(blocks)), blocks[0]))
                for index, block in enumerate(blocks[1:], start=1):
                    sock.sendmsg((header.pack(connection_id, OP_DATAN, message_id,
                                              index), block))
                self.datagrams_sent += len(blocks)


class UdprosConnection(Transport):
    """One UDPROS subscriber of one topic, in the publisher's connection list.

    `socket` is the DatagramStream the loop's batches are written to; `endpoint_id` the
    subscriber's node name, as for TCPROS (getBusInfo, transport.subscriber_names).
    """

    transport_type = PROTOCOL

    def __init__(self, topic: str, caller_id: str, stream: DatagramStream,
                 remote: tuple[str, int]) -> None:
        super().__init__(OUTBOUND, name=topic)
        self.socket = stream
        self.endpoint_id = caller_id
        self.remote_endpoint = remote
        self.local_endpoint = stream.sock.getsockname()[:2]

    def fileno(self) -> int | None:
        """None once closed: rospy matches connections by fileno, and a closed socket's -1
        would match every other closed one."""
        return None if self.done else self.socket.fileno()

    def write_data(self, data: bytes | bytearray) -> bool:
        """rospy's publish path: `data` is one message with its TCPROS length prefix."""
        if self.done:
            raise TransportTerminated('connection closed')
        try:
            self.socket.sendall(data)
        except OSError as err:
            self.close()
            raise TransportTerminated(f'{self.name} to {self.endpoint_id}: {err}') from err
        self.stat_bytes += len(data)
        self.stat_num_msg += 1
        return True

    def close(self) -> None:
        if self.done:
            return
        self.socket.close()
        super().close()

    def get_transport_info(self) -> str:
        host, port = self.remote_endpoint
        return (f'UDPROS connection on port {self.local_endpoint[1]} to [{host}:{port}], '
                f'{self.socket.max_datagram_size}-byte datagrams')


class UdprosHandler(ProtocolHandler):
    """rospy protocol handler serving the node's topics over UDPROS (publishing only).

    get_supported() is empty: the node's own subscriptions keep offering TCPROS alone.
    """

    def __init__(self, warn: Callable[[str], None] = rospy.logwarn) -> None:
        self._connection_ids = itertools.count(1)
        self._warned: set[tuple[str, ...]] = set()
        self._warn = warn

    def warn_once(self, key: tuple[str, ...], text: str) -> None:
        """One line per key: a subscriber retrying the same request adds nothing."""
        if key not in self._warned:
            self._warned.add(key)
            self._warn(text)

    def supports(self, protocol: str) -> bool:
        return protocol == PROTOCOL

    def get_supported(self) -> list[list[str]]:
        return []

    def create_transport(self, topic: str, pub_uri: str,
                         protocol_params: list[Any]) -> tuple[int, str, int]:
        return 0, 'atlas_sim subscribes over TCPROS only', 0

    def shutdown(self) -> None:
        """Nothing of its own: rospy closes the topics, and with them the connections."""

    def init_publisher(self, topic: str, protocol: list[Any]) -> tuple[int, str, list[Any]]:
        """requestTopic's answer to an offered UDPROS: connect, or say why not."""
        try:
            request = parse_udpros_request(protocol)
        except UdprosError as err:
            return self._refuse('?', topic, str(err))
        caller_id = request.header.get('callerid', '?')
        impl = get_topic_manager().get_publisher_impl(topic)
        if impl is None:
            return 0, f'{rospy.get_name()} does not publish {topic}', []
        data_class = impl.data_class
        md5sum = request.header.get('md5sum')
        if request.header.get('topic', topic) != topic:
            return self._refuse(caller_id, topic, f'its connection header names topic '
                                f'{request.header["topic"]}')
        if md5sum not in ('*', data_class._md5sum):
            return self._refuse(caller_id, topic, f'it expects type {request.header.get("type")}'
                                f' (MD5 {md5sum}), the topic is {data_class._type} '
                                f'(MD5 {data_class._md5sum})')
        try:
            sock = _connected_socket(request.host, request.port)
        except (OSError, AtlasControlError) as err:
            return self._refuse(caller_id, topic, f'cannot send to {request.host}:'
                                f'{request.port}: {err}')
        connection_id = next(self._connection_ids)
        stream = DatagramStream(sock, connection_id, request.max_datagram_size)
        connection = UdprosConnection(topic, caller_id, stream, (request.host, request.port))
        rospy.logdebug(f'{topic}: UDPROS subscriber {caller_id} at {request.host}:'
                       f'{request.port}, {request.max_datagram_size}-byte datagrams')
        answer = udpros_reply(rosgraph.network.get_host_name(), connection.local_endpoint[1],
                              connection_id, request.max_datagram_size, {
                                  'callerid': rospy.get_name(),
                                  'md5sum': data_class._md5sum,
                                  'type': data_class._type,
                                  'message_definition': data_class._full_text,
                                  'topic': topic,
                                  'latching': '1' if impl.is_latch else '0'})
        answer[-1] = xmlrpc.client.Binary(answer[-1])  # roscpp requires base64
        impl.add_connection(connection)  # a latched topic sends its message now
        return 1, f'ready on {answer[1]}:{answer[2]}', answer

    def _refuse(self, caller_id: str, topic: str, reason: str) -> tuple[int, str, list[Any]]:
        text = f'UDPROS subscriber {caller_id} of {topic} refused: {reason}'
        self.warn_once((caller_id, topic, reason), text)
        return 0, text, []


def _connected_socket(host: str, port: int) -> socket.socket:
    """A UDP socket connected to the subscriber (IPv4, as roscpp's UDP), in timeout mode.

    Connected, so that ICMP port unreachable (the subscriber is gone) comes back as
    ECONNREFUSED on a later send. When ROS is bound to this machine only (ROS_HOSTNAME
    localhost or ROS_IP 127.x, as env.sh sets), only loopback destinations are accepted,
    as roscpp does.
    """
    address = socket.getaddrinfo(host, port, socket.AF_INET, socket.SOCK_DGRAM)[0][4]
    override = rosgraph.network.get_address_override() or ''
    if override.startswith(LOOPBACK_NAMES) and not address[0].startswith('127.'):
        raise AtlasControlError(f'ROS is bound to {override}; {address[0]} is not on this '
                                'machine')
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        sock.connect(address)
        sock.settimeout(SEND_TIMEOUT_S)
    except OSError:
        sock.close()
        raise
    return sock


def _node_handler() -> Any:
    """The node's rospy ROSHandler (the XML-RPC slave API), through its RegManager: the
    registration listener init_node() adds once the node is registered."""
    for listener in get_registration_listeners().listeners:
        if isinstance(listener, RegManager):
            return listener.handler
    raise AtlasControlError('UDPROS: rospy has no registered node; call rospy.init_node() first')


def serve(warn: Callable[[str], None] = rospy.logwarn) -> UdprosHandler:
    """Serve the node's topics over UDPROS to subscribers that offer it, and name in the
    log any subscriber that offers only protocols the node cannot serve. Call before
    advertising: roscpp asks a publisher once, when the master announces it."""
    ros_handler = _node_handler()
    handler = UdprosHandler(warn)
    ros_handler.protocol_handlers.append(handler)
    request_topic = ros_handler.requestTopic

    def request_topic_logged(caller_id: str, topic: str, protocols: Any) -> Any:
        answer = request_topic(caller_id, topic, protocols)
        if answer[0] == 0 and not answer[2] and isinstance(protocols, list):
            offered = [str(p[0]) for p in protocols if isinstance(p, list) and p]
            servable = [name for name in offered
                        for h in ros_handler.protocol_handlers or () if h.supports(name)]
            if offered and not servable:
                handler.warn_once((caller_id, topic, *offered), (
                    f'subscriber {caller_id} of {topic} offers only {", ".join(offered)}; '
                    f'{rospy.get_name()} serves TCPROS and UDPROS: not connected (roscpp: '
                    'ros::TransportHints().reliable() or .unreliable())'))
        return answer

    # The XML-RPC server looks methods up on the handler instance at each call.
    ros_handler.requestTopic = request_topic_logged
    return handler
