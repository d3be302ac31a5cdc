"""AtlasSimInterfaceCommand decoding: genpy's bytes read field for field; k_effort taken
only at 28 entries; NaN/Inf and absurd floats refused with one line naming the field."""

from __future__ import annotations

import io
import math
import re
import struct
from dataclasses import replace

import numpy as np
import pytest

from tutorial_atlas_control.command.arrays import CommandError
from tutorial_atlas_control.msgs.atlas_sim_interface import (
    AsiCommand,
    ManipulateParams,
    StepData,
    decode_asi_command,
    encode_asi_command,
)


def command(behavior: int = 4, **changes: object) -> AsiCommand:
    queue = tuple(StepData(i + 1, i % 2, 0.63, (0.2 * (i + 1), 0.12 - 0.24 * (i % 2), 0.0),
                           (0.0, 0.0, math.sin(0.05), math.cos(0.05)), 0.1) for i in range(4))
    fields = dict(stamp_ns=12_000_000_345, behavior=behavior, step_queue=queue,
                  use_demo_walk=False, desired_step=queue[1], step_use_demo_walk=True,
                  manipulate=ManipulateParams(True, 0.8, -0.3, 0.05, False),
                  k_effort=None, k_effort_length=0)
    fields.update(changes)
    return AsiCommand(**fields)


def test_genpy_bytes_decode_field_for_field() -> None:
    atlas = pytest.importorskip('atlas_msgs.msg', reason='needs the catkin workspace')
    message = atlas.AtlasSimInterfaceCommand()
    message.header.stamp.secs, message.header.stamp.nsecs = 12, 345
    message.behavior = message.WALK
    for i, step in enumerate(message.walk_params.step_queue):
        step.step_index, step.foot_index, step.duration = i + 1, i % 2, 0.63
        step.pose.position.x, step.pose.position.y = 0.2 * (i + 1), 0.12 - 0.24 * (i % 2)
        step.pose.orientation.z, step.pose.orientation.w = math.sin(0.05), math.cos(0.05)
        step.swing_height = 0.1
    message.step_params.desired_step = message.walk_params.step_queue[1]
    message.step_params.use_demo_walk = True
    message.manipulate_params.use_desired = True
    desired = message.manipulate_params.desired
    desired.pelvis_height, desired.pelvis_yaw, desired.pelvis_lat = 0.8, -0.3, 0.05
    message.k_effort = bytes([255] * 12 + [0] * 16)
    out = io.BytesIO()
    message.serialize(out)
    decoded = decode_asi_command(out.getvalue())
    expected = command(k_effort=None, k_effort_length=28)
    assert decoded.stamp_ns == expected.stamp_ns
    assert decoded.step_queue == expected.step_queue
    assert decoded.desired_step == expected.desired_step and decoded.step_use_demo_walk
    assert decoded.manipulate == expected.manipulate
    assert decoded.behavior == 4
    assert decoded.step_queue[0].yaw_rad() == pytest.approx(0.1)
    np.testing.assert_array_equal(decoded.k_effort, [1.0] * 12 + [0.0] * 16)
    assert encode_asi_command(expected, bytes([255] * 12 + [0] * 16)) == out.getvalue()


def test_a_default_command_is_stand_with_no_blend() -> None:
    atlas = pytest.importorskip('atlas_msgs.msg', reason='needs the catkin workspace')
    out = io.BytesIO()
    atlas.AtlasSimInterfaceCommand().serialize(out)
    decoded = decode_asi_command(out.getvalue())
    assert decoded.behavior == 0
    assert decoded.k_effort is None and decoded.ignored_text() == ''
    assert decoded.step_queue[0].yaw_rad() == 0.0


@pytest.mark.parametrize('length', [0, 27, 29])
def test_k_effort_is_taken_only_at_28(length: int) -> None:
    decoded = decode_asi_command(encode_asi_command(command(), bytes(length)))
    assert decoded.k_effort is None
    assert decoded.ignored_text() == ('' if length == 0 else
                                      f'k_effort ({length} entries) not 28 long; '
                                      'the previous blend stays')


def test_an_unknown_behavior_is_passed_on_for_the_behaviours_to_report() -> None:
    assert decode_asi_command(encode_asi_command(command(behavior=17))).behavior == 17


@pytest.mark.parametrize(('changes', 'text'), [
    ({'manipulate': ManipulateParams(True, math.nan, 0.0, 0.0)},
     'manipulate_params.desired.pelvis_height is nan (NaN/Inf are refused)'),
    ({'desired_step': StepData(1, 0, math.inf)},
     'step_params.desired_step.duration is inf (NaN/Inf are refused)'),
    ({'step_queue': (StepData(),) * 3 + (StepData(4, 1, 0.6, (1e5, 0.0, 0.0)),)},
     'walk_params.step_queue[3].pose.position.x is 100000, beyond ±10000'),
])
def test_bad_floats_are_refused_with_the_field_named(changes: dict, text: str) -> None:
    with pytest.raises(CommandError) as refused:
        decode_asi_command(encode_asi_command(command(**changes)))
    assert str(refused.value) == text


def test_a_truncated_or_padded_message_is_malformed() -> None:
    raw = encode_asi_command(command(), bytes(28))
    with pytest.raises(CommandError, match=r'^malformed AtlasSimInterfaceCommand \('):
        decode_asi_command(raw[:-30])
    with pytest.raises(CommandError) as refused:
        decode_asi_command(raw + b'\x00')
    assert str(refused.value) == ('malformed AtlasSimInterfaceCommand '
                                  '(1 bytes left after the last field)')
    assert struct.calcsize('<II9d') == 80  # AtlasBehaviorStepData on the wire


@pytest.mark.parametrize(('behavior', 'slot', 'field'), [
    (4, 2, 'walk_params.step_queue[2].foot_index'),
    (5, None, 'step_params.desired_step.foot_index')])
def test_a_step_to_take_with_no_such_foot_is_refused(behavior: int, slot: int | None,
                                                     field: str) -> None:
    queue = list(command().step_queue)
    bad = StepData(3, 2, 0.63)
    if slot is not None:
        queue[slot] = bad
    changed = command(behavior, step_queue=tuple(queue),
                      desired_step=bad if slot is None else command().desired_step)
    with pytest.raises(CommandError, match=rf'{re.escape(field)} is 2, not 0 \(left\) or 1'):
        decode_asi_command(encode_asi_command(changed))
    # An unused slot (step_index 0) and another behaviour's parameters are not looked at.
    unused = replace(bad, step_index=0)
    queue[2] = unused
    assert decode_asi_command(encode_asi_command(command(4, step_queue=tuple(queue)))).behavior == 4
    assert decode_asi_command(encode_asi_command(command(0, desired_step=bad))).behavior == 0


@pytest.mark.parametrize('duration_s', [0.0, -0.5])
def test_a_walk_step_without_a_duration_is_refused(duration_s: float) -> None:
    queue = list(command().step_queue)
    queue[1] = StepData(2, 1, duration_s)
    with pytest.raises(CommandError, match=re.escape(
            f'walk_params.step_queue[1].duration is {duration_s:g}, not positive')):
        decode_asi_command(encode_asi_command(command(4, step_queue=tuple(queue))))
    # Step's desired step may come without one (DRCSim's actionlib server sends none).
    step = decode_asi_command(encode_asi_command(command(5, desired_step=StepData(1, 0, 0.0))))
    assert step.desired_step.duration_s == 0.0
