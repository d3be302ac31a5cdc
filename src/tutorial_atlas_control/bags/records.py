"""The raw messages of a ROS 1 bag, per connection and in time order: reader.py's file layer.

Two readers behind one small interface (`connections`, `times_ns`, `raw_messages`, `close`):

* :class:`IndexedBag`, the default, reads each chunk's index as one numpy block and slices
  the messages straight out of the decompressed chunks: rosbags' `Reader.messages` builds
  Python objects per message, which makes a 1 kHz recording several times slower to read.
  It reads the bag through rosbag1_fast.BlockIndexReader, which relies on rosbags' Reader
  internals (requirements.txt pins rosbags; test_bag_reader checks its results against
  :class:`PublicBag` on the same bags).
* :class:`PublicBag` uses only rosbags' public `Reader.messages()`.

Sim time can go back within a bag: `/gazebo/reset_simulation` sets it to 0, and the
recorder stamps each message with the sim time it arrived. Ordering such a bag by time
would interleave the run before the reset with the run after it, so :class:`IndexedBag`
cuts the bag into *epochs* where record times go back in file (arrival) order, and shifts
each later epoch to start :data:`EPOCH_GAP_NS` after the previous one ended: `times_ns`
then rises through the whole bag ("run time"), and `epoch_shifts_ns` undoes the shift.
:class:`PublicBag` cannot see the file order: it reports one epoch, in time order.
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

__all__ = ['EPOCH_GAP_NS', 'REWIND_NS', 'BagRecords', 'IndexedBag', 'PublicBag', 'open_bag']

#: Record times going back by more than this (ns) in file order start a new epoch (arrival
#: times of different topics may be out of order by a few ms; a reset rewinds to 0).
REWIND_NS = 200_000_000
#: Run time (ns) between the last message of an epoch and the first of the next.
EPOCH_GAP_NS = 1_000_000_000

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

    def epochs(self, connections: Sequence[Connection]) -> np.ndarray: ...

    @property
    def epoch_shifts_ns(self) -> list[int]: ...

    @property
    def epoch_starts_ns(self) -> list[int]: ...

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
    #: With resets: every message's file position (chunk position << 32 | offset), in file
    #: order, and its epoch; empty without.
    _keys: np.ndarray
    _epochs: np.ndarray
    _shifts_ns: list[int]

    def open(self) -> None:
        super().open()
        self._find_epochs()

    def _in_file_order(self, connections: Sequence[Connection]) -> tuple[np.ndarray, np.ndarray]:
        """(bag times (ns), file keys) of the messages of `connections`, in file order."""
        blocks = [block for connection in connections
                  for block in self._reader.index_blocks(connection.id)]
        if not blocks:
            empty = np.empty(0, dtype=np.int64)
            return empty, empty
        entries = np.concatenate([entries for _, entries in blocks])
        times_ns = entries['sec'].astype(np.int64) * NS_PER_S + entries['nsec']
        chunk_pos = np.repeat([pos for pos, _ in blocks],
                              [len(entries) for _, entries in blocks]).astype(np.int64)
        keys = (chunk_pos << 32) | entries['offset'].astype(np.int64)
        # A chunk's index is in time order (rosbag sorts it), not always in file order.
        in_file = np.argsort(keys, kind='stable')
        return times_ns[in_file], keys[in_file]

    def _find_epochs(self) -> None:
        """Which epoch each message belongs to, and each epoch's shift to run time.

        Only when some connection's record times go back by more than REWIND_NS: writers
        that write a block per topic (offline runs) are in time order per connection only,
        and have no resets. A live recorder writes in arrival order, so a new epoch starts
        at each message recorded more than REWIND_NS before the one written just before it.
        """
        self._keys = self._epochs = np.empty(0, dtype=np.int64)
        self._shifts_ns = [0]
        self._starts_ns: list[int] = []
        rewinds = any(np.any(np.diff(self._in_file_order([connection])[0]) < -REWIND_NS)
                      for connection in self.connections)
        if not rewinds:
            return
        times_ns, self._keys = self._in_file_order(self.connections)
        starts = np.flatnonzero(np.diff(times_ns) < -REWIND_NS) + 1
        self._epochs = np.zeros(len(times_ns), dtype=np.int64)
        self._epochs[starts] = 1
        self._epochs = np.cumsum(self._epochs)
        bounds = [0, *starts.tolist(), len(times_ns)]
        for epoch in range(1, len(bounds) - 1):
            end_ns = int(times_ns[bounds[epoch - 1]:bounds[epoch]].max()) + self._shifts_ns[-1]
            first_ns = int(times_ns[bounds[epoch]:bounds[epoch + 1]].min())
            self._shifts_ns.append(end_ns + EPOCH_GAP_NS - first_ns)
            self._starts_ns.append(end_ns + EPOCH_GAP_NS // 2)

    def _epochs_of(self, keys: np.ndarray) -> np.ndarray:
        """The epochs of the messages at file positions `keys`."""
        if not len(self._keys):
            return np.zeros(len(keys), dtype=np.int64)
        return self._epochs[np.searchsorted(self._keys, keys)]

    @property
    def epoch_starts_ns(self) -> list[int]:
        """Run time (ns) where epochs 1, 2, ... begin: mid-gap (epoch 0 starts the bag)."""
        return list(self._starts_ns)

    @property
    def epoch_shifts_ns(self) -> list[int]:
        """Per epoch, what was added (ns) to its record times to make them run times."""
        return list(self._shifts_ns)

    def _index(self, connections: Sequence[Connection]) -> tuple[np.ndarray, ...]:
        """(run times (ns), chunk positions, offsets, epochs) of `connections`, in order.

        Ordered by epoch, then time; ties in file order (chunk, then offset), as
        `Reader.messages` yields them.
        """
        times_ns, keys = self._in_file_order(connections)
        epochs = self._epochs_of(keys)
        times_ns = times_ns + np.asarray(self._shifts_ns, dtype=np.int64)[epochs]
        order = np.argsort(times_ns, kind='stable')
        keys = keys[order]
        return times_ns[order], keys >> 32, keys & 0xFFFFFFFF, epochs[order]

    def times_ns(self, connections: Sequence[Connection]) -> np.ndarray:
        """Run times (ns) of the messages of `connections`, from the index alone."""
        return self._index(connections)[0]

    def epochs(self, connections: Sequence[Connection]) -> np.ndarray:
        """The epoch of each message of `connections`, in the order of `times_ns`."""
        return self._index(connections)[3]

    def raw_messages(self, connections: Sequence[Connection]) -> tuple[np.ndarray, list[bytes]]:
        """(bag times (ns), serialized messages) of `connections`, in time order.

        The record parsing is inlined: it runs once per message (60,000 for a 60 s run).
        """
        times_ns, chunk_positions, offsets, _ = self._index(connections)
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
    """Reads messages with rosbags' public `Reader.messages()` only (one epoch)."""

    @property
    def epoch_shifts_ns(self) -> list[int]:
        return [0]

    @property
    def epoch_starts_ns(self) -> list[int]:
        return []

    def epochs(self, connections: Sequence[Connection]) -> np.ndarray:
        return np.zeros(len(self.times_ns(connections)), dtype=np.int64)

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
        if 'index looks damaged' in text or 'could not be read' in text:
            return BagAnalysisError(
                f'{path} is truncated or its index is damaged (was the recording cut short?); '
                f'run `rosbag reindex {path}` and analyze it again.')
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
