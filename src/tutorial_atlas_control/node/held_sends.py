"""Holding a bag recorder's bytes for a few milliseconds: one send where there were ten.

At real time the simulator sends after every step: each state reaches a controller at once,
which is what a controller needs. A bag recorder needs none of it: it writes what it
receives to a file and wakes every 5 ms anyway, while every send is a syscall of the
simulator's loop that also runs the recorder's side of loopback TCP and wakes it. So the
bytes for the subscribers named here (the launch's recorder) are held and sent together once
`period_s` of wall time has passed since the first one held; every other subscriber still
gets each flush. Measured on a standing launch at real time with its recorder (20 s a run,
alternated, nothing else running): every step, the node 0.29-0.32 of a core and the recorder
0.12-0.13; held 4 ms, 0.24-0.25 and 0.07 (2 ms: 0.26 and 0.08; 10 ms: 0.22-0.24 and 0.06-0.07;
/clock alone sent every step and the rest held 10 ms: 0.28 and 0.10, most of the cost is the
per-step wake).

/clock is held too, so the recorder's clock, from which it takes each message's bag time,
runs up to `period_s` behind: a command it receives straight from a client (an unstamped
one is placed by its bag time) is recorded up to that much early, as at real_time_factor 0,
where every subscriber gets a flush only every 4 ms (stepping/pacing.py's FLUSH_PERIOD_S):
the period is that 4 ms. What is held goes out in one flush, in that flush's order
(transport.WireBatch.flush): the batches, then what was held for publishers with nothing new,
then /clock; so the recorder still never receives a time before the messages stamped with
it. At shutdown, what is held joins the backlogs that ConnectionWriter.drain sends.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Collection

__all__ = ['RECORDER_SEND_PERIOD_S', 'HeldSends']

#: Default hold (wall s) for the recorder's bytes: its clock at most this far behind, as
#: every subscriber's at real_time_factor 0 (pacing.FLUSH_PERIOD_S).
RECORDER_SEND_PERIOD_S = 0.004


class HeldSends:
    """The bytes held per connection for the named subscribers, and when to let them go.

    A flush calls begin_flush() first: once `period_s` has passed since the first byte
    held, that flush releases everything (take() hands a connection's held bytes back with
    the new ones, release_rest() the connections the flush wrote nothing to).
    """

    def __init__(self, subscribers: Collection[str], period_s: float = RECORDER_SEND_PERIOD_S,
                 clock: Callable[[], float] = time.monotonic) -> None:
        if not period_s >= 0.0:
            raise ValueError(f'the hold must be a number of seconds >= 0, got {period_s!r}')
        self.subscribers = frozenset(subscribers) if period_s > 0.0 else frozenset()
        self.period_s = period_s
        self.clock = clock
        #: connection -> (its publisher, the bytes held for it, oldest first).
        self.held: dict[object, tuple[object, bytearray]] = {}
        self.first_held_s: float | None = None
        self.releasing = False

    def holds(self, connection: object) -> bool:
        """Is `connection` a named subscriber's (its bytes may be held)?"""
        return getattr(connection, 'endpoint_id', None) in self.subscribers

    def begin_flush(self) -> None:
        """Decide whether this flush releases what is held."""
        self.releasing = (self.first_held_s is not None
                          and self.clock() - self.first_held_s >= self.period_s)

    def take(self, pub: object, connection: object,
             data: bytes | bytearray) -> bytes | bytearray | None:
        """What to send `connection` now, `data` included: None while held."""
        entry = self.held.get(connection)
        if self.releasing:
            if entry is None:
                return data
            del self.held[connection]
            entry[1].extend(data)
            return entry[1]
        if entry is None:
            self.held[connection] = (pub, bytearray(data))
            if self.first_held_s is None:
                self.first_held_s = self.clock()
        else:
            entry[1].extend(data)
        return None

    def release_rest(self, taken_next: Collection[object] = ()
                     ) -> list[tuple[object, object, bytearray]]:
        """In a releasing flush: (publisher, connection, bytes) of every connection still
        held, but those of the publishers in `taken_next` (take() comes for them later in
        the flush); they are no longer held."""
        if not self.releasing:
            return []
        rest = [(pub, connection, data) for connection, (pub, data) in self.held.items()
                if pub not in taken_next]
        for _pub, connection, _data in rest:
            del self.held[connection]
        return rest

    def end_flush(self) -> None:
        """After a flush: a releasing one has let everything go; the next hold starts a
        new period."""
        if self.releasing:
            self.releasing = False
            self.first_held_s = None if not self.held else self.clock()

    def pop_all(self) -> list[tuple[object, object, bytearray]]:
        """Every connection's held bytes (at shutdown: they join the backlogs to drain)."""
        rest = [(pub, connection, data) for connection, (pub, data) in self.held.items()]
        self.held.clear()
        self.first_held_s = None
        return rest

    def forget(self, connection: object) -> None:
        """`connection` closed: its held bytes have nowhere to go."""
        self.held.pop(connection, None)
