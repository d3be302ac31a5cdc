"""A live plot's state: its arguments, the topics they resolved to, their samples.

Fed with raw serialized messages (what rospy's AnyMsg holds) and the type named in the
connection header, it decodes them with that type's class, reads only the fields asked for
and keeps floats, nothing else. An argument that cannot be plotted gets one line saying why
(`cannot plot ARG: ...`) and is dropped; the others go on. ROS time moving back (a reset of
sim time) clears every series. The ROS side (subscribing, the clock, the master's topic
list) is plot_topics_node.py; this module has no ROS import, so its logic is unit-tested.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from tutorial_atlas_control.plotting.fields import (
    FieldReader,
    FieldStep,
    PlotError,
    parse_field_path,
    split_topic,
    unit_of,
)
from tutorial_atlas_control.plotting.series import ClockWatch, RollingSeries

__all__ = ['LivePlot', 'PlotField', 'RawMessage']

#: A message stamped this far (s) ahead of ROS time was sent before ROS time moved back (an
#: in-flight message of the run before a reset): it is dropped. Stamps run ahead of the
#: plotter's clock by a few steps at most (the simulator sends /clock after the messages).
FUTURE_TOLERANCE_S = 1.0

#: (ROS time at receipt (s), the serialized message, or the message rospy already decoded).
RawMessage = tuple[float, object]
MessageClassLookup = Callable[[str], object]


@dataclass
class PlotField:
    """One argument: where it reads from, what it holds, or why it is not plotted."""

    argument: str
    series: RollingSeries
    topic: str | None = None
    path: tuple[FieldStep, ...] = ()
    reader: FieldReader | None = None
    #: The message type the reader was checked against.
    checked_type: str | None = None
    refused: str | None = None
    samples: int = 0
    reported_silent: bool = field(default=False, repr=False)
    #: The array element's name (JointState's `name`) once a message was read ('' if the
    #: message names none).
    element: str | None = None
    #: The field's unit when it is a common one (fields.unit_of).
    unit: str | None = None

    @property
    def plotted(self) -> bool:
        return self.refused is None

    @property
    def label(self) -> str:
        """The legend's text: the argument, and the element's name when known."""
        return f'{self.argument} ({self.element})' if self.element else self.argument


class LivePlot:
    """The fields of one plot over a rolling window of `window_s` seconds.

    Times are ROS time minus `origin_s` (0 under sim time, so the axis shows sim time).
    """

    def __init__(self, arguments: Sequence[str], window_s: float, origin_s: float = 0.0) -> None:
        self.window_s = window_s
        self.origin_s = origin_s
        self.fields = [PlotField(argument, RollingSeries(window_s)) for argument in arguments]
        self.clock = ClockWatch()
        self.resets = 0

    # -- topics ----------------------------------------------------------------------------
    def unmatched(self) -> list[PlotField]:
        """The arguments still waiting for a topic of theirs to be published."""
        return [f for f in self.fields if f.plotted and f.topic is None]

    def match_topics(self, published: Mapping[str, str]) -> tuple[list[str], list[str]]:
        """Match the waiting arguments against `published` ({topic: type}, the master's).

        Returns:
            The topics to subscribe to now, and one line per argument refused.
        """
        lines = []
        new_topics: list[str] = []
        for plot_field in self.unmatched():
            split = split_topic(plot_field.argument, published)
            if split is None:
                continue
            topic, path_text = split
            if not path_text:
                lines.append(self._refuse(plot_field, f'{topic} is a topic ({published[topic]}),'
                                                      ' not a field of one: add /FIELD'))
                continue
            try:
                plot_field.path = parse_field_path(path_text)
            except PlotError as err:
                lines.append(self._refuse(plot_field, str(err)))
                continue
            plot_field.topic = topic
            if topic not in new_topics:
                new_topics.append(topic)
        return new_topics, lines

    def fields_of(self, topic: str) -> list[PlotField]:
        return [f for f in self.fields if f.topic == topic and f.plotted]

    # -- samples ---------------------------------------------------------------------------
    def feed(self, topic: str, type_name: str, messages: Iterable[RawMessage],
             lookup: MessageClassLookup) -> list[str]:
        """Decode `messages` of `topic` (type `type_name`, from the connection header) and
        append the fields' values; one line per argument refused on the way."""
        lines = []
        fields = self.fields_of(topic)
        message_class = lookup(type_name) if fields else None
        if fields and message_class is None:
            for plot_field in fields:
                lines.append(self._refuse(plot_field, f'no message class for {type_name} (is its '
                                                      'package built and the workspace sourced?)'))
            return lines
        for plot_field in fields:
            if plot_field.checked_type != type_name:
                try:
                    plot_field.reader = FieldReader.for_class(message_class, plot_field.path,
                                                              lookup)
                    plot_field.checked_type = type_name
                    plot_field.unit = unit_of(plot_field.path, plot_field.reader.leaf_type)
                    plot_field.element = None
                except PlotError as err:
                    lines.append(self._refuse(plot_field, f'{topic}: {err}'))
        fields = [f for f in fields if f.plotted]
        if not fields:
            return lines
        has_header = bool(getattr(message_class, '_has_header', False))
        latest_s = self.clock.last_s
        times: list[float] = []
        values: list[list[float]] = [[] for _ in fields]
        for receipt_s, raw in messages:
            if isinstance(raw, (bytes, bytearray, memoryview)):
                message = message_class()
                message.deserialize(raw)
            else:
                message = raw
            stamp_s = message.header.stamp.to_sec() if has_header else 0.0
            time_s = (stamp_s if stamp_s > 0.0 else receipt_s) - self.origin_s
            if latest_s is not None and time_s > latest_s - self.origin_s + FUTURE_TOLERANCE_S:
                continue
            times.append(time_s)
            for column, plot_field in zip(values, fields):
                if plot_field.plotted:
                    try:
                        if plot_field.element is None:
                            plot_field.element = plot_field.reader.element_name(message) or ''
                        column.append(plot_field.reader.read(message))
                        continue
                    except PlotError as err:
                        lines.append(self._refuse(plot_field, f'{topic}: {err}'))
                column.append(np.nan)
        for column, plot_field in zip(values, fields):
            if plot_field.plotted and times:
                plot_field.series.extend(times, column)
                plot_field.samples += len(times)
        return lines

    def advance(self, now_s: float, rewound: bool | None = None) -> bool:
        """ROS time is `now_s`: slide the window; True (and every series cleared) when time
        moved back: as `rewound` says when given (a /clock watch that saw every message),
        else when `now_s` is earlier than the time last given."""
        moved_back = self.clock.moved_back(now_s)
        if moved_back if rewound is None else rewound:
            for plot_field in self.fields:
                plot_field.series.clear()
            self.resets += 1
            return True
        for plot_field in self.fields:
            plot_field.series.trim(now_s - self.origin_s)
        return False

    @property
    def now_s(self) -> float:
        """The latest ROS time seen, on the plot's axis."""
        return (self.clock.last_s or self.origin_s) - self.origin_s

    # -- what to say -----------------------------------------------------------------------
    def silent_lines(self, waited_s: float) -> list[str]:
        """One line, once, per plotted argument that got no sample in `waited_s` of ROS time."""
        lines = []
        for plot_field in self.fields:
            if not plot_field.plotted or plot_field.samples or plot_field.reported_silent:
                continue
            plot_field.reported_silent = True
            if plot_field.topic is None:
                lines.append(f'no data for {plot_field.argument}: no topic it names is '
                             f'published ({waited_s:.1f} s of ROS time)')
            else:
                lines.append(f'no data for {plot_field.argument}: no message on '
                             f'{plot_field.topic} in {waited_s:.1f} s of ROS time')
        return lines

    def plotted(self) -> list[PlotField]:
        return [f for f in self.fields if f.plotted]

    @staticmethod
    def _refuse(plot_field: PlotField, reason: str) -> str:
        plot_field.refused = reason
        plot_field.series.clear()
        return f'cannot plot {plot_field.argument}: {reason}'
