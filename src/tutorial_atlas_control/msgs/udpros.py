"""UDPROS, ROS 1's datagram transport, as roscpp speaks it. No rospy.

The byte layouts the simulator node needs to serve roscpp subscribers that ask for
`ros::TransportHints().unreliable()` (node/udpros.py is the rospy side):

- the negotiation: the subscriber's requestTopic offers
  ['UDPROS', connection header, host, port, max datagram size]; the publisher answers
  ['UDPROS', host, port, connection id, max datagram size, connection header]. Connection
  headers are TCPROS's `key=value` fields, each behind a uint32 length, with no total length
  in front (roscpp's ros::Header::write);
- the data: each message, with its TCPROS uint32 length prefix (roscpp's UDP reader reads
  the length, then the message, from the datagrams), cut into blocks of at most
  max_datagram_size - 8 bytes, each block behind an 8-byte header: connection id (uint32),
  opcode (uint8: DATA0 on the first block, DATAN on the others), message id (uint8, never 0:
  roscpp takes 0 for "no message under way"), block (uint16: on DATA0 the number of blocks,
  on DATAN the block's index). Little-endian, roscpp's in-memory struct on x86.

roscpp sends no keep-alive and treats any opcode but DATA0/DATAN as an error (it defines
PING and ERR and uses neither), so a publisher sends only data.
"""

from __future__ import annotations

import struct
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import Any, NamedTuple

from tutorial_atlas_control.errors import AtlasControlError

__all__ = [
    'HEADER', 'HEADER_SIZE', 'MAX_BLOCKS', 'MAX_DATAGRAM_SIZE', 'OP_DATA0', 'OP_DATAN',
    'OP_ERR', 'OP_PING', 'PROTOCOL', 'DatagramHeader', 'Reassembler', 'UdprosError',
    'UdprosRequest', 'datagram_header', 'datagrams', 'decode_connection_header',
    'encode_connection_header', 'framed_messages', 'message_blocks', 'next_message_id',
    'parse_request', 'reply',
]

#: The protocol's name in requestTopic.
PROTOCOL = 'UDPROS'
#: connection id, opcode, message id, block.
HEADER = struct.Struct('<IBBH')
HEADER_SIZE = HEADER.size  # 8 bytes
OP_DATA0 = 0  # the first block of a message; its block field holds the number of blocks
OP_DATAN = 1  # a following block; its block field holds the block's index (1, 2, ...)
OP_PING = 2   # defined by roscpp, never sent
OP_ERR = 3    # defined by roscpp, never sent
#: The block count and index are uint16.
MAX_BLOCKS = 0xFFFF
#: Largest UDP payload over IPv4 (65535 - 20 IP - 8 UDP bytes).
MAX_DATAGRAM_SIZE = 65507
_LENGTH = struct.Struct('<I')


class UdprosError(AtlasControlError):
    """A UDPROS request, connection header or data that does not follow the protocol."""


class DatagramHeader(NamedTuple):
    connection_id: int
    op: int
    message_id: int
    block: int


def datagram_header(connection_id: int, op: int, message_id: int, block: int) -> bytes:
    """The 8 bytes in front of every datagram."""
    return HEADER.pack(connection_id, op, message_id, block)


def next_message_id(message_id: int) -> int:
    """The id after `message_id`: 1..255, then 1 again (0 means "none" to roscpp)."""
    return message_id % 255 + 1


def framed_messages(batch: bytes | bytearray | memoryview) -> Iterator[memoryview]:
    """Cut TCPROS-framed bytes (messages back to back, each behind its uint32 length) into
    the messages, each a view that keeps its length prefix.

    Raises:
        UdprosError: the batch ends inside a message.
    """
    view = memoryview(batch)
    offset, end = 0, len(view)
    while offset < end:
        if end - offset < _LENGTH.size:
            raise UdprosError(f'TCPROS batch ends inside a length prefix at byte {offset} '
                              f'of {end}.')
        stop = offset + _LENGTH.size + _LENGTH.unpack_from(view, offset)[0]
        if stop > end:
            raise UdprosError(f'TCPROS batch ends inside a message: the message at byte '
                              f'{offset} needs {stop - offset} bytes, {end - offset} are left.')
        yield view[offset:stop]
        offset = stop


def message_blocks(frame: bytes | bytearray | memoryview, max_datagram_size: int
                   ) -> list[memoryview]:
    """`frame` (a message with its length prefix) cut into the payloads of its datagrams.

    Raises:
        UdprosError: the message needs more than MAX_BLOCKS datagrams of that size.
    """
    payload_size = max_datagram_size - HEADER_SIZE
    view = memoryview(frame)
    blocks = [view[start:start + payload_size] for start in range(0, len(view), payload_size)]
    if len(blocks) > MAX_BLOCKS:
        raise UdprosError(f'a message of {len(view)} bytes needs {len(blocks)} datagrams of '
                          f'{max_datagram_size} bytes; UDPROS counts at most {MAX_BLOCKS}.')
    return blocks


def datagrams(connection_id: int, message_id: int, frame: bytes | bytearray | memoryview,
              max_datagram_size: int) -> list[bytes]:
    """The datagrams that carry one message, headers included, as sent."""
    blocks = message_blocks(frame, max_datagram_size)
    out = [datagram_header(connection_id, OP_DATA0, message_id, len(blocks)) + blocks[0]]
    out += [datagram_header(connection_id, OP_DATAN, message_id, index) + block
            for index, block in enumerate(blocks[1:], start=1)]
    return out


def encode_connection_header(fields: Mapping[str, str]) -> bytes:
    """TCPROS `key=value` fields, each behind its uint32 length (no total in front)."""
    out = bytearray()
    for key, value in fields.items():
        field = f'{key}={value}'.encode()
        out += _LENGTH.pack(len(field)) + field
    return bytes(out)


def decode_connection_header(data: bytes) -> dict[str, str]:
    """The fields of a connection header (encode_connection_header's inverse).

    Raises:
        UdprosError: a field is cut short, has no '=', or is not UTF-8.
    """
    fields: dict[str, str] = {}
    offset = 0
    while offset < len(data):
        if len(data) - offset < _LENGTH.size:
            raise UdprosError(f'connection header ends inside a field length at byte {offset}.')
        size = _LENGTH.unpack_from(data, offset)[0]
        offset += _LENGTH.size
        if offset + size > len(data):
            raise UdprosError(f'connection header field at byte {offset} is {size} bytes '
                              f'long, only {len(data) - offset} are left.')
        try:
            key, sep, value = data[offset:offset + size].decode().partition('=')
        except UnicodeDecodeError as err:
            raise UdprosError(f'connection header field at byte {offset} is not UTF-8.') from err
        if not sep:
            raise UdprosError(f'connection header field {key!r} has no "=".')
        fields[key] = value
        offset += size
    return fields


@dataclass(frozen=True)
class UdprosRequest:
    """What a subscriber's requestTopic offers for UDPROS."""

    header: dict[str, str]
    host: str
    port: int
    max_datagram_size: int


def parse_request(protocol: list[Any]) -> UdprosRequest:
    """['UDPROS', header, host, port, max_datagram_size], checked. `header` is bytes or an
    object holding them in `.data` (xmlrpc.client.Binary, as XML-RPC delivers base64).

    Raises:
        UdprosError: saying which parameter is wrong.
    """
    if not isinstance(protocol, list) or len(protocol) != 5 or protocol[0] != PROTOCOL:
        raise UdprosError(f'UDPROS parameters must be [UDPROS, header, host, port, '
                          f'max_datagram_size], got {protocol!r}.')
    _, header, host, port, size = protocol
    raw = getattr(header, 'data', header)
    if not isinstance(raw, bytes):
        raise UdprosError(f'UDPROS connection header must be base64 bytes, got {header!r}.')
    if not isinstance(host, str) or not host:
        raise UdprosError(f'UDPROS host must be a host name or address, got {host!r}.')
    if isinstance(port, bool) or not isinstance(port, int) or not 0 < port < 65536:
        raise UdprosError(f'UDPROS port must be 1..65535, got {port!r}.')
    if (isinstance(size, bool) or not isinstance(size, int)
            or not HEADER_SIZE < size <= MAX_DATAGRAM_SIZE):
        raise UdprosError(f'UDPROS max_datagram_size must be {HEADER_SIZE + 1}..'
                          f'{MAX_DATAGRAM_SIZE} bytes, got {size!r}.')
    return UdprosRequest(decode_connection_header(raw), host, port, size)


def reply(host: str, port: int, connection_id: int, max_datagram_size: int,
          header: Mapping[str, str]) -> list[Any]:
    """The requestTopic answer, the header still as bytes (the caller wraps them for XML-RPC
    as base64, which roscpp requires)."""
    return [PROTOCOL, host, port, connection_id, max_datagram_size,
            encode_connection_header(header)]


class Reassembler:
    """Messages back from datagrams, as roscpp's reader takes them: a DATA0 starts a
    message, DATAN blocks of that message id in order complete it; anything else (a block
    out of order, of another message) drops the message under way. For tests and probes."""

    def __init__(self) -> None:
        self._message_id = 0
        self._blocks_left = 0
        self._next_block = 1
        self._parts: list[bytes] = []

    def feed(self, datagram: bytes) -> bytes | None:
        """The message (without its length prefix) this datagram completes, if any.

        Raises:
            UdprosError: a datagram shorter than its header, an unknown opcode, or a
                message whose length prefix disagrees with its blocks.
        """
        if len(datagram) < HEADER_SIZE:
            raise UdprosError(f'datagram of {len(datagram)} bytes, shorter than its header.')
        head = DatagramHeader(*HEADER.unpack_from(datagram))
        body = datagram[HEADER_SIZE:]
        if head.op == OP_DATA0:
            self._message_id, self._blocks_left, self._parts = head.message_id, head.block, []
            self._next_block = 1
        elif head.op == OP_DATAN:
            if head.message_id != self._message_id or head.block != self._next_block:
                self._message_id, self._blocks_left, self._parts = 0, 0, []
                return None
            self._next_block += 1
        else:
            raise UdprosError(f'unexpected UDPROS opcode {head.op}.')
        self._parts.append(body)
        self._blocks_left -= 1
        if self._blocks_left:
            return None
        frame = b''.join(self._parts)
        self._message_id, self._parts = 0, []
        if len(frame) < _LENGTH.size or _LENGTH.unpack_from(frame)[0] != len(frame) - 4:
            raise UdprosError(f'reassembled {len(frame)} bytes disagree with their length '
                              'prefix.')
        return frame[_LENGTH.size:]
