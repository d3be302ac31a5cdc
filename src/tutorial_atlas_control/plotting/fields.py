"""rqt_plot's arguments, and the numbers they name in a message of any type.

An argument is `TOPIC/FIELD`, with nested fields separated by `/` and an index in brackets
on any array: `/atlas/joint_states/position[19]`, `/ground_truth_odom/pose/pose/position/z`.
`TOPIC/FIELD1:FIELD2` names several fields of one topic (`/odom/pose/pose/position/x:y:z`)
and `A,B` several arguments in one word, as rqt_plot took them. Where the topic ends and
the field begins is only known from the topics the master lists (split_topic), and whether
a field holds a number only from the message class (FieldReader.for_class). Message
classes are genpy's, used through their `__slots__` and `_slot_types` only: no ROS import.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

from tutorial_atlas_control.errors import AtlasControlError

__all__ = ['FieldReader', 'FieldStep', 'PlotError', 'expand_arguments', 'parse_field_path',
           'split_topic']

#: ROS primitive types that plot as numbers (bool and char too, as rqt_plot plots them).
NUMERIC_TYPES = frozenset({
    'bool', 'byte', 'char', 'int8', 'uint8', 'int16', 'uint16', 'int32', 'uint32',
    'int64', 'uint64', 'float32', 'float64'})
#: Primitive types plotted in seconds (genpy's Time and Duration have to_sec()).
TIME_TYPES = frozenset({'time', 'duration'})
#: One field of a path: a name and an optional index, `position[19]`.
_STEP = re.compile(r'(?P<name>[A-Za-z][A-Za-z0-9_]*)(?:\[(?P<index>[0-9]+)\])?')
#: An array slot type, `float64[]` or `float64[36]`.
_ARRAY = re.compile(r'(?P<element>.+)\[(?P<length>[0-9]*)\]')


class PlotError(AtlasControlError):
    """An argument of plot_topics.py cannot be plotted; the message names it and why."""


@dataclass(frozen=True)
class FieldStep:
    """One field of a path and, for an array, the element wanted."""

    name: str
    index: int | None = None

    def __str__(self) -> str:
        return self.name if self.index is None else f'{self.name}[{self.index}]'


def expand_arguments(arguments: Iterable[str]) -> list[str]:
    """rqt_plot's shorthands written out: `A,B` is two arguments, `/t/a/x:y` is `/t/a/x` and
    `/t/a/y`. Names without a leading `/` are taken from the root namespace.

    Raises:
        PlotError: an argument is empty or its `:` form has no field to replace.
    """
    expanded = []
    for word in arguments:
        for part in word.split(','):
            if not part:
                continue
            head, *others = part.split(':')
            if others and '/' not in head.strip('/'):
                raise PlotError(f'{part}: the FIELD1:FIELD2 form needs TOPIC/FIELD1 before the '
                                'first colon')
            base = head.rsplit('/', 1)[0]
            names = [head] + [f'{base}/{other}' for other in others if other]
            expanded += [name if name.startswith('/') else f'/{name}' for name in names]
    if not expanded:
        raise PlotError('no TOPIC/FIELD to plot')
    return expanded


def parse_field_path(text: str) -> tuple[FieldStep, ...]:
    """`pose/pose/position/x` or `position[19]` as steps (dots separate fields too).

    Raises:
        PlotError: an empty path, an empty field, or a field that is not NAME or NAME[N].
    """
    parts = [part for part in re.split(r'[/.]', text)]
    if not text or any(not part for part in parts):
        raise PlotError(f'{text!r} is not a field path (expected FIELD, FIELD[N] or '
                        'FIELD/SUBFIELD)')
    steps = []
    for part in parts:
        match = _STEP.fullmatch(part)
        if match is None:
            raise PlotError(f'{part!r} is not a field name, or NAME[N] with N >= 0')
        index = match['index']
        steps.append(FieldStep(match['name'], None if index is None else int(index)))
    return tuple(steps)


def split_topic(argument: str, topics: Iterable[str]) -> tuple[str, str] | None:
    """(topic, field path) of `argument`, the topic being the longest of `topics` it starts
    with (followed by `/`); None when no topic matches."""
    matches = [topic for topic in topics
               if argument == topic or argument.startswith(topic.rstrip('/') + '/')]
    if not matches:
        return None
    topic = max(matches, key=len)
    return topic, argument[len(topic.rstrip('/')):].strip('/')


MessageClassLookup = Callable[[str], object]

#: Units of common fields, by (the field holding it, the field read); '*' for any holder.
#: sensor_msgs/JointState's position is in rad for Atlas's revolute joints.
UNITS: dict[tuple[str, str], str] = {
    ('*', 'position'): 'rad', ('*', 'velocity'): 'rad/s', ('*', 'effort'): 'N·m',
    ('position', 'x'): 'm', ('position', 'y'): 'm', ('position', 'z'): 'm',
    ('linear', 'x'): 'm/s', ('linear', 'y'): 'm/s', ('linear', 'z'): 'm/s',
    ('angular', 'x'): 'rad/s', ('angular', 'y'): 'rad/s', ('angular', 'z'): 'rad/s',
    ('angular_velocity', 'x'): 'rad/s', ('angular_velocity', 'y'): 'rad/s',
    ('angular_velocity', 'z'): 'rad/s',
    ('linear_acceleration', 'x'): 'm/s²', ('linear_acceleration', 'y'): 'm/s²',
    ('linear_acceleration', 'z'): 'm/s²',
    ('force', 'x'): 'N', ('force', 'y'): 'N', ('force', 'z'): 'N',
    ('torque', 'x'): 'N·m', ('torque', 'y'): 'N·m', ('torque', 'z'): 'N·m',
}


def unit_of(path: Sequence[FieldStep], leaf_type: str) -> str | None:
    """The unit of the field at `path` when it is a common one (UNITS), else None."""
    if leaf_type in TIME_TYPES:
        return 's'
    names = [step.name for step in path]
    holder = names[-2] if len(names) > 1 else ''
    return UNITS.get((holder, names[-1])) or (
        UNITS.get(('*', names[-1])) if len(names) == 1 else None)


def _qualified(type_name: str, package: str) -> str:
    """A slot's message type with its package (`Header` is std_msgs', as in genmsg)."""
    if '/' in type_name:
        return type_name
    return 'std_msgs/Header' if type_name == 'Header' else f'{package}/{type_name}'


def _slot_type(message_class: object, name: str) -> str | None:
    slots = getattr(message_class, '__slots__', ())
    types = getattr(message_class, '_slot_types', ())
    return dict(zip(slots, types)).get(name)


@dataclass(frozen=True)
class FieldReader:
    """Reads one number from a decoded message along a checked path."""

    path: tuple[FieldStep, ...]
    #: The primitive type read at the end: a number type, `time` or `duration`.
    leaf_type: str

    @classmethod
    def for_class(cls, message_class: object, path: Sequence[FieldStep],
                  lookup: MessageClassLookup) -> FieldReader:
        """Check `path` against `message_class` (genpy: `__slots__`, `_slot_types`, `_type`);
        `lookup(type_name)` gives the class of a nested message type (or None).

        Raises:
            PlotError: a field the type lacks, a string or a whole message or array where a
                number is needed, an index on a non-array or past a fixed array's end, or a
                nested type whose class cannot be found.
        """
        current = message_class
        type_name = str(getattr(message_class, '_type', '?'))
        for position, step in enumerate(path):
            slot = _slot_type(current, step.name)
            if slot is None:
                fields = ', '.join(getattr(current, '__slots__', ())) or 'none'
                raise PlotError(f'{type_name} has no field {step.name!r} (its fields: {fields})')
            array = _ARRAY.fullmatch(slot)
            if array is not None:
                if step.index is None:
                    raise PlotError(f'{step.name} is an array ({slot}): give an element, e.g. '
                                    f'{step.name}[0]')
                length = array['length']
                if length and step.index >= int(length):
                    raise PlotError(f'{step} is past the end of {step.name} ({slot})')
                slot = array['element']
            elif step.index is not None:
                raise PlotError(f'{step.name} is {slot}, not an array: no index')
            last = position == len(path) - 1
            if slot in NUMERIC_TYPES or slot in TIME_TYPES:
                if not last:
                    raise PlotError(f'{step} is a number ({slot}): it has no field '
                                    f'{path[position + 1].name!r}')
                return cls(tuple(path), slot)
            if slot == 'string':
                raise PlotError(f'{step} is a string, not a number')
            package = type_name.split('/')[0]
            type_name = _qualified(slot, package)
            if last:
                fields = ', '.join(getattr(lookup(type_name), '__slots__', ()))
                hint = f' (its fields: {fields})' if fields else ''
                raise PlotError(f'{step} is a message ({type_name}), not a number: name one '
                                f'of its fields{hint}')
            current = lookup(type_name)
            if current is None:
                raise PlotError(f'no message class for {type_name} (is its package built and '
                                'the workspace sourced?)')
        raise PlotError('no field given')

    def element_name(self, message: object) -> str | None:
        """The name of the array element read, when the message holding the array also holds
        a `name` list of the same length (sensor_msgs/JointState and its kind): `position[19]`
        of /atlas/joint_states is l_arm_elx. None otherwise."""
        last = self.path[-1]
        if last.index is None:
            return None
        holder = message
        for step in self.path[:-1]:
            holder = getattr(holder, step.name, None)
            if step.index is not None and holder is not None:
                holder = holder[step.index] if step.index < len(holder) else None
        names = getattr(holder, 'name', None)
        values = getattr(holder, last.name, None)
        if not isinstance(names, (list, tuple)) or values is None or len(names) != len(values):
            return None
        return str(names[last.index]) if last.index < len(names) else None

    def read(self, message: object) -> float:
        """The field's value in `message` as a float (s for time and duration).

        Raises:
            PlotError: an index past the end of a variable-length array in this message.
        """
        value = message
        for step in self.path:
            value = getattr(value, step.name)
            if step.index is not None:
                try:
                    value = value[step.index]
                except IndexError:
                    raise PlotError(f'{step} is past the end of {step.name} ({len(value)} '
                                    'elements in the message)') from None
        if self.leaf_type in TIME_TYPES:
            return float(value.to_sec())
        if isinstance(value, (bytes, str)):  # genpy's char and byte may come as one character
            return float(ord(value)) if len(value) == 1 else math.nan
        return float(value)
