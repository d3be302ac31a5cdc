"""AtlasSimInterfaceState's wire bytes are genpy's, field for field; a misshapen walk queue
is refused."""

from __future__ import annotations

import io
import math

import numpy as np
import pytest

from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.msgs.atlas_sim_interface import StepData
from tutorial_atlas_control.msgs.atlas_sim_interface_state import (
    AsiState,
    BehaviorFeedback,
    ManipulateFeedback,
    StepFeedback,
    WalkFeedback,
    encode_asi_state,
)


def step(index: int) -> StepData:
    return StepData(index, index % 2, 0.63, (0.2 * index, 0.12 - 0.24 * (index % 2), 0.01),
                    (0.0, 0.0, math.sin(0.05 * index), math.cos(0.05 * index)), 0.1 + index)


def state() -> AsiState:
    feet = np.array([[0.01, 0.11, 0.02, 0.0, 0.0, 0.1, 0.995],
                     [0.02, -0.12, 0.03, 0.0, 0.0, -0.1, 0.995]])
    return AsiState(
        stamp_ns=12_000_000_345, error_code=-6, current_behavior=0, desired_behavior=9,
        f_out_nm=np.linspace(-50.0, 50.0, NUM_JOINTS), pelvis_position_m=(0.1, -0.2, 0.9),
        pelvis_velocity_m_s=(0.3, 0.01, -0.02), foot_poses=feet,
        behavior_feedback=BehaviorFeedback(4, 0, 9),
        step_feedback=StepFeedback(2, 0.25, 3, 4, step(4)), stand_status_flags=0,
        walk_feedback=WalkFeedback(0.4, 5, 9, 8, tuple(step(i) for i in range(6, 10))),
        manipulate_feedback=ManipulateFeedback(0, 0.8, -0.3, 0.05),
        k_effort=np.arange(NUM_JOINTS, dtype=np.uint8) * 9)


def fill_step(target, data: StepData) -> None:
    target.step_index, target.foot_index = data.step_index, data.foot_index
    target.duration, target.swing_height = data.duration_s, data.swing_height_m
    p, o = target.pose.position, target.pose.orientation
    p.x, p.y, p.z = data.position_m
    o.x, o.y, o.z, o.w = data.orientation_xyzw


def test_bytes_are_genpy_s_field_for_field() -> None:
    atlas = pytest.importorskip('atlas_msgs.msg', reason='needs the catkin workspace')
    ours = state()
    message = atlas.AtlasSimInterfaceState()
    message.header.seq = 7
    message.header.stamp.secs, message.header.stamp.nsecs = 12, 345
    message.header.frame_id = 'world'
    message.error_code, message.current_behavior = ours.error_code, ours.current_behavior
    message.desired_behavior = ours.desired_behavior
    message.f_out = list(ours.f_out_nm)
    pos = message.pos_est
    pos.position.x, pos.position.y, pos.position.z = ours.pelvis_position_m
    pos.velocity.x, pos.velocity.y, pos.velocity.z = ours.pelvis_velocity_m_s
    for pose, values in zip(message.foot_pos_est, ours.foot_poses):
        pose.position.x, pose.position.y, pose.position.z = values[:3]
        pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = values[3:]
    feedback = message.behavior_feedback
    feedback.status_flags = ours.behavior_feedback.status_flags
    feedback.trans_from_behavior_index = ours.behavior_feedback.trans_from_behavior_index
    feedback.trans_to_behavior_index = ours.behavior_feedback.trans_to_behavior_index
    s, walk, ours_walk = message.step_feedback, message.walk_feedback, ours.walk_feedback
    s.status_flags, s.t_step_rem = ours.step_feedback.status_flags, ours.step_feedback.t_step_rem_s
    s.current_step_index = ours.step_feedback.current_step_index
    s.next_step_index_needed = ours.step_feedback.next_step_index_needed
    fill_step(s.desired_step_saturated, ours.step_feedback.desired_step_saturated)
    message.stand_feedback.status_flags = ours.stand_status_flags
    walk.t_step_rem, walk.current_step_index = ours_walk.t_step_rem_s, ours_walk.current_step_index
    walk.next_step_index_needed = ours_walk.next_step_index_needed
    walk.status_flags = ours_walk.status_flags
    for target, data in zip(walk.step_queue_saturated, ours_walk.step_queue_saturated):
        fill_step(target, data)
    manipulate = message.manipulate_feedback
    manipulate.status_flags = ours.manipulate_feedback.status_flags
    clamped = manipulate.clamped
    clamped.pelvis_height = ours.manipulate_feedback.pelvis_height_m
    clamped.pelvis_yaw = ours.manipulate_feedback.pelvis_yaw_rad
    clamped.pelvis_lat = ours.manipulate_feedback.pelvis_lat_m
    message.k_effort = ours.k_effort.tobytes()
    buffer = io.BytesIO()
    message.serialize(buffer)
    assert encode_asi_state(ours, seq=7, frame_id='world') == buffer.getvalue()


def test_a_default_state_is_a_default_message_with_unit_quaternion_feet() -> None:
    atlas = pytest.importorskip('atlas_msgs.msg', reason='needs the catkin workspace')
    message = atlas.AtlasSimInterfaceState()
    message.deserialize(encode_asi_state(AsiState(stamp_ns=0)))
    assert [pose.orientation.w for pose in message.foot_pos_est] == [1.0, 1.0]
    assert len(message.k_effort) == NUM_JOINTS and len(message.f_out) == NUM_JOINTS


def test_a_walk_queue_of_another_length_is_refused() -> None:
    bad = AsiState(stamp_ns=0, walk_feedback=WalkFeedback(step_queue_saturated=(step(1),)))
    with pytest.raises(ValueError, match='step_queue_saturated has 1 steps, not 4'):
        encode_asi_state(bad)
