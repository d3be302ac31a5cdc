"""Indexed copies of message numbers, many per call: how the simulator's messages take
their numbers from MjData (sim_messages.py).

Through numpy each copy is a call of its own, costing far more than the few values it
moves; compiled (src/atlas_gather.c, loaded by tutorial_atlas_control.native) one call
does all of a plan's copies. Copies only: the values are numpy's `dst[to] = src[from]`
bit for bit, and without the library the plan runs exactly those numpy copies.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from tutorial_atlas_control.native import AtlasCopy, address, load_library

__all__ = ['Copy', 'CopyPlan']

#: One copy of a CopyPlan: (dst, dst_index, src, src_index), meaning
#: dst[dst_index] = src[src_index].
Copy = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


class CopyPlan:
    """A fixed list of indexed float64 copies, run together by one call.

    Compiled (one ctypes call) when the library is built, else numpy, one call per copy;
    the values copied are the same. Holds pointers into the arrays given and references to
    them: they must never be reallocated (MjData's arrays and wire.py's views are not).
    """

    def __init__(self, copies: Sequence[Copy], compiled: bool = True) -> None:
        """`compiled`: False always copies with numpy (the reference the C copies equal)."""
        self.copies = [(dst, np.ascontiguousarray(to, dtype=np.intp), src,
                        np.ascontiguousarray(source, dtype=np.intp))
                       for dst, to, src, source in copies]
        for dst, to, src, source in self.copies:
            if len(to) != len(source):
                raise ValueError(f'a copy of {len(source)} values to {len(to)} places')
            for name, array, index in (('dst', dst, to), ('src', src, source)):
                if len(index) and not 0 <= index.min() <= index.max() < array.size:
                    raise ValueError(f'{name} index outside 0..{array.size - 1}')
        library = load_library() if compiled else None
        self._call = None
        if library is not None:
            table = (AtlasCopy * len(self.copies))()
            for entry, (dst, to, src, source) in zip(table, self.copies):
                entry.dst = address(dst, np.float64)
                entry.dst_index = address(to, np.intp)
                entry.src = address(src, np.float64)
                entry.src_index = address(source, np.intp)
                entry.count = len(to)
            self._table = table
            self._call = library.atlas_copy_all
            self._arguments = (table, len(table))

    def __call__(self) -> None:
        """Every copy of the plan, in order."""
        if self._call is not None:
            self._call(*self._arguments)
            return
        for dst, to, src, source in self.copies:
            dst[to] = src[source]
