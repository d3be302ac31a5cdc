"""Fast ROS 1 bag reading and writing: the one module on rosbags' non-public API.

rosbags' public Reader and Writer handle each message as Python objects and struct calls;
a 1 kHz run has tens of thousands of messages, and that cost dominates both reading a bag
and writing one offline. Both sides here keep rosbags' file handling (opening, chunk
compression, connection records, the bag's index) and replace the per-message part with
numpy blocks:

* :class:`BlockIndexReader` reads each chunk's index of a connection as one numpy block
  and hands out decompressed chunks (records.IndexedBag slices messages out of them).
* :class:`BlockBagWriter` writes whole records a block at a time into rosbags' open chunk
  and keeps the chunk's index as numpy blocks (:class:`RecordBlock` lays out the records
  of a fixed-layout topic once and stamps many rows at a time).

Both subclass rosbags' Reader and Writer and use their attributes and helpers, which are
not public API: requirements.txt pins rosbags, and test_bag_reader checks both sides
against rosbags' public Reader and Writer on the same messages.
"""

from __future__ import annotations

import struct
from collections import defaultdict
from collections.abc import Mapping
from io import BytesIO
from pathlib import Path
from typing import Any, NamedTuple

import lz4.frame
import numpy as np
from rosbags.rosbag1 import Reader, ReaderError, Writer

# Not public API (requirements.txt pins rosbags; test_bag_reader checks them).
from rosbags.rosbag1.reader import Header as ReadHeader
from rosbags.rosbag1.reader import RecordType, read_uint32
from rosbags.rosbag1.writer import MAXSIZE, WriteChunk
from rosbags.rosbag1.writer import Header as WriteHeader
from rosbags.typesys.store import Typestore

from tutorial_atlas_control.units import NS_PER_S

__all__ = ['INDEX_ENTRY', 'BlockBagWriter', 'BlockIndexReader', 'RecordBlock', 'TopicConnection']

#: One entry of an IDXDATA record: bag time (sec, nsec) and the record's offset in its chunk.
INDEX_ENTRY = np.dtype([('sec', '<u4'), ('nsec', '<u4'), ('offset', '<u4')])
_U32 = struct.Struct('<I')
_TIME = struct.Struct('<II')
#: Bytes of a ROS time (secs, nsecs) and of a uint32 (std_msgs/Header.seq, a length).
_TIME_BYTES = 8
_U32_BYTES = 4


# ---------------------------------------------------------------------------- reading


class BlockIndexReader(Reader):  # type: ignore[misc]
    """rosbags' Reader, keeping each chunk's index of a connection as one numpy block.

    Overrides `read_index_data`, the hook `Reader.open` calls per IDXDATA record, so
    `self.indexes[connection id]` holds (chunk position, entries) blocks instead of one
    tuple per message; `Reader.messages` cannot read those.
    """

    def read_index_data(self, pos: int, indexes: dict[int, list[object]]) -> None:
        header = ReadHeader.read(self.bio, RecordType.IDXDATA)
        if (version := header.get_uint32('ver')) != 1:
            raise ReaderError(f'IDXDATA version {version} is not supported.')
        count = header.get_uint32('count')
        size = read_uint32(self.bio)
        if size != count * INDEX_ENTRY.itemsize:
            raise ReaderError(f'IDXDATA of chunk {pos} has {size} bytes for {count} entries.')
        entries = np.frombuffer(self.bio.read(size), dtype=INDEX_ENTRY, count=count)
        indexes[header.get_uint32('conn')].append((pos, entries))

    def index_blocks(self, connection_id: int) -> list[tuple[int, np.ndarray]]:
        """(chunk position, INDEX_ENTRY entries) of connection `connection_id`, chunk by chunk.

        `Reader.open` sorts each connection's blocks by chunk position.
        """
        return self.indexes[connection_id]

    def chunk_data(self, pos: int) -> bytes:
        """The decompressed data of the chunk at file position `pos` (Reader's chunk table)."""
        info = self.chunks[pos]
        self.bio.seek(info.datapos)
        try:
            return info.decompressor(self.bio.read(info.datasize))
        except (OSError, RuntimeError, ValueError, EOFError) as err:  # bz2, lz4: corrupt data
            raise ReaderError(f'the chunk at byte {pos} cannot be decompressed '
                              f'({type(err).__name__}: {err})') from err


# ---------------------------------------------------------------------------- writing


def _put_times(rows: np.ndarray, at: int, times_ns: np.ndarray) -> None:
    """Write ROS times (secs, nsecs as two uint32) at byte `at` of every row."""
    column = rows[:, at:at + _TIME_BYTES].view('<u4')
    column[:, 0] = times_ns // NS_PER_S
    column[:, 1] = times_ns % NS_PER_S


class RecordBlock:
    """Bag records of one topic whose messages all have the layout of one message.

    The message starts with std_msgs/Header (seq, stamp). Rows are laid out once as whole
    bag records (record header, length, the message); the numbers of many messages are
    then written into them by numpy (float_view, or add() copying the message) and take()
    stamps the record times, Header.seq and Header.stamp of all rows at once.
    """

    def __init__(self, record_prefix: bytes, message: np.ndarray, capacity: int) -> None:
        """Rows for `capacity` records; `message` (uint8) is a live view of its serialization,
        which add() copies as it is then."""
        self.source = message
        self.time_at = len(record_prefix)
        self.data_at = self.time_at + _TIME_BYTES + _U32_BYTES
        self.rows = np.zeros((capacity, self.data_at + len(self.source)), dtype=np.uint8)
        self.rows[:, :self.time_at] = np.frombuffer(record_prefix, dtype=np.uint8)
        self.rows[:, self.time_at + _TIME_BYTES:self.data_at] = np.frombuffer(
            _U32.pack(len(self.source)), dtype=np.uint8)
        self.rows[:, self.data_at:] = self.source
        self.times_ns = np.empty(capacity, dtype=np.int64)
        self.stamps_ns = np.empty(capacity, dtype=np.int64)
        self.count = 0
        self.seq = 0

    def float_view(self, offset: int, count: int) -> np.ndarray:
        """The `count` float64s at byte `offset` of the message, every row: (rows, count)."""
        at = self.data_at + offset
        return self.rows[:, at:at + 8 * count].view('<f8')

    def add(self, time_ns: int, stamp_ns: int) -> None:
        """Queue the message as it is now, recorded at `time_ns`, stamped `stamp_ns`."""
        k = self.count
        self.rows[k, self.data_at:] = self.source
        self.times_ns[k] = time_ns
        self.stamps_ns[k] = stamp_ns
        self.count = k + 1

    def take(self, times_ns: np.ndarray | None = None,
             stamps_ns: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Stamp and return the first rows: those add()ed, or len(times_ns) filled in place.

        Header.seq counts on from the last take(), starting at 1.
        """
        if times_ns is None or stamps_ns is None:
            times_ns, stamps_ns = self.times_ns[:self.count], self.stamps_ns[:self.count]
        count = len(times_ns)
        rows = self.rows[:count]
        _put_times(rows, self.time_at, times_ns)
        rows[:, self.data_at:self.data_at + _U32_BYTES].view('<u4')[:, 0] = (
            self.seq + 1 + np.arange(count, dtype=np.uint32))
        _put_times(rows, self.data_at + _U32_BYTES, stamps_ns)
        self.seq += count
        self.count = 0
        return times_ns.copy(), rows


class _IndexEntries:
    """One connection's index entries in one chunk, kept as numpy blocks (len() = entries)."""

    def __init__(self) -> None:
        self.blocks: list[np.ndarray] = []
        self.count = 0

    def __len__(self) -> int:
        return self.count

    def add(self, times_ns: np.ndarray, offsets: np.ndarray) -> None:
        block = np.empty(len(times_ns), dtype=INDEX_ENTRY)
        block['sec'], block['nsec'] = np.divmod(times_ns, NS_PER_S)
        block['offset'] = offsets
        self.blocks.append(block)
        self.count += len(block)

    def to_bytes(self) -> bytes:
        return b''.join(block.tobytes() for block in self.blocks)


def _new_chunk() -> WriteChunk:
    """An empty open chunk whose index entries are _IndexEntries."""
    return WriteChunk(BytesIO(), -1, MAXSIZE, 0, defaultdict(_IndexEntries))


def _roslz4_frame(data: bytes) -> bytes:
    """`data` as an LZ4 frame laid out as ROS 1's roslz4 writes one, and so reads one:
    independent 4 MB blocks, a content checksum, no content size. rosbags' own (lz4's
    defaults: the content size in the header) makes Debian's rosbag fail ("malformed data
    to decompress")."""
    return lz4.frame.compress(data, block_size=lz4.frame.BLOCKSIZE_MAX4MB, block_linked=False,
                              content_checksum=True, store_size=False)


#: atlas.launch's compression names, as rosbags' Writer calls them.
CHUNK_COMPRESSIONS = {'lz4': Writer.CompressionFormat.LZ4, 'bz2': Writer.CompressionFormat.BZ2}


class _IndexedWriter(Writer):  # type: ignore[misc]
    """rosbags' rosbag1 Writer, its chunk index kept and written by numpy.

    rosbags writes each index entry with its own struct calls when it closes a chunk; the
    chunk layout (CHUNK, then one IDXDATA per connection) is rosbags' own write_chunk.
    """

    def __init__(self, path: Path) -> None:
        super().__init__(path)
        self.chunks = [_new_chunk()]

    def write_chunk(self, chunk: WriteChunk) -> None:
        if (size := chunk.data.tell()) > 0:
            chunk.pos = self.bio.tell()
            header = WriteHeader()
            header.set_string('compression', self.compression_format)
            header.set_uint32('size', size)
            header.write(self.bio, RecordType.CHUNK)
            data = self.compressor(chunk.data.getvalue())
            self.bio.write(_U32.pack(len(data)))
            self.bio.write(data)
            for cid, entries in chunk.connections.items():
                header = WriteHeader()
                header.set_uint32('ver', 1)
                header.set_uint32('conn', cid)
                header.set_uint32('count', len(entries))
                header.write(self.bio, RecordType.IDXDATA)
                self.bio.write(_U32.pack(len(entries) * INDEX_ENTRY.itemsize))
                self.bio.write(entries.to_bytes())
            chunk.data.close()
            self.chunks.append(_new_chunk())


class TopicConnection(NamedTuple):
    """A bag connection: rosbags message type ('pkg/msg/Name'), publishing node, latched."""

    msgtype: str
    callerid: str
    latched: bool


class BlockBagWriter:
    """A new ROS 1 bag with one connection per topic, written a block of messages at a time.

    rosbags' Writer.write builds each record header field by field. Here a topic's record
    header is laid out once; fixed-layout topics are stamped and appended by numpy a block
    at a time (RecordBlock rows, write_rows), the rest one by one as they come (write);
    flush() puts everything queued into the writer's open chunk and its index, and the
    writer closes and indexes the bag as its own. Within a chunk, records are grouped by
    topic (readers go by the index, in time order).
    """

    def __init__(self, path: Path, typestore: Typestore,
                 connections: Mapping[str, TopicConnection], chunk_bytes: int,
                 compression: str = 'none') -> None:
        """Create the bag at `path` (which must not exist) with `connections`, in order.

        A chunk is closed after the flush() that takes it past `chunk_bytes`; chunks are
        compressed as `compression` says: 'lz4', 'bz2' or 'none' (atlas.launch's values).
        """
        self.typestore = typestore
        self.msgtypes = {topic: connection.msgtype for topic, connection in connections.items()}
        self.writer = _IndexedWriter(path)
        self.writer.chunk_threshold = chunk_bytes
        if compression != 'none':
            self.writer.set_compression(CHUNK_COMPRESSIONS[compression])
            if compression == 'lz4':
                self.writer.compressor = _roslz4_frame
        self.writer.open()
        self.connection_ids: dict[str, int] = {}
        self.prefixes: dict[str, bytes] = {}
        for topic, (msgtype, caller, latched) in connections.items():
            connection = self.writer.add_connection(
                topic, msgtype, typestore=typestore, callerid=caller,
                latching=1 if latched else None)
            self.connection_ids[topic] = connection.id
            # The record header as rosbags writes it: op=MSGDATA, conn=<id>, time=<8 bytes>.
            fields = [b'op=' + bytes([RecordType.MSGDATA]), b'conn=' + _U32.pack(connection.id)]
            head = b''.join(_U32.pack(len(field)) + field for field in fields)
            size = len(head) + _U32_BYTES + len(b'time=') + _TIME_BYTES
            self.prefixes[topic] = (_U32.pack(size) + head
                                    + _U32.pack(len(b'time=') + _TIME_BYTES) + b'time=')
        self._pending: list[tuple[str, int, bytes]] = []
        self._blocks: list[tuple[str, np.ndarray, bytes, int]] = []

    def record_block(self, topic: str, message: np.ndarray, capacity: int) -> RecordBlock:
        """Rows for `capacity` records of `topic`, laid out like `message` (see RecordBlock)."""
        return RecordBlock(self.prefixes[topic], message, capacity)

    def write_rows(self, topic: str, times_ns: np.ndarray, rows: np.ndarray) -> None:
        """Queue whole records (a RecordBlock's take()) of `topic`."""
        if len(rows):
            self._blocks.append((topic, times_ns, rows.tobytes(), rows.shape[1]))

    def write(self, topic: str, time_ns: int, data: bytes) -> None:
        """Queue one message (its ROS 1 serialization, no length prefix) at bag time `time_ns`."""
        self._pending.append((topic, time_ns, data))

    def write_message(self, topic: str, time_ns: int, message: Any) -> None:
        """Serialize a rosbags message of the topic's type and queue it."""
        self.write(topic, time_ns,
                   bytes(self.typestore.serialize_ros1(message, self.msgtypes[topic])))

    def flush(self) -> None:
        """Append everything queued to the writer's open chunk; close the chunk when full.

        The single messages go first, then the blocks, each in the order queued.
        """
        writer = self.writer
        chunk = writer.chunks[-1]
        bio = chunk.data
        first_ns, last_ns = chunk.start, chunk.end
        for topic, time_ns, data in self._pending:
            chunk.connections[self.connection_ids[topic]].add(np.array([time_ns]),
                                                              np.array([bio.tell()]))
            bio.write(self.prefixes[topic] + _TIME.pack(*divmod(time_ns, NS_PER_S))
                      + _U32.pack(len(data)) + data)
            first_ns, last_ns = min(first_ns, time_ns), max(last_ns, time_ns)
        self._pending.clear()
        for topic, times_ns, records, width in self._blocks:
            start = bio.tell()
            bio.write(records)
            offsets = start + np.arange(len(times_ns), dtype=np.int64) * width
            chunk.connections[self.connection_ids[topic]].add(times_ns, offsets)
            first_ns, last_ns = min(first_ns, int(times_ns[0])), max(last_ns, int(times_ns[-1]))
        self._blocks.clear()
        chunk.start, chunk.end = first_ns, last_ns
        if bio.tell() > writer.chunk_threshold:
            writer.write_chunk(chunk)

    def close(self) -> None:
        """Flush, then close the last chunk and write the bag's index."""
        self.flush()
        self.writer.close()
