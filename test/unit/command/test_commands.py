"""JointCommands mapping and refusal rules (command/arrays.py's merge_command)."""

from __future__ import annotations

import io
import math

import numpy as np
import pytest

from tutorial_atlas_control.command.arrays import (
    ALL_JOINTS,
    FIELD_NAMES,
    LAW_FIELDS,
    MAX_MAGNITUDE,
    CommandError,
    CommandUpdate,
    JointCommandArrays,
    joint_indices,
    merge_command,
)
from tutorial_atlas_control.joints import JOINT_INDEX, JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.msgs.joint_commands import CommandDecoder


def previous_command() -> JointCommandArrays:
    command = JointCommandArrays.zeros()
    command.position[:] = np.arange(NUM_JOINTS) * 0.01
    command.kp_position[:] = 100.0
    return command


def test_empty_names_read_arrays_in_tutorial_order() -> None:
    positions = np.linspace(-1.0, 1.0, NUM_JOINTS)
    merged = merge_command(previous_command(), [], {'position': positions})
    np.testing.assert_array_equal(merged.position, positions)
    # Fields sent empty keep their previous values.
    np.testing.assert_array_equal(merged.kp_position, np.full(NUM_JOINTS, 100.0))


@pytest.mark.parametrize('prefix', ['', 'atlas::'])
def test_named_subset_in_any_order_maps_by_name(prefix: str) -> None:
    names = [prefix + 'r_arm_elx', prefix + 'back_lbz', prefix + 'l_leg_kny']
    merged = merge_command(previous_command(), names,
                           {'position': [0.3, -0.2, 1.1], 'kd_position': [1.0, 2.0, 3.0]})
    assert merged.position[JOINT_INDEX['r_arm_elx']] == 0.3
    assert merged.position[JOINT_INDEX['back_lbz']] == -0.2
    assert merged.position[JOINT_INDEX['l_leg_kny']] == 1.1
    assert merged.kd_position[JOINT_INDEX['l_leg_kny']] == 3.0
    untouched = JOINT_INDEX['neck_ay']
    assert merged.position[untouched] == pytest.approx(untouched * 0.01)
    assert merged.kd_position[untouched] == 0.0


def test_shuffled_full_command_equals_ordered_one() -> None:
    rng = np.random.default_rng(7)
    values = rng.normal(size=NUM_JOINTS)
    order = rng.permutation(NUM_JOINTS)
    shuffled = merge_command(previous_command(), ['atlas::' + JOINT_NAMES[i] for i in order],
                             {'position': values[order]})
    ordered = merge_command(previous_command(), [], {'position': values})
    np.testing.assert_array_equal(shuffled.position, ordered.position)


def test_previous_command_is_not_modified() -> None:
    previous = previous_command()
    merge_command(previous, ['neck_ay'], {'position': [0.5]})
    assert previous.position[JOINT_INDEX['neck_ay']] == pytest.approx(0.03)


@pytest.mark.parametrize(('names', 'arrays', 'reason'), [
    ([], {'position': [0.0] * 27}, 'position has 27 entries for 28 commanded joints'),
    (['neck_ay', 'back_lbz'], {'effort': [1.0]}, 'effort has 1 entries for 2 commanded joints'),
    (['neck_ay'], {'position': [math.nan]}, r'position\[0\] is nan'),
    (['neck_ay'], {'kp_position': [math.inf]}, r'kp_position\[0\] is inf'),
    (['neck_ay'], {'kp_position': [1e12]}, r'kp_position\[0\] is 1e\+12, beyond the sane bound'),
    (['neck_ay', 'back_lbz'], {'kd_position': [20.0, -1e7]}, r'kd_position\[1\] is -1e\+07'),
    (['neck_ay'], {'effort': [1e300]}, r'effort\[0\] is 1e\+300, beyond the sane bound of 100000'),
    (['neck_ay'], {'velocity': [5e3]}, r'velocity\[0\] is 5000'),
    (['atlas::nose'], {'position': [0.0]}, "unknown joint name 'atlas::nose'"),
    (['neck_ay', 'atlas::neck_ay'], {'position': [0.0, 0.0]}, 'named twice'),
])
def test_bad_messages_are_refused_with_the_reason(names: list[str], arrays: dict,
                                                  reason: str) -> None:
    with pytest.raises(CommandError, match=reason):
        merge_command(previous_command(), names, arrays)


def test_refusal_is_all_or_nothing() -> None:
    previous = previous_command()
    arrays = {'position': [9.0] * NUM_JOINTS, 'velocity': [0.0] * (NUM_JOINTS - 1)}
    with pytest.raises(CommandError):
        merge_command(previous, [], arrays)
    assert previous.position[0] == 0.0


def test_every_field_is_mergeable() -> None:
    merged = merge_command(JointCommandArrays.zeros(), ['back_mby'],
                           {field: [float(k + 1)] for k, field in enumerate(FIELD_NAMES)})
    for k, field in enumerate(FIELD_NAMES):
        assert getattr(merged, field)[JOINT_INDEX['back_mby']] == k + 1


def test_empty_names_mean_all_joints() -> None:
    np.testing.assert_array_equal(joint_indices([]), np.arange(NUM_JOINTS))


def test_values_at_the_bounds_are_accepted() -> None:
    """The bounds refuse absurd values only: a value exactly at each bound is a command."""
    arrays = {field: [bound] for field, bound in MAX_MAGNITUDE.items()}
    arrays['position'] = [1e6]  # no bound: the law clamps it to the joint limits
    merged = merge_command(JointCommandArrays.zeros(), ['back_mby'], arrays)
    for field, bound in MAX_MAGNITUDE.items():
        assert getattr(merged, field)[JOINT_INDEX['back_mby']] == bound


def test_every_field_but_position_has_a_bound() -> None:
    assert set(MAX_MAGNITUDE) == set(FIELD_NAMES) - {'position'}


# -- CommandDecoder: serialized messages, as the simulator node receives them ------------

def serialized(names: list[str], **arrays: list[float]) -> bytes:
    """A JointCommands serialized by genpy, the way rospy sends it."""
    osrf_msgs = pytest.importorskip('osrf_msgs.msg',
                                    reason='needs the catkin workspace: source ./env.sh')
    buffer = io.BytesIO()
    osrf_msgs.JointCommands(name=names, **arrays).serialize(buffer)
    return buffer.getvalue()


def test_decoder_agrees_with_merge_command_and_reuses_the_names() -> None:
    positions = [0.01 * k for k in range(NUM_JOINTS)]
    names = ['atlas::' + name for name in JOINT_NAMES]
    decoder = CommandDecoder()
    for _ in range(2):  # the second message takes the memoized-names path
        merged = previous_command()
        update = decoder.decode(serialized(names, position=positions, kp_position=[5.0] * 28))
        update.apply_to(merged)
        expected = merge_command(previous_command(), names,
                                 {'position': positions, 'kp_position': [5.0] * 28})
        for field in FIELD_NAMES:
            np.testing.assert_array_equal(getattr(merged, field), getattr(expected, field))
    assert not update.is_complete  # 2 of 9 fields


def test_decoder_maps_a_new_name_list_after_a_memoized_one() -> None:
    decoder = CommandDecoder()
    decoder.decode(serialized(['neck_ay'], position=[0.1]))
    update = decoder.decode(serialized(['back_lbz', 'neck_ay'], position=[0.2, 0.3]))
    assert list(update.indices) == [JOINT_INDEX['back_lbz'], JOINT_INDEX['neck_ay']]


def test_a_full_command_sets_every_joint_commands_field_but_not_k_effort() -> None:
    update = CommandDecoder().decode(serialized(
        list(JOINT_NAMES), **{field: [0.0] * NUM_JOINTS for field in FIELD_NAMES}))
    assert update.all_joints and update.rows == tuple(range(len(FIELD_NAMES)))
    # an older AtlasCommand's k_effort survives it
    assert not update.is_complete


@pytest.mark.parametrize(('cut', 'reason'), [
    (lambda raw: raw[:-3], 'malformed message'),
    (lambda raw: raw + b'\0', 'malformed message .*1 bytes left'),
    (lambda raw: raw[:20], 'malformed message'),
    (lambda raw: b'', 'malformed message'),
])
def test_decoder_refuses_malformed_bytes(cut, reason: str) -> None:
    raw = serialized(['neck_ay', 'back_lbz'], position=[0.1, 0.2])
    with pytest.raises(CommandError, match=reason):
        CommandDecoder().decode(cut(raw))


def test_decoder_refuses_what_merge_command_refuses() -> None:
    with pytest.raises(CommandError, match=r'kd_position\[0\] is 1e\+12'):
        CommandDecoder().decode(serialized(['neck_ay'], kd_position=[1e12]))
    with pytest.raises(CommandError, match='unknown joint name'):
        CommandDecoder().decode(serialized(['nose'], position=[0.0]))


def _field_by_field(command: JointCommandArrays, update: CommandUpdate) -> JointCommandArrays:
    """update.apply_to as one indexed write per field, on a command without a block."""
    plain = JointCommandArrays(*(getattr(command, name).copy() for name in LAW_FIELDS))
    for row, values in zip(update.rows, update.values):
        getattr(plain, LAW_FIELDS[row])[update.indices] = values
    return plain


def test_whole_row_updates_write_the_block_as_field_by_field_writes_do() -> None:
    """A controller's updates (every joint in order, fields in any order, k_effort among
    them or not), a named subset, a repeated row: each leaves the same numbers as one
    write per field, and a copied command keeps its fields the rows of one block."""
    rng = np.random.default_rng(4)
    ordered = joint_indices(list(JOINT_NAMES))
    assert ordered is ALL_JOINTS  # the tutorial's order: whole rows
    subset = joint_indices(['r_arm_elx', 'back_lbz'])
    updates = [CommandUpdate(ALL_JOINTS, (0, 1, 2, 3, 4, 5, 6, 9, 7, 8),
                             rng.uniform(-1, 1, (10, NUM_JOINTS))),
               CommandUpdate(ordered, (0, 2, 5), rng.uniform(-1, 1, (3, NUM_JOINTS))),
               CommandUpdate(subset, (1, 9), rng.uniform(-1, 1, (2, 2))),
               CommandUpdate(ALL_JOINTS, (4, 4), rng.uniform(-1, 1, (2, NUM_JOINTS)))]
    command = previous_command().copy()
    for update in updates:
        expected = _field_by_field(command, update)
        merged = command.copy()
        block = merged.rows_block()
        assert block is not None
        update.apply_to(merged)
        assert merged.rows_block() is block
        for name in LAW_FIELDS:
            assert getattr(merged, name).tobytes() == getattr(expected, name).tobytes(), name
        command = merged
