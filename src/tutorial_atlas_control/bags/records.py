"""The raw messages of a ROS 1 bag, per connection and in time order: bag_reader's file layer.

Two readers behind one small interface (`connections`, `times_ns`, `raw_messages`, `close`):

* :class:`IndexedBag`, the default, reads each chunk's index as one numpy block and slices
  the messages straight out of the decompressed chunks: rosbags' `Reader.messages` builds
  Python objects per message, which makes a 1 kHz recording several times slower to read.
  It reads the bag through rosbag1_fast.BlockIndexReader, which relies on rosbags' Reader
  internals (requirements.txt pins rosbags; test_bag_reader checks its results against
  :class:`PublicBag` on the same bags).
* :class:`PublicBag` uses only rosbags' public `Reader.messages()`.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from pathlib import Path
from typing import Protocol

import numpy as np
from rosbags.interfaces import Connection
from rosbags.rosbag1 import Reader, ReaderError

from tutorial_atlas_control.bags.rosbag1_fast import BlockIndexReader
from tutorial_atlas_control.errors import BagAnalysisError
from tutorial_atlas_control.units import NS_PER_S

__all__ = ['BagRecords', 'IndexedBag', 'PublicBag', 'open_bag']

_BAG_MAGIC = b'#ROSBAG V2.0\n'
_U32 = struct.Struct('<I')
#: A record header's `op` field (length 4, 'op=' and one byte) and the MSGDATA op code.
_OP_FIELD = b'\x04\x00\x00\x00op='
_OP_MSGDATA = 2


class BagRecords(Protocol):
    """An open bag's messages as (bag times (ns), raw serialized bytes), in time order."""

    @property
    def connections(self) -> list[Connection]: ...

    def times_ns(self, connections: Sequence[Connection]) -> np.ndarray: ...

    def raw_messages(self, connections: Sequence[Connection]) -> tuple[np.ndarray, list[bytes]]:
        ...

    def close(self) -> None: ...


# ---------------------------------------------------------------------------- fast reader


class _ReaderBag:
    """A rosbags Reader (of class `reader_class`) behind the BagRecords interface."""

    reader_class: type[Reader] = Reader

    def __init__(self, path: Path) -> None:
        self._reader = self.reader_class(path)

    def open(self) -> None:
        self._reader.open()

    def close(self) -> None:
        self._reader.close()

    @property
    def connections(self) -> list[Connection]:
        return self._reader.connections


class IndexedBag(_ReaderBag):
    """Reads messages by slicing them out of chunks, located with a numpy index."""

    reader_class = BlockIndexReader
    _reader: BlockIndexReader

    def _index(self, connections: Sequence[Connection]) -> tuple[np.ndarray, ...]:
        """(bag times (ns), chunk positions, offsets in chunk) of `connections`, time-ordered.

        Ties are in file order (chunk, then offset), as `Reader.messages` yields them.
        """
        blocks = [block for connection in connections
                  for block in self._reader.index_blocks(connection.id)]
        if not blocks:
            empty = np.empty(0, dtype=np.int64)
            return empty, empty, empty
        entries = np.concatenate([entries for _, entries in blocks])
        times_ns = entries['sec'].astype(np.int64) * NS_PER_S + entries['nsec']
        chunk_pos = np.repeat([pos for pos, _ in blocks],
                              [len(entries) for _, entries in blocks]).astype(np.int64)
        offsets = entries['offset'].astype(np.int64)
        if len(connections) > 1:  # Reader.open sorts each connection's blocks by position
            in_file = np.lexsort((offsets, chunk_pos))
            times_ns, chunk_pos, offsets = times_ns[in_file], chunk_pos[in_file], offsets[in_file]
        order = np.argsort(times_ns, kind='stable')
        return times_ns[order], chunk_pos[order], offsets[order]

    def times_ns(self, connections: Sequence[Connection]) -> np.ndarray:
        """Bag times (ns) of the messages of `connections`, from the index alone."""
        return self._index(connections)[0]

    def raw_messages(self, connections: Sequence[Connection]) -> tuple[np.ndarray, list[bytes]]:
        """(bag times (ns), serialized messages) of `connections`, in time order.

        The record parsing is inlined: it runs once per message (60,000 for a 60 s run).
        """
        times_ns, chunk_positions, offsets = self._index(connections)
        raws: list[bytes] = []
        unpack_u32 = _U32.unpack_from
        chunk_pos, chunk = -1, b''
        for entry_chunk, offset in zip(chunk_positions.tolist(), offsets.tolist()):
            if entry_chunk != chunk_pos:
                chunk_pos, chunk = entry_chunk, self._reader.chunk_data(entry_chunk)
            while True:  # skip the CONNECTION records a chunk may hold before a message
                (header_len,) = unpack_u32(chunk, offset)
                header_end = offset + 4 + header_len
                (data_len,) = unpack_u32(chunk, header_end)
                op_at = chunk.find(_OP_FIELD, offset + 4, header_end)
                if op_at < 0:
                    raise BagAnalysisError(f'A record in chunk {chunk_pos} has no op field.')
                if chunk[op_at + len(_OP_FIELD)] == _OP_MSGDATA:
                    break
                offset = header_end + 4 + data_len
            raws.append(chunk[header_end + 4:header_end + 4 + data_len])
        return times_ns, raws


# ---------------------------------------------------------------------------- public reader


class PublicBag(_ReaderBag):
    """Reads messages with rosbags' public `Reader.messages()` only."""

    def times_ns(self, connections: Sequence[Connection]) -> np.ndarray:
        """Bag times (ns) of the messages of `connections` (reads the messages too)."""
        return self.raw_messages(connections)[0]

    def raw_messages(self, connections: Sequence[Connection]) -> tuple[np.ndarray, list[bytes]]:
        """(bag times (ns), serialized messages) of `connections`, in time order."""
        if not connections:  # Reader.messages reads every connection when given none
            return np.empty(0, dtype=np.int64), []
        times_ns: list[int] = []
        raws: list[bytes] = []
        for _, time_ns, raw in self._reader.messages(connections=connections):
            times_ns.append(time_ns)
            raws.append(raw)
        return np.array(times_ns, dtype=np.int64), raws


# ---------------------------------------------------------------------------- opening


def _check_file(path: Path) -> None:
    """Raise a BagAnalysisError that says what to do if `path` is not a readable ROS 1 bag."""
    if not path.exists():
        active = path.with_name(path.name + '.active')
        hint = (f'; {active} exists, so the recording was interrupted: run '
                f'`rosbag reindex {active}` and analyze that file' if active.exists() else '')
        raise BagAnalysisError(f'{path}: no such file{hint}.')
    if path.is_dir():
        raise BagAnalysisError(
            f'{path} is a directory; expected a ROS 1 .bag file (ROS 2 bags are not supported).')
    try:
        with path.open('rb') as stream:
            magic = stream.read(len(_BAG_MAGIC))
    except OSError as err:
        raise BagAnalysisError(f'Could not open {path}: {err.strerror or err}.') from err
    if not magic.startswith(_BAG_MAGIC[:9]):  # '#ROSBAG V', any version
        raise BagAnalysisError(
            f'{path} is not a ROS 1 bag (it does not start with "#ROSBAG V2.0").')


def _open_error(path: Path, err: Exception) -> BagAnalysisError:
    """What to tell the user when rosbags cannot open `path`."""
    if isinstance(err, ReaderError):
        text = str(err)
        if 'not indexed' in text or path.name.endswith('.active'):
            return BagAnalysisError(
                f'{path} is not indexed (an interrupted `rosbag record` leaves an unindexed '
                f'.bag.active file); run `rosbag reindex {path}` and analyze it again.')
        if 'magic' in text or 'empty' in text:
            return BagAnalysisError(
                f'{path} is not a ROS 1 bag (it does not start with "#ROSBAG V2.0").')
        return BagAnalysisError(f'Could not read {path}: {text}')
    hint = (f'; if it is an interrupted recording, run `rosbag reindex {path}`'
            if path.name.endswith('.active') else '')
    return BagAnalysisError(
        f'Could not read {path}, it looks damaged ({type(err).__name__}: {err}){hint}.')


def open_bag(path: Path, fast: bool = True) -> IndexedBag | PublicBag:
    """Open the ROS 1 bag at `path`: an :class:`IndexedBag`, or with `fast` False a PublicBag.

    Raises:
        BagAnalysisError: Missing file, directory, not a bag, unindexed or damaged bag.
    """
    _check_file(path)
    bag = IndexedBag(path) if fast else PublicBag(path)
    try:
        bag.open()
    except (ReaderError, OSError, struct.error, ValueError, KeyError, IndexError,
            AssertionError) as err:
        raise _open_error(path, err) from err
    return bag
