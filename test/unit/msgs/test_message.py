"""The vendored osrf_msgs/JointCommands must be DRCSim's message on the wire."""

import pytest

DRCSIM_MD5 = 'f298c98f3e9c7aae9376ac19f73bfba3'
FIELDS = ['header', 'name', 'position', 'velocity', 'effort', 'kp_position', 'ki_position',
          'kd_position', 'kp_velocity', 'i_effort_min', 'i_effort_max']

msg = pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')


def test_type_and_md5_match_drcsim() -> None:
    assert msg.JointCommands._type == 'osrf_msgs/JointCommands'
    assert msg.JointCommands._md5sum == DRCSIM_MD5


def test_fields_in_drcsim_order() -> None:
    assert msg.JointCommands.__slots__ == FIELDS
    assert msg.JointCommands._slot_types[1:] == ['string[]'] + ['float64[]'] * 9


def test_serialization_roundtrip() -> None:
    from io import BytesIO
    out = BytesIO()
    sent = msg.JointCommands(name=['atlas::back_lbz'], position=[0.5], kp_position=[20.0])
    sent.serialize(out)
    received = msg.JointCommands().deserialize(out.getvalue())
    assert received.name == ['atlas::back_lbz']
    assert list(received.position) == [0.5]
    assert list(received.kp_position) == [20.0]


def test_simulator_subscribes_with_the_real_type_and_md5() -> None:
    """The node takes commands undecoded, but registers and negotiates the real type."""
    from tutorial_atlas_control.node.sim_node import RawJointCommands

    assert RawJointCommands._type == 'osrf_msgs/JointCommands'
    assert RawJointCommands._md5sum == 'f298c98f3e9c7aae9376ac19f73bfba3'
    assert RawJointCommands._full_text == msg.JointCommands._full_text
    raw = b'\x01\x02'
    assert RawJointCommands().deserialize(raw).raw is raw


def test_controller_statistics_is_drcsim_atlas_msgs() -> None:
    atlas = pytest.importorskip('atlas_msgs.msg',
                                reason='needs the catkin workspace: source ./env.sh')
    assert atlas.ControllerStatistics._type == 'atlas_msgs/ControllerStatistics'
    assert atlas.ControllerStatistics._md5sum == '628a0c6643f9fd5708402f085735e478'
    assert atlas.ControllerStatistics.__slots__ == [
        'header', 'command_age', 'command_age_mean', 'command_age_variance',
        'command_age_window_size']


#: DRCSim 2.7.0's genmsg MD5 sums (the reference README's table): a field out of place, a
#: changed type or a lost constant changes them.
ATLAS_MSGS_MD5 = {
    'AtlasCommand': '3a56dd1f50633ad975636160b665384a',
    'AtlasState': 'f401ea8c0dd89918d4fa3a58c57816e6',
    'ForceTorqueSensors': '608f43cae98f77f5fb6cfbbbfa4c9253',
    'Test': '62f63cd4b6db15007d8d3d4a23411c4c',
    'ControllerStatistics': '628a0c6643f9fd5708402f085735e478',
    'SynchronizationStatistics': '27bc1701ef8ff889822573f985ebb2b6',
    # The AtlasSimInterface set (2.6.0 = 2.7.0; ../shared/reference/drcsim_2.x/ASI.md).
    'AtlasSimInterfaceCommand': 'afd78cf894b94df9f3ad71fa0e37286b',
    'AtlasSimInterfaceState': 'cac8848356ecf29db9175b861bbf8e75',
    'AtlasBehaviorFeedback': 'f7b1da61a8fcdd81f1e8d9a700d9d2bd',
    'AtlasBehaviorStepFeedback': 'cff2fc0e568e03f6269567166d997b7c',
    'AtlasBehaviorStandFeedback': 'db5aeaf3d00b862980dcbc6b5cfc70fc',
    'AtlasBehaviorWalkFeedback': '4bd389e051b01f8e9b15c23ca6b58e8b',
    'AtlasBehaviorManipulateFeedback': '81c353ff9e8def49f995ee851f13f670',
    'AtlasBehaviorStepData': 'd310ca2045a49be1648d8958f198af57',
    'AtlasBehaviorStepParams': 'fea683aa80fed08d9ec89dd950667373',
    'AtlasBehaviorWalkParams': '0a5b4bccbb6f87ef4f591430c3499c4f',
    'AtlasBehaviorStandParams': '569a10f839b2e1ce334950a722d388b4',
    'AtlasBehaviorManipulateParams': 'c4e967ec87266f9e108243e7ac4b9614',
    'AtlasBehaviorPelvisServoParams': '82f59d8aa26e61afaf2c8dbb7b4e7856',
    'AtlasPositionData': '589dbd8c358d253de2ab5441acd36a2b',
    # VRCScoringPlugin's /vrc_score (../shared/reference/drcsim_2.x/vrc/VRC.md).
    'VRCScore': '15d1f218676ad0e9382ec3bd7afd4995',
    # DRCSim's actionlib server's action, through actionlib_msgs' genaction (ASI.md gives
    # the first 8 digits of all but the first; the rest are genmsg's of the same text).
    'WalkDemoAction': 'abe30eb264997de30b2841a700221184',
    'WalkDemoGoal': '9f688523db1280090d872cabed20d25b',
    'WalkDemoResult': '9acd5105e8aac35c60f292ff9a681629',
    'WalkDemoFeedback': 'dbaa9607b44a2efe654c751e0bae6116',
    'WalkDemoActionGoal': 'be276040800453fdc072cc2f7f7dbc6a',
    'WalkDemoActionResult': 'e62dca2bf26ccbf63139e15689379528',
    'WalkDemoActionFeedback': '27ff4207512409473fc0e40ce6d1c140',
}


@pytest.mark.parametrize(('name', 'md5'), sorted(ATLAS_MSGS_MD5.items()))
def test_atlas_msgs_md5_match_drcsim_2_7_0(name: str, md5: str) -> None:
    atlas = pytest.importorskip('atlas_msgs.msg',
                                reason='needs the catkin workspace: source ./env.sh')
    message = getattr(atlas, name)
    assert message._type == f'atlas_msgs/{name}'
    assert message._md5sum == md5


def test_reset_controls_service_md5_matches_drcsim_2_7_0() -> None:
    srv = pytest.importorskip('atlas_msgs.srv',
                              reason='needs the catkin workspace: source ./env.sh')
    assert srv.ResetControls._type == 'atlas_msgs/ResetControls'
    assert srv.ResetControls._md5sum == '132418be2559866cd92987f80ed5ce8a'


def test_atlas_state_joint_constants_are_the_joint_order() -> None:
    """AtlasState's constants index its arrays in the port's joint order."""
    atlas = pytest.importorskip('atlas_msgs.msg',
                                reason='needs the catkin workspace: source ./env.sh')
    from tutorial_atlas_control.joints import JOINT_NAMES

    assert [getattr(atlas.AtlasState, name) for name in JOINT_NAMES] == list(range(28))
    assert 'back_lbz' not in atlas.AtlasState.__slots__
