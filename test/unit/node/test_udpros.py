"""msgs/udpros.py: UDPROS's datagram header, blocks and negotiation, byte for byte as roscpp
(transport_udp.cpp, topic_manager.cpp) lays them out; node/udpros.py's DatagramStream over
real loopback sockets."""

from __future__ import annotations

import socket
import struct
import xmlrpc.client

import pytest

from tutorial_atlas_control.msgs import udpros
from tutorial_atlas_control.node import udpros as node_udpros


def framed(payload: bytes) -> bytes:
    return struct.pack('<I', len(payload)) + payload


def test_the_header_is_roscpps_struct_little_endian():
    # TransportUDPHeader {uint32 connection_id_; uint8 op_; uint8 message_id_; uint16 block_;}
    assert udpros.HEADER_SIZE == 8
    assert udpros.datagram_header(0x01020304, udpros.OP_DATAN, 0xAB, 0x0506) == \
        b'\x04\x03\x02\x01\x01\xab\x06\x05'
    assert (udpros.OP_DATA0, udpros.OP_DATAN, udpros.OP_PING, udpros.OP_ERR) == (0, 1, 2, 3)


def test_message_ids_run_1_to_255_never_0():
    """roscpp's reader takes message id 0 for "no message under way"."""
    ids = [1]
    for _ in range(600):
        ids.append(udpros.next_message_id(ids[-1]))
    assert 0 not in ids and min(ids) == 1 and max(ids) == 255
    assert udpros.next_message_id(255) == 1 and udpros.next_message_id(0) == 1


def test_a_message_that_fits_is_one_data0_datagram_with_its_length_prefix():
    frame = framed(b'hello')
    assert udpros.datagrams(7, 3, frame, 1500) == [
        b'\x07\x00\x00\x00' b'\x00' b'\x03' b'\x01\x00' b'\x05\x00\x00\x00hello']


def test_a_message_larger_than_a_datagram_is_cut_into_blocks():
    """24 bytes (4 of length, 20 of message) in 16-byte datagrams: 8 bytes of header and 8
    of payload each, 3 blocks; DATA0 carries the count, DATAN their index."""
    payload = bytes(range(20))
    sent = udpros.datagrams(7, 3, framed(payload), 16)
    assert sent == [
        b'\x07\x00\x00\x00\x00\x03\x03\x00' + b'\x14\x00\x00\x00' + bytes(range(0, 4)),
        b'\x07\x00\x00\x00\x01\x03\x01\x00' + bytes(range(4, 12)),
        b'\x07\x00\x00\x00\x01\x03\x02\x00' + bytes(range(12, 20)),
    ]
    assert all(len(d) <= 16 for d in sent)
    reassembler = udpros.Reassembler()
    assert [reassembler.feed(d) for d in sent] == [None, None, payload]


def test_an_exact_multiple_of_the_payload_size_has_no_empty_block():
    frame = framed(bytes(12))  # 16 bytes = 2 payloads of 8
    sent = udpros.datagrams(1, 1, frame, 16)
    assert [len(d) for d in sent] == [16, 16]
    assert sent[0][6:8] == b'\x02\x00'


def test_a_message_needing_more_than_65535_blocks_is_refused():
    frame = framed(bytes(65535 * 1 + 1 - 4))  # 65536 bytes in 1-byte payloads
    with pytest.raises(udpros.UdprosError, match='needs 65536 datagrams of 9 bytes; UDPROS '
                                                 'counts at most 65535'):
        udpros.message_blocks(frame, 9)


def test_a_tcpros_batch_is_cut_at_its_length_prefixes():
    batch = framed(b'a') + framed(b'') + framed(b'xyz')
    assert [bytes(m) for m in udpros.framed_messages(batch)] == [
        framed(b'a'), framed(b''), framed(b'xyz')]
    assert list(udpros.framed_messages(b'')) == []


@pytest.mark.parametrize('batch, message', [
    (framed(b'abc') + b'\x05\x00', 'ends inside a length prefix at byte 7 of 9'),
    (framed(b'abc')[:-1], 'the message at byte 0 needs 7 bytes, 6 are left'),
])
def test_a_truncated_batch_is_an_error(batch, message):
    with pytest.raises(udpros.UdprosError, match=message):
        list(udpros.framed_messages(batch))


def test_connection_headers_round_trip_as_roscpp_writes_them():
    fields = {'topic': '/atlas/joint_states', 'md5sum': '3066dcd76a6cfaef579bd0f34173e9fd',
              'callerid': '/client', 'type': 'sensor_msgs/JointState', 'empty': ''}
    raw = udpros.encode_connection_header(fields)
    assert raw.startswith(b'\x19\x00\x00\x00topic=/atlas/joint_states')
    assert udpros.decode_connection_header(raw) == fields
    # '=' in a value (message definitions hold them) stays in the value.
    assert udpros.decode_connection_header(b'\x05\x00\x00\x00a=b=c') == {'a': 'b=c'}


@pytest.mark.parametrize('raw, message', [
    (b'\x09\x00\x00\x00abc', 'field at byte 4 is 9 bytes long, only 3 are left'),
    (b'\x03\x00\x00\x00abc', "field 'abc' has no \"=\""),
    (b'\x02\x00', 'ends inside a field length at byte 0'),
    (b'\x02\x00\x00\x00\xff=', 'field at byte 4 is not UTF-8'),
])
def test_a_bad_connection_header_is_an_error(raw, message):
    with pytest.raises(udpros.UdprosError, match=message):
        udpros.decode_connection_header(raw)


def test_a_request_is_parsed_from_what_xmlrpc_delivers():
    header = udpros.encode_connection_header({'topic': '/clock', 'callerid': '/c'})
    request = udpros.parse_request(
        ['UDPROS', xmlrpc.client.Binary(header), 'localhost', 40000, 1500])
    assert request == udpros.UdprosRequest({'topic': '/clock', 'callerid': '/c'},
                                           'localhost', 40000, 1500)


@pytest.mark.parametrize('protocol, message', [
    (['UDPROS', b'', 'localhost', 40000], r'must be \[UDPROS, header, host, port, max_data'),
    (['TCPROS', b'', 'h', 1, 1500], 'must be'),
    (['UDPROS', 'text', 'localhost', 40000, 1500], 'header must be base64 bytes'),
    (['UDPROS', b'', '', 40000, 1500], 'host must be a host name or address'),
    (['UDPROS', b'', 'h', 0, 1500], 'port must be 1..65535, got 0'),
    (['UDPROS', b'', 'h', 1, 8], 'max_datagram_size must be 9..65507 bytes, got 8'),
    (['UDPROS', b'', 'h', 1, 65508], 'got 65508'),
])
def test_a_bad_request_says_which_parameter(protocol, message):
    with pytest.raises(udpros.UdprosError, match=message):
        udpros.parse_request(protocol)


def test_the_reply_is_roscpps_six_items():
    answer = udpros.reply('localhost', 5000, 9, 1500, {'topic': '/clock'})
    assert answer == ['UDPROS', 'localhost', 5000, 9, 1500, b'\x0c\x00\x00\x00topic=/clock']


def test_the_reassembler_drops_a_message_whose_blocks_come_out_of_order():
    first, second, third = udpros.datagrams(1, 5, framed(bytes(20)), 16)
    reassembler = udpros.Reassembler()
    assert reassembler.feed(first) is None
    assert reassembler.feed(third) is None  # block 2 before block 1: dropped
    assert reassembler.feed(second) is None
    # The next message starts afresh.
    assert [reassembler.feed(d) for d in udpros.datagrams(1, 6, framed(b'ok'), 16)] == [b'ok']
    with pytest.raises(udpros.UdprosError, match='unexpected UDPROS opcode 2'):
        reassembler.feed(udpros.datagram_header(1, udpros.OP_PING, 1, 0))


# -- node/udpros.py's DatagramStream over loopback --------------------------------------------
@pytest.fixture
def receiver():
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(('127.0.0.1', 0))
    sock.settimeout(5.0)
    yield sock
    sock.close()


def stream_to(receiver_sock: socket.socket, max_datagram_size: int):
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.connect(receiver_sock.getsockname())
    return node_udpros.DatagramStream(sock, 42, max_datagram_size)


def test_a_batch_goes_out_one_message_per_datagram_large_ones_in_blocks(receiver):
    stream = stream_to(receiver, 64)
    big = bytes(range(100))
    stream.sendall(framed(b'first') + framed(big) + framed(b'last'))
    got = [receiver.recv(65536) for _ in range(4)]
    assert got[0] == udpros.datagrams(42, 1, framed(b'first'), 64)[0]
    assert got[1:3] == udpros.datagrams(42, 2, framed(big), 64)
    assert got[3] == udpros.datagrams(42, 3, framed(b'last'), 64)[0]
    assert stream.datagrams_sent == 4
    stream.close()


def test_a_subscriber_whose_port_closed_is_refused(receiver):
    """The kernel answers a datagram to a closed port with ICMP port unreachable; the
    connected socket's next send fails: what drops a killed UDPROS subscriber."""
    stream = stream_to(receiver, 1500)
    receiver.close()
    with pytest.raises(ConnectionRefusedError):
        for _ in range(3):
            stream.sendall(framed(b'x'))
    stream.close()


# -- node/udpros.py's handler, against a fake publisher ---------------------------------------
class FakeMessage:
    _type = 'std_msgs/String'
    _md5sum = '992ce8a1687cec8c8bd883ec73ca41d1'
    _full_text = 'string data\n'


class FakePublisherImpl:
    data_class = FakeMessage
    is_latch = True

    def __init__(self) -> None:
        self.connections = []

    def add_connection(self, connection) -> None:
        self.connections.append(connection)


class FakeTopicManager:
    def __init__(self, topic: str, impl: FakePublisherImpl) -> None:
        self.impls = {topic: impl}

    def get_publisher_impl(self, topic: str):
        return self.impls.get(topic)


@pytest.fixture
def handler(monkeypatch):
    impl = FakePublisherImpl()
    monkeypatch.setattr(node_udpros, 'get_topic_manager',
                        lambda: FakeTopicManager('/atlas/sim_config', impl))
    monkeypatch.setattr(node_udpros.rospy, 'get_name', lambda: '/atlas_sim')
    monkeypatch.setattr(node_udpros.rospy, 'logdebug', lambda _text: None)
    warnings = []
    udp = node_udpros.UdprosHandler(warn=warnings.append)
    udp.impl, udp.warnings = impl, warnings
    yield udp
    for connection in impl.connections:
        connection.close()


def offer(receiver_sock, md5sum=FakeMessage._md5sum, size=1500):
    header = udpros.encode_connection_header({
        'topic': '/atlas/sim_config', 'md5sum': md5sum, 'callerid': '/client',
        'type': 'std_msgs/String'})
    return ['UDPROS', xmlrpc.client.Binary(header), '127.0.0.1',
            receiver_sock.getsockname()[1], size]


def test_an_offer_is_answered_as_roscpp_expects_and_connected(handler, receiver):
    code, _text, answer = handler.init_publisher('/atlas/sim_config', offer(receiver))
    assert code == 1
    assert answer[0] == 'UDPROS' and isinstance(answer[2], int) and answer[4] == 1500
    connection_id = answer[3]
    assert isinstance(answer[5], xmlrpc.client.Binary)  # roscpp requires base64
    assert udpros.decode_connection_header(answer[5].data) == {
        'callerid': '/atlas_sim', 'md5sum': FakeMessage._md5sum, 'type': 'std_msgs/String',
        'message_definition': 'string data\n', 'topic': '/atlas/sim_config', 'latching': '1'}
    [connection] = handler.impl.connections
    assert (connection.endpoint_id, connection.transport_type) == ('/client', 'UDPROS')
    # rospy's publish path: one TCPROS-framed message per write_data.
    connection.write_data(framed(b'\x02\x00\x00\x00hi'))
    assert receiver.recv(65536) == udpros.datagrams(
        connection_id, 1, framed(b'\x02\x00\x00\x00hi'), 1500)[0]
    assert (connection.stat_num_msg, connection.stat_bytes) == (1, 10)
    assert handler.warnings == []


def test_a_wrong_type_is_refused_with_one_line(handler, receiver):
    for _ in range(2):
        code, text, answer = handler.init_publisher('/atlas/sim_config',
                                                    offer(receiver, md5sum='0' * 32))
        assert (code, answer) == (0, [])
    assert handler.warnings == [
        'UDPROS subscriber /client of /atlas/sim_config refused: it expects type '
        f'std_msgs/String (MD5 {"0" * 32}), the topic is std_msgs/String '
        f'(MD5 {FakeMessage._md5sum})']
    assert text == handler.warnings[0]
    assert handler.impl.connections == []


def test_a_closed_connection_raises_transport_terminated_and_has_no_fileno(handler, receiver):
    handler.init_publisher('/atlas/sim_config', offer(receiver))
    [connection] = handler.impl.connections
    connection.close()
    assert connection.fileno() is None
    with pytest.raises(node_udpros.TransportTerminated):
        connection.write_data(framed(b'x'))


class FakeTcpHandler:
    @staticmethod
    def supports(protocol: str) -> bool:
        return protocol == 'TCPROS'


class FakeRosHandler:
    """rospy's ROSHandler as serve() sees it: requestTopic picks the first offered protocol
    a handler supports, else answers 0 with no parameters."""

    def __init__(self) -> None:
        self.protocol_handlers = [FakeTcpHandler()]

    def requestTopic(self, caller_id, topic, protocols):  # rospy's name
        for protocol in protocols:
            for handler in self.protocol_handlers:
                if handler.supports(protocol[0]):
                    return 1, 'ready', [protocol[0]]
        return 0, 'no supported protocol implementations', []


def test_serve_registers_udpros_and_names_an_unservable_subscriber_once(monkeypatch):
    ros_handler = FakeRosHandler()
    monkeypatch.setattr(node_udpros, '_node_handler', lambda: ros_handler)
    monkeypatch.setattr(node_udpros.rospy, 'get_name', lambda: '/atlas_sim')
    warnings = []
    handler = node_udpros.serve(warn=warnings.append)
    assert ros_handler.protocol_handlers[-1] is handler
    assert handler.get_supported() == []  # the node's own subscriptions stay TCPROS
    for _ in range(2):
        assert ros_handler.requestTopic('/sub', '/clock', [['FOOROS'], ['BAROS']]) == (
            0, 'no supported protocol implementations', [])
    assert ros_handler.requestTopic('/sub', '/clock', [['FOOROS'], ['TCPROS']])[0] == 1
    assert warnings == [
        'subscriber /sub of /clock offers only FOOROS, BAROS; /atlas_sim serves TCPROS and '
        'UDPROS: not connected (roscpp: ros::TransportHints().reliable() or .unreliable())']


def test_ros_bound_to_localhost_sends_to_this_machine_only(monkeypatch):
    """As roscpp with ROS_HOSTNAME=localhost (env.sh): no datagrams leave the machine."""
    monkeypatch.setattr(node_udpros.rosgraph.network, 'get_address_override',
                        lambda: 'localhost')
    with pytest.raises(node_udpros.AtlasControlError,
                       match='ROS is bound to localhost; 192.0.2.1 is not on this machine'):
        node_udpros._connected_socket('192.0.2.1', 9)
    node_udpros._connected_socket('127.0.0.1', 9).close()
